"""What a solve returns: a status, the motion(s), forces, modes, power and audit, and how it was proven.

Plain value types; this module imports nothing else of the package.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Generic, Literal, Protocol, TypeVar, overload

import numpy as np

__all__ = [
    "Status",
    "Mode",
    "Diagnosis",
    "CertificateKind",
    "Certificate",
    "Attempt",
    "ContactResult",
    "ContactSource",
    "RobotLoad",
    "MoverWrench",
    "LoadSource",
    "LoadList",
    "Bounds",
    "PowerBalance",
    "Audit",
    "StepAudit",
    "CompliantStep",
    "UnprovenExtreme",
    "Motion",
    "Solution",
    "Later",
    "LaterField",
]

Status = Literal["solved", "ambiguous", "jammed", "unstable", "failed"]
Mode = Literal["rolling", "sliding", "separating"]
Bounds = tuple[float | None, float | None]
"""``(lo, hi)`` of a quantity over every consistent force distribution; None where it is unbounded."""

T = TypeVar("T")


class Later(Generic[T]):
    """A value worked out when first read, then kept.

    Whether a solved motion's contact forces are indeterminate costs more than the rest of a small
    certified solve (a rank test, often an LP); a simulation step or a sweep that never reads it does
    not pay. The value is the one an eager solve would have given: the same function, only called later.
    Pickled (a batch's worker, a saved answer), it is worked out first and travels as its value.
    """

    __slots__ = ("_work", "_value")

    def __init__(self, work: Callable[[], T]) -> None:
        self._work: Callable[[], T] | None = work
        self._value: T | None = None

    @classmethod
    def known(cls, value: T) -> Later[T]:
        """A Later that already holds its value."""
        later = cls(_nothing)
        later._work, later._value = None, value
        return later

    @property
    def decided(self) -> bool:
        """Whether the value has been worked out (reading :meth:`value` does it)."""
        return self._work is None

    def value(self) -> T:
        if self._work is not None:
            self._value = self._work()
            self._work = None  # drop the solver's data it held
        return self._value  # type: ignore[return-value]  # set just above

    def __reduce__(self) -> tuple[Any, ...]:
        return (Later.known, (self.value(),))


def _nothing() -> Any:
    return None


class LaterField(Generic[T]):
    """A frozen dataclass field that holds its value, or a :class:`Later` of it: reading it gives the value.

    ``Solution(..., forces_indeterminate=Later(decide))`` decides only when ``solution.forces_indeterminate``
    (or anything that shows it: the message, the JSON, the table, ``==``) is read.
    """

    def __init__(self, default: T | None = None, *, required: bool = False) -> None:
        self.default, self.required, self.name = default, required, ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> T: ...
    @overload
    def __get__(self, obj: object, owner: type | None = None) -> T: ...
    def __get__(self, obj: object | None, owner: type | None = None) -> T:
        if obj is None:  # the class's own attribute: what dataclass reads as the field's default
            if self.required:
                raise AttributeError(self.name)
            return self.default  # type: ignore[return-value]  # a default is given unless required
        value = obj.__dict__[self.name]
        return value.value() if isinstance(value, Later) else value  # type: ignore[no-any-return]

    def __set__(self, obj: object, value: T | Later[T]) -> None:
        obj.__dict__[self.name] = value  # frozen dataclasses set their fields through object.__setattr__, here

    def kept(self, obj: object) -> T | Later[T]:
        """What ``obj`` holds: the value, or its :class:`Later` undecided (another value sharing it decides it once for both)."""
        return obj.__dict__[self.name]  # type: ignore[no-any-return]

    def decided(self, obj: object) -> bool:
        """Whether ``obj``'s value is known without working anything out."""
        value = obj.__dict__[self.name]
        return not isinstance(value, Later) or value.decided


class Diagnosis(enum.Enum):
    """Why no motion exists."""

    KINEMATIC = "kinematic"
    """jammed: every twist of the free bodies would let a mover penetrate them."""
    WEDGED = "wedged"
    """jammed: the parts could rest, but friction wedges them against the commanded motion."""
    PRESCRIBED_MODES = "prescribed_modes"
    """jammed: no motion has the prescribed contact modes."""
    NO_EQUILIBRIUM = "no_equilibrium"
    """unstable: no force in the friction cones balances the load."""


class CertificateKind(enum.Enum):
    """What kind of proof stands behind a verdict."""

    FARKAS = "farkas"
    """Multipliers y >= 0 with Jn^T y = 0 and bn.y > 0: no twist keeps every contact from penetrating."""
    RAY = "ray"
    """A twist d with Jn d >= 0 along which the load does positive work: no equilibrium."""
    INFEASIBLE_EQUILIBRIUM = "infeasible_equilibrium"
    """The LP of forces in (circumscribed) friction cones that balance the load is infeasible."""
    COMPLETE_SEARCH = "complete_search"
    """A complete mixed-integer search found no motion (within the pyramid model it searched)."""
    SECTOR_RELAXATION = "sector_relaxation"
    """A relaxation of the exact-cone laws (slips in sectors) is infeasible."""
    GLOBAL_OPTIMUM = "global_optimum"
    """The paper's minimum-power program has a positive global minimum (no power-balanced motion)."""


@dataclass(frozen=True)
class Certificate:
    """The proof behind a verdict.

    Attributes
    ----------
    kind : CertificateKind
    text : str
        What was proven, in words.
    data : tuple of float
        The certificate's numbers where they are small enough to report
        (Farkas multipliers per contact, a ray's twist direction); else empty.
    """

    kind: CertificateKind
    text: LaterField[str] = LaterField(required=True)  # each may be a Later: a certificate the verdict does not rest on
    data: LaterField[tuple[float, ...]] = LaterField(())  # (the direction of a fall, an LP) is worked out when read

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind.value, "text": self.text, "data": [float(x) for x in self.data]}


