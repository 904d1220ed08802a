"""What a solve returns: a status, the motion(s), forces, modes, power and audit."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

import numpy as np

__all__ = ["Status", "Mode", "ContactResult", "PowerBalance", "Audit", "Motion", "Solution"]

Status = Literal["solved", "ambiguous", "jammed", "unstable", "failed"]
Mode = Literal["rolling", "sliding", "separating"]


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
        Largest shortfall from maximum dissipation at a sliding contact.
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


class _ContactSource(Protocol):
    """Per-contact results kept as arrays until a Motion's ``contacts`` are first read."""

    def results(self) -> tuple[ContactResult, ...]: ...

    def modes(self) -> tuple[Mode, ...]: ...


@dataclass(frozen=True)
class Motion:
    """One motion that satisfies the laws: twists, contacts, power and its audit.

    Attributes
    ----------
    twists : dict name -> array (3,) in 2-D or (6,) in 3-D
        Linear velocity of the com, then angular velocity, world frame.
    contacts : tuple of ContactResult, in scene order
        (For a motion returned by a solve, made from the audit's arrays when first read.)
    power : PowerBalance
    audit : Audit
    continuum : bool
        True when this motion stands for a continuum of motions with the same
        contact modes; ``extreme_twists`` then lists its extreme motions along
        each twist coordinate and ``unbounded`` says whether it extends to infinity.
    """

    twists: dict[str, np.ndarray]
    contacts: tuple[ContactResult, ...]
    power: PowerBalance
    audit: Audit
    continuum: bool = False
    extreme_twists: tuple[dict[str, np.ndarray], ...] = ()
    unbounded: bool = False

    def __getstate__(self) -> dict[str, Any]:
        # Twists as floats in lists: pickling small arrays costs more than the numbers in them.
        state = dict(self.__dict__)
        state["twists"] = [(name, np.shape(t), np.asarray(t, dtype=float).ravel().tolist()) for name, t in self.twists.items()]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        state["twists"] = {name: np.array(values, dtype=float).reshape(shape) for name, shape, values in state["twists"]}
        self.__dict__.update(state)

    @property
    def modes(self) -> tuple[Mode, ...]:
        source = self.__dict__.get("_contact_source")
        if source is not None and "contacts" not in self.__dict__:
            return source.modes()  # type: ignore[no-any-return]
        return tuple(c.mode for c in self.contacts)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "bodies": {name: {"twist": _floats(t)} for name, t in self.twists.items()},
            "modes": list(self.modes),
            "contacts": [c.to_dict() for c in self.contacts],
            "power": self.power.to_dict(),
            "audit": self.audit.to_dict(),
        }
        if self.continuum:
            out["continuum"] = True
            out["unbounded"] = self.unbounded
            out["extreme_twists"] = [{n: _floats(t) for n, t in e.items()} for e in self.extreme_twists]
        return out


class _LazyContacts:
    """``Motion.contacts`` of a motion made by :func:`_lazy_motion`: built on first read, then kept.

    A non-data descriptor: a Motion built the ordinary way holds ``contacts`` in its
    ``__dict__``, which takes precedence, so this only runs for lazily built ones.
    """

    def __get__(self, motion: Motion | None, owner: type | None = None) -> Any:
        if motion is None:
            return self
        contacts = motion.__dict__["_contact_source"].results()
        motion.__dict__["contacts"] = contacts  # frozen: set once, as the constructor would have
        return contacts


Motion.contacts = _LazyContacts()  # type: ignore[assignment]  # after @dataclass, so it is no default


def _lazy_motion(
    twists: dict[str, np.ndarray],
    source: _ContactSource,
    power: PowerBalance,
    audit: Audit,
    continuum: bool = False,
    extreme_twists: tuple[dict[str, np.ndarray], ...] = (),
    unbounded: bool = False,
) -> Motion:
    """A Motion whose ``contacts`` are made from ``source`` when first read (equal to an eager one).

    Solves that only need the twists, statuses and audits (batches, benchmarks,
    simulation steps) then never pay for one object per contact; the source
    (arrays) also pickles faster than the objects would.
    """
    motion = object.__new__(Motion)
    motion.__dict__.update(
        twists=twists,
        power=power,
        audit=audit,
        continuum=continuum,
        extreme_twists=extreme_twists,
        unbounded=unbounded,
        _contact_source=source,
    )
    return motion


@dataclass(frozen=True)
class Solution:
    """The answer to one forward object motion problem.

    Attributes
    ----------
    status : {"solved", "ambiguous", "jammed", "unstable", "failed"}
    message : str
        One sentence a person can act on.
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
        The motion is determined but the contact forces are not; each contact
        then carries ``normal_force_range``.
    """

    status: Status
    message: str
    method: str
    friction: str
    motion: Motion | None = None
    solutions: tuple[Motion, ...] = ()
    forces_indeterminate: bool = False
    details: dict[str, Any] = field(default_factory=dict)

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
    def audit(self) -> Audit | None:
        return self.motion.audit if self.motion else None

    @property
    def ok(self) -> bool:
        """True for ``solved``: one motion, audited."""
        return self.status == "solved"

    def to_dict(self) -> dict[str, Any]:
        """Exactly what ``quasistatic solve --json`` prints."""
        out: dict[str, Any] = {
            "status": self.status,
            "message": self.message,
            "method": self.method,
            "friction": self.friction,
            "forces_indeterminate": self.forces_indeterminate,
        }
        if self.motion is not None:
            motion = self.motion.to_dict()
            out["bodies"] = motion["bodies"]
            out["contacts"] = motion["contacts"]
            out["power"] = motion["power"]
            out["audit"] = motion["audit"]
        else:
            out["bodies"], out["contacts"], out["power"], out["audit"] = {}, [], None, None
        out["solutions"] = [m.to_dict() for m in self.solutions]
        if self.details:
            out["details"] = self.details
        return out


def _floats(array: np.ndarray) -> list[float]:
    return [float(x) + 0.0 for x in np.asarray(array).ravel()]  # + 0.0: no "-0.0" in output