@dataclass(frozen=True)
class Attempt:
    """A method tried before the one that answered, and why its answer was not kept."""

    method: str
    message: str


@dataclass(frozen=True)
class ContactResult:
    """One contact of one motion, in physical units and world frame.

    Attributes
    ----------
    body, other : str
    mode : {"rolling", "sliding", "separating"}
    force : array (d,)
        Contact force on ``body`` [force].
    normal_force : float
        Its component along the normal [force], >= 0.
    slip : array (d,)
        Tangential velocity of ``body`` relative to ``other`` at the point [length/time].
    normal_velocity : float
        Normal relative velocity [length/time]; > 0 means separating.
    normal_force_range : (lo, hi) or None
        When forces are indeterminate: the normal force's range over every force
        distribution consistent with the motion; ``hi`` is None when unbounded.
    """

    body: str
    other: str
    mode: Mode
    force: np.ndarray
    normal_force: float
    slip: np.ndarray
    normal_velocity: float
    normal_force_range: tuple[float, float | None] | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "body": self.body,
            "other": self.other,
            "mode": self.mode,
            "force": _floats(self.force),
            "normal_force": float(self.normal_force),
            "slip": _floats(self.slip),
            "normal_velocity": float(self.normal_velocity),
        }
        if self.normal_force_range is not None:
            lo, hi = self.normal_force_range
            out["normal_force_range"] = [float(lo), None if hi is None else float(hi)]
        return out


@dataclass(frozen=True)
class RobotLoad:
    """The joint torques a robot must supply to hold one motion's contact forces.

    Sign: ``torques = sum_i J_i^T f_i`` over the robot's contacts, with ``f_i`` the
    contact force on the free body (:attr:`ContactResult.force`), which is the force the
    robot's link applies, and ``J_i`` the contact's ``jacobian`` (world velocity of the
    link's point per unit joint velocity). Then ``torques . qdot = sum_i f_i . (J_i qdot)``:
    the power the robot puts in through its contacts. A robot holding a weight up sees the
    torque that raising it would need. Gravity on the robot's own links is not included
    (the scene does not model their masses).

    Attributes
    ----------
    robot : str
    joints : tuple of str
        One label per joint, in Jacobian column order: the joint names of a URDF robot (or
        of ``Robot(joint_names=...)``), else ``joint[0]``, ``joint[1]``, ...
    torques : array (n_joints,)
        The torques of the motion's reported force distribution [force x length per
        radian for a revolute joint, force for a prismatic one].
    torque_ranges : tuple of (lo, hi) or None
        When the forces are indeterminate: each torque's range over every force
        distribution consistent with the motion (None for an unbounded side).
    torque_limits : array (n_joints,) or None
        The robot's limits ``|torque_j| <= limit_j``, when the scene gives them.
    limits_exceeded : tuple of str
        Joints whose limits no consistent force distribution can meet: the motion is
        infeasible for this robot. When no joint fails alone but several cannot be met
        together, a smallest such set of joints. The motion's status is unchanged: the
        rigid model still predicts it.
    """

    robot: str
    joints: tuple[str, ...]
    torques: np.ndarray
    torque_ranges: tuple[Bounds, ...] | None = None
    torque_limits: np.ndarray | None = None
    limits_exceeded: tuple[str, ...] = ()

    @property
    def within_limits(self) -> bool:
        """False when the motion needs more torque than the limits allow at some joint."""
        return not self.limits_exceeded

    def to_dict(self) -> dict[str, Any]:
        return {
            "robot": self.robot,
            "joints": list(self.joints),
            "torques": _floats(self.torques),
            "torque_ranges": _bounds(self.torque_ranges),
            "torque_limits": None if self.torque_limits is None else _floats(self.torque_limits),
            "within_limits": self.within_limits,
            "limits_exceeded": list(self.limits_exceeded),
        }


@dataclass(frozen=True)
class MoverWrench:
    """The net wrench a mover applies to the free bodies through its contacts, in one motion.

    Sign: the sum of the contact forces on the bodies (:attr:`ContactResult.force`) at
    the mover's contacts, and their moment about the mover's ``origin``; what the mover's
    drive must supply to hold its prescribed motion. The mover itself feels the opposite.
    A table carrying a box's weight ``m g`` applies ``-m g``.

    Attributes
    ----------
    mover : str
    origin : array (d,)
        The point the moment is taken about: the mover's ``origin`` (world origin by default) [length].
    force : array (d,)
        Net force [force].
    moment : array (1,) in 2-D (about z) or (3,) in 3-D
        Net moment about ``origin`` [force x length].
    ranges : tuple of (lo, hi) or None
        When the forces are indeterminate: the range of each entry of ``[force, moment]``
        over every force distribution consistent with the motion.
    """

    mover: str
    origin: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    ranges: tuple[Bounds, ...] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "mover": self.mover,
            "origin": _floats(self.origin),
            "force": _floats(self.force),
            "moment": _floats(self.moment),
            "ranges": _bounds(self.ranges),
        }


class LoadSource(Protocol):
    """Where a Motion's robot loads and mover wrenches come from: worked out when first read."""

    def robot_loads(self) -> tuple[RobotLoad, ...]: ...

    def mover_wrenches(self) -> tuple[MoverWrench, ...]: ...

    def force_ranges(self) -> tuple[tuple[Bounds, ...] | None, ...] | None: ...


@dataclass(frozen=True)
class LoadList:
    """A :class:`LoadSource` that already holds its values."""

    robots: tuple[RobotLoad, ...] = ()
    movers: tuple[MoverWrench, ...] = ()

    def robot_loads(self) -> tuple[RobotLoad, ...]:
        return self.robots

    def mover_wrenches(self) -> tuple[MoverWrench, ...]:
        return self.movers

    def force_ranges(self) -> tuple[tuple[Bounds, ...] | None, ...] | None:
        return None


@dataclass(frozen=True)
class PowerBalance:
    """Power balance of eq. 19, generalised to tangential mover motion [force x length/time].

    Attributes
    ----------
    input : float
        Power delivered by the movers through the contact forces.
    gravity : float
        Rate of potential-energy gain plus work against applied wrenches.
    dissipation : float
        Power lost to friction, >= 0.
    residual : float
        ``input - gravity - dissipation``; zero when the laws hold.
    """

    input: float
    gravity: float
    dissipation: float
    residual: float

    def to_dict(self) -> dict[str, float]:
        return {k: float(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class Audit:
    """Residuals of the laws on the original scene data, each relative to the scene's scales.

    Attributes
    ----------
    equilibrium : float
        Largest unbalanced force (per force scale) or moment (per force x length).
    cone : float
        Largest excursion of a force outside its friction cone (or below zero normal force).
    complementarity : float
        Largest penetration velocity or normal force times normal velocity.
    dissipation : float
        Largest shortfall from maximum dissipation at a sliding contact (per power scale)
        and, for exact 3-D cones, largest distance of a sliding contact's friction from
        ``-mu f_n slip/|slip|`` (per force scale): an error in its direction counts linearly.
    power : float
        Power-balance residual per power scale.
    tolerance : float
        Threshold every residual must meet.
    """

    equilibrium: float
    cone: float
    complementarity: float
    dissipation: float
    power: float
    tolerance: float

    @property
    def passed(self) -> bool:
        t = self.tolerance  # written out: this runs after every solve (a NaN residual fails)
        return self.equilibrium <= t and self.cone <= t and self.complementarity <= t and self.dissipation <= t and self.power <= t

    def residuals(self) -> dict[str, float]:
        return {
            "equilibrium": self.equilibrium,
            "cone": self.cone,
            "complementarity": self.complementarity,
            "dissipation": self.dissipation,
            "power": self.power,
        }

    def failures(self) -> list[str]:
        """Names of the laws whose residual exceeds the tolerance."""
        return [k for k, v in self.residuals().items() if not v <= self.tolerance]

    def to_dict(self) -> dict[str, Any]:
        return {**{k: float(v) for k, v in self.residuals().items()}, "tolerance": self.tolerance, "passed": self.passed}


@dataclass(frozen=True)
class StepAudit:
    """Residuals of the compliant step's laws on the scene data, each relative to the scene's scales.

    Attributes
    ----------
    equilibrium : float
        Largest unbalanced force (per force scale) or moment (per force x length scale).
    cone : float
        Largest excursion of a force outside its friction cone or below zero normal force (per force scale).
    compatibility : float
        Largest mismatch, per displacement scale (the largest commanded advance or spring deflection), between
        what the springs of a stuck contact deflect and how far the bodies and movers moved there; at an open
        contact, the penetration of its gap; at a contact at its friction limit, the part of the slip not
        opposite to its friction.
    tolerance : float
    """

    equilibrium: float
    cone: float
    compatibility: float
    tolerance: float

    @property
    def passed(self) -> bool:
        t = self.tolerance
        return self.equilibrium <= t and self.cone <= t and self.compatibility <= t

    def to_dict(self) -> dict[str, Any]:
        residuals = {"equilibrium": self.equilibrium, "cone": self.cone, "compatibility": self.compatibility}
        return {**{k: float(v) for k, v in residuals.items()}, "tolerance": self.tolerance, "passed": self.passed}


@dataclass(frozen=True)
class CompliantStep:
    """What the contact springs do when the movers advance for ``closing_time`` (``Scene.closing_time``).

    The answer when the rigid model has none (``jammed``: a squeeze) or many (``ambiguous``): the bodies'
    small displacement and the forces of least complementary energy, 1/2 f.C f minus the work of the
    movers' advance. Exact while every loaded contact sticks; a contact at its friction limit would slip,
    which this static step does not model: ``valid`` is then False and the numbers are not an answer.

    Attributes
    ----------
    closing_time : float
        [time]
    displacements : dict name -> array (3,) in 2-D or (6,) in 3-D
        Each body's displacement over the step: its com's, then its (small) rotation [length, rad].
    forces : array (m, d)
        Contact forces on each ``body``, world frame [force].
    normal_forces : tuple of float
        Their components along the contact normals [force], >= 0.
    states : tuple of {"stuck", "at friction limit", "open"}
    audit : StepAudit
    valid : bool
        The audit passed and no loaded contact is at its friction limit.
    message : str
    """

    closing_time: float
    displacements: dict[str, np.ndarray]
    forces: np.ndarray
    normal_forces: tuple[float, ...]
    states: tuple[str, ...]
    audit: StepAudit
    valid: bool
    message: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "closing_time": float(self.closing_time),
            "valid": self.valid,
            "message": self.message,
            "displacements": {name: _floats(d) for name, d in self.displacements.items()},
            "contacts": [
                {"force": _floats(f), "normal_force": float(n), "state": state}
                for f, n, state in zip(self.forces, self.normal_forces, self.states, strict=True)
            ],
            "audit": self.audit.to_dict(),
        }


class ContactSource(Protocol):
    """Where a Motion's per-contact results come from: built when first read (solves that only need
    twists, statuses and audits, as batches do, never pay for one object per contact)."""

    def results(self) -> tuple[ContactResult, ...]: ...

    def modes(self) -> tuple[Mode, ...]: ...

    def forces_and_slips(self) -> tuple[np.ndarray, np.ndarray]: ...

    def forces_indeterminate(self) -> bool: ...


@dataclass(frozen=True)
class ContactList:
    """A :class:`ContactSource` that already holds its results."""

    contacts: tuple[ContactResult, ...]

    def results(self) -> tuple[ContactResult, ...]:
        return self.contacts

    def modes(self) -> tuple[Mode, ...]:
        return tuple(c.mode for c in self.contacts)

    def forces_and_slips(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([c.force for c in self.contacts]), np.array([c.slip for c in self.contacts])

    def forces_indeterminate(self) -> bool:
        return any(c.normal_force_range is not None for c in self.contacts)


@dataclass(frozen=True)
class UnprovenExtreme:
    """An extreme twist a method gave for a continuum that the audit did not pass: not a motion, not listed as one.

    Attributes
    ----------
    twists : dict name -> array
        Its body twists, as :attr:`Motion.twists`.
    audit : Audit or None
        The audit with the forces the method found at it; None when it found none.
    """

    twists: dict[str, np.ndarray]
    audit: Audit | None

    def to_dict(self) -> dict[str, Any]:
        return {"twists": {n: _floats(t) for n, t in self.twists.items()}, "audit": None if self.audit is None else self.audit.to_dict()}


@dataclass(frozen=True)
class Motion:
    """One motion that satisfies the laws: twists, contacts, power and its audit.

    Attributes
    ----------
    twists : dict name -> array (3,) in 2-D or (6,) in 3-D
        Linear velocity of the com, then angular velocity, world frame.
    source : ContactSource
        The per-contact results, read through :attr:`contacts` and :attr:`modes`.
    power : PowerBalance
    audit : Audit
    continuum : bool
        True when this motion stands for a continuum of motions with the same
        contact modes; ``extreme_twists`` then lists its extreme motions along
        each twist coordinate and ``unbounded`` says whether it extends to infinity.
    free_directions : tuple of str
        For an unbounded continuum: the twist entries that grow (``+``) or fall (``-``)
        without bound, e.g. ``("box v_x +",)``.
    extreme_audits : tuple of Audit
        The audit of each of ``extreme_twists``, in order, with the forces found at it: every listed
        extreme passed its own (an extreme is a motion too).
    unproven_extremes : tuple of UnprovenExtreme
        Extremes the method gave that failed their audit (or had no forces): not motions, so not in
        ``extreme_twists``; kept to show what was refused.
    loads : LoadSource
        The robot loads and mover wrenches, read through :attr:`robot_loads` and :attr:`mover_wrenches`.
    """

    twists: dict[str, np.ndarray]
    source: ContactSource = field(repr=False, compare=False)
    power: PowerBalance
    audit: Audit
    continuum: bool = False
    extreme_twists: tuple[dict[str, np.ndarray], ...] = ()
    unbounded: bool = False
    free_directions: tuple[str, ...] = ()
    loads: LoadSource = field(default=LoadList(), repr=False, compare=False)
    extreme_audits: tuple[Audit, ...] = ()
    unproven_extremes: tuple[UnprovenExtreme, ...] = ()

    def __getstate__(self) -> dict[str, Any]:
        # Twists as floats in lists: pickling small arrays costs more than the numbers in them.
        state = dict(self.__dict__)
        state["twists"] = [(name, np.shape(t), np.asarray(t, dtype=float).ravel().tolist()) for name, t in self.twists.items()]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        state["twists"] = {name: np.array(values, dtype=float).reshape(shape) for name, shape, values in state["twists"]}
        self.__dict__.update(state)

    @cached_property
    def contacts(self) -> tuple[ContactResult, ...]:
        """Each contact's result, in scene order."""
        return self.source.results()

    @property
    def modes(self) -> tuple[Mode, ...]:
        return self.source.modes()

    def forces_and_slips(self) -> tuple[np.ndarray, np.ndarray]:
        """Each contact's force and slip (m, d), world frame, as :attr:`contacts` gives them, without working
        out the force ranges (a simulation records these at every step)."""
        return self.source.forces_and_slips()

    @property
    def forces_indeterminate(self) -> bool:
        """The motion is determined but its contact forces are not: each contact carries ``normal_force_range``."""
        return self.source.forces_indeterminate()

    @cached_property
    def robot_loads(self) -> tuple[RobotLoad, ...]:
        """Each robot's joint torques (and their ranges and limits), in scene order."""
        return self.loads.robot_loads()

    @cached_property
    def mover_wrenches(self) -> tuple[MoverWrench, ...]:
        """The net wrench of each mover that touches a free body, in scene order."""
        return self.loads.mover_wrenches()

    @cached_property
    def force_ranges(self) -> tuple[tuple[Bounds, ...] | None, ...] | None:
        """When the forces are indeterminate: each frictional contact's world force components' ranges,
        ``((lo, hi) per axis)`` [force] (None for a frictionless contact, whose ``normal_force_range`` says
        all; an end is None when unbounded). None when the forces are unique, or not known."""
        return self.loads.force_ranges() if self.forces_indeterminate else None

    @property
    def torque_limits_exceeded(self) -> dict[str, tuple[str, ...]]:
        """Robot name -> the joints whose torque limits this motion cannot meet; empty when every limit holds."""
        return {load.robot: load.limits_exceeded for load in self.robot_loads if load.limits_exceeded}

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "bodies": {name: {"twist": _floats(t)} for name, t in self.twists.items()},
            "modes": list(self.modes),
            "contacts": self._contact_dicts(),
            "power": self.power.to_dict(),
            "audit": self.audit.to_dict(),
            "forces_indeterminate": self.forces_indeterminate,
            "robot_loads": [load.to_dict() for load in self.robot_loads],
            "mover_wrenches": [wrench.to_dict() for wrench in self.mover_wrenches],
        }
        if self.continuum:
            out["continuum"] = True
            out["unbounded"] = self.unbounded
            out["free_directions"] = list(self.free_directions)
            out["extreme_twists"] = [{n: _floats(t) for n, t in e.items()} for e in self.extreme_twists]
            out["extreme_audits"] = [audit.to_dict() for audit in self.extreme_audits]
            out["unproven_extremes"] = [extreme.to_dict() for extreme in self.unproven_extremes]
        return out

    def _contact_dicts(self) -> list[dict[str, Any]]:
        contacts = [c.to_dict() for c in self.contacts]
        for out, bounds in zip(contacts, self.force_ranges or (), strict=False):
            if bounds is not None:
                out["force_range"] = [[_end(lo), _end(hi)] for lo, hi in bounds]
        return contacts


def _end(value: float | None) -> float | None:
    return None if value is None else float(value)


class SolveSource(Protocol):
    """What a Solution keeps of the solve that made it (:class:`quasistatic.derivative.SolvedScene`, set by ``solve``).

    ``scene`` is the Scene it was solved from (typed loosely: this module imports nothing of the package).
    """

    @property
    def scene(self) -> Any: ...

    def sensitivity(self, solution: Solution, inputs: Collection[str] | None = None, geometry: bool = False) -> Any: ...


@dataclass(frozen=True)
class Solution:
    """The answer to one forward object motion problem.

    Attributes
    ----------
    status : {"solved", "ambiguous", "jammed", "unstable", "failed"}
    message : str
        One sentence a person can act on (a solved motion's claim about its forces is
        worked out when the message is first read).
    method : str
        The solver backend that produced the answer.
    friction : str
        The friction model used (``exact``, ``pyramid:K`` or ``none``).
    motion : Motion or None
        The motion reported (for ``ambiguous``: the first of ``solutions``).
    solutions : tuple of Motion
        Every distinct motion when ``ambiguous`` (a continuum is one entry with
        ``continuum`` set); otherwise empty.
    forces_indeterminate : bool
        The reported motion is determined but its contact forces are not; each
        contact then carries ``normal_force_range``. (For ``ambiguous``, each
        listed motion says the same of itself.) Decided when first read (here, in
        the message, the JSON or the table): a caller that never reads it does not pay.
    compliant_forces : bool
        The reported forces are the compliant ones: of the forces the rigid motion allows,
        those of least elastic energy of the scene's contact springs and joint stiffness
        (:mod:`quasistatic.solvers.compliance`), unique and audited; ``forces_indeterminate``
        is then False.
    compliant_step : CompliantStep or None
        With ``Scene.closing_time``, when the rigid answer is ``jammed`` or ``ambiguous``: what the
        contact springs do as the movers advance for that time (a squeeze force, a held or slipping grasp).
    certified : bool
        The verdict is proven: ``solved`` means the only motion, ``ambiguous``
        lists motions that all satisfy the laws, ``jammed``/``unstable`` carry a
        certificate. False for an answer found but not proven (the fast path's
        first motion, the paper's global minimiser).
    diagnosis : Diagnosis or None
        Why no motion exists, for ``jammed`` and ``unstable``.
    certificate : Certificate or None
        The proof behind the verdict, when there is one to show.
    search_complete : bool or None
        For a search over motions: whether the list of motions is complete.
    prescribed_modes : tuple or None
        The contact modes the solve was asked to respect.
    fallback : tuple of Attempt
        Methods tried first whose answer was not kept, in order.
    seconds : float
        Wall time of the whole solve, audit included [s].
    notes : tuple of (name, value) pairs
        Solver-specific remarks for people (pivots, stages, formulations); ``details`` shows them as a dict.
    source : SolveSource or None
        The scene this answer was solved from (``solve`` and ``solve_many`` set it), so that :meth:`sensitivity`
        needs no arguments; not compared, not printed, not in :meth:`to_dict` and not pickled. None for a
        Solution built by hand or read back from a pickle.
    """

    status: Status
    message: LaterField[str] = LaterField(required=True)  # no default: reading it from the class raises AttributeError
    method: str  # type: ignore[misc]  # mypy takes any descriptor for a default; the message has none
    friction: str  # type: ignore[misc]
    motion: Motion | None = None
    solutions: tuple[Motion, ...] = ()
    forces_indeterminate: LaterField[bool] = LaterField(False)
    compliant_forces: bool = False
    compliant_step: CompliantStep | None = None
    certified: bool = False
    diagnosis: Diagnosis | None = None
    certificate: Certificate | None = None
    search_complete: bool | None = None
    prescribed_modes: tuple[Mode | None, ...] | None = None
    fallback: tuple[Attempt, ...] = ()
    seconds: float = 0.0
    notes: tuple[tuple[str, Any], ...] = ()
    source: SolveSource | None = field(default=None, repr=False, compare=False)

    @property
    def scene(self) -> Any:
        """The Scene this answer was solved from (None for a Solution built by hand)."""
        return None if self.source is None else self.source.scene

    def sensitivity(self, inputs: Collection[str] | None = None, geometry: bool = False) -> Any:
        """The exact derivative of this answer's motion with respect to its scene's inputs (issue 15).

        Returns a :class:`quasistatic.Sensitivity`, or a :class:`quasistatic.NoSensitivity` saying why there is
        none (not ``solved``, forces indeterminate, a mode boundary), exactly as
        ``quasistatic.sensitivity(solution.scene, solution, inputs=inputs, geometry=geometry)``. ``inputs`` names
        the robots and movers to differentiate by (all by default); ``geometry`` adds the derivative with respect
        to the contact points and normals.
        """
        if self.source is None:
            raise ValueError(
                "source: this Solution was not made by solve(), so it has no scene to differentiate; use qs.sensitivity(scene, solution)"
            )
        return self.source.sensitivity(self, inputs, geometry)

    def kept_message(self) -> str | Later[str]:
        """The message, or its :class:`Later` undecided: a record sharing it (a simulation step) decides it once for both."""
        field: LaterField[str] = type(self).__dict__["message"]
        return field.kept(self)

    def __getstate__(self) -> dict[str, Any]:
        # Pickled without its scene: a batch's worker would ship back the scene its parent holds, doubling the cost
        # of returning a small answer; solve_many attaches the parent's own scene again.
        return {**self.__dict__, "source": None}

    @property
    def twists(self) -> dict[str, np.ndarray]:
        return self.motion.twists if self.motion else {}

    @property
    def contacts(self) -> tuple[ContactResult, ...]:
        return self.motion.contacts if self.motion else ()

    @property
    def modes(self) -> tuple[Mode, ...]:
        return self.motion.modes if self.motion else ()

    @property
    def power(self) -> PowerBalance | None:
        return self.motion.power if self.motion else None

    @property
    def robot_loads(self) -> tuple[RobotLoad, ...]:
        """The reported motion's joint torques per robot (see :class:`RobotLoad`)."""
        return self.motion.robot_loads if self.motion else ()

    @property
    def mover_wrenches(self) -> tuple[MoverWrench, ...]:
        """The reported motion's net wrench per loaded mover (see :class:`MoverWrench`)."""
        return self.motion.mover_wrenches if self.motion else ()

    @property
    def audit(self) -> Audit | None:
        return self.motion.audit if self.motion else None

    @property
    def ok(self) -> bool:
        """True for ``solved``: one motion, audited."""
        return self.status == "solved"

    @property
    def details(self) -> dict[str, Any]:
        """The typed fields above as the flat dict of earlier versions (and of the JSON's ``details``).

        Keys: ``uniqueness`` (when a motion is not certified), ``certificate`` (its text),
        ``search`` ("complete" or why not), ``modes`` (prescribed), ``fallback``
        ({method: message}), and every note.
        """
        out: dict[str, Any] = {}
        if not self.certified and self.status in ("solved", "ambiguous"):
            out["uniqueness"] = "not checked"
        if self.certificate is not None:
            out["certificate"] = self.certificate.text
        if self.search_complete is not None:
            out["search"] = (
                "complete"
                if self.search_complete
                else f"stopped after {len(self.solutions) or int(self.motion is not None)} motions (limit or time)"
            )
        if self.prescribed_modes is not None:
            out["modes"] = list(self.prescribed_modes)
        out.update(dict(self.notes))
        if self.fallback:
            out["fallback"] = {attempt.method: attempt.message for attempt in self.fallback}
        return out

    def _repr_png_(self) -> bytes | None:
        """Jupyter's picture of this answer: each contact's normal force coloured by its mode (a Solution holds no
        geometry; ``quasistatic.viz.plot(solution, scene)`` draws it on its scene). None without matplotlib."""
        from .viz.chart import summary_png  # the one way from a value to the pictures; chart imports no value type

        return summary_png(self)

    def _repr_html_(self) -> str:
        """Jupyter's view of this answer: the verdict, whether it is proven and audited, the contacts' modes, forces
        and slips as a table, the twists, and the picture of :meth:`_repr_png_` when matplotlib is installed."""
        from .viz.chart import summary_html

        return summary_html(self)

    def to_dict(self) -> dict[str, Any]:
        """Exactly what ``quasistatic solve --json`` prints."""
        out: dict[str, Any] = {
            "status": self.status,
            "message": self.message,
            "method": self.method,
            "friction": self.friction,
            "certified": self.certified,
            "forces_indeterminate": self.forces_indeterminate,
            "compliant_forces": self.compliant_forces,
        }
        if self.motion is not None:
            motion = self.motion.to_dict()
            out["bodies"] = motion["bodies"]
            out["contacts"] = motion["contacts"]
            out["power"] = motion["power"]
            out["audit"] = motion["audit"]
            out["robot_loads"] = motion["robot_loads"]
            out["mover_wrenches"] = motion["mover_wrenches"]
        else:
            out["bodies"], out["contacts"], out["power"], out["audit"] = {}, [], None, None
            out["robot_loads"], out["mover_wrenches"] = [], []
        out["solutions"] = [m.to_dict() for m in self.solutions]
        out["diagnosis"] = None if self.diagnosis is None else self.diagnosis.value
        out["certificate"] = None if self.certificate is None else self.certificate.to_dict()
        out["search_complete"] = self.search_complete
        out["fallback"] = [{"method": a.method, "message": a.message} for a in self.fallback]
        out["compliant_step"] = None if self.compliant_step is None else self.compliant_step.to_dict()
        out["seconds"] = float(self.seconds)
        details = self.details
        if details:
            out["details"] = details
        return out


def _bounds(ranges: tuple[Bounds, ...] | None) -> list[list[float | None]] | None:
    if ranges is None:
        return None
    return [[None if lo is None else float(lo) + 0.0, None if hi is None else float(hi) + 0.0] for lo, hi in ranges]


def _floats(array: np.ndarray) -> list[float]:
    return [float(x) + 0.0 for x in np.asarray(array).ravel()]  # + 0.0: no "-0.0" in output
