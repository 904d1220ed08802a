"""Scenes: free bodies, movers, robots and contacts, validated once and frozen.

Each part converts its own numbers to read-only float arrays when it is
built; :class:`Scene` then checks what needs the whole scene (lengths for the
dimension, names, unit normals, robot Jacobians) and keeps *new* parts with
the defaults filled in, so the caller's objects are never changed. Later
stages can trust a Scene without checking it again.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..tolerances import MAX_FRICTION, MAX_MAGNITUDE, MAX_NAME_LENGTH, MAX_PYRAMID_EDGES, NORMAL_LENGTH
from .friction import FrictionModel, parse_friction

__all__ = ["Body", "Mover", "Robot", "Contact", "Scene", "Stiffness", "FloatArray", "checked_array", "checked_number"]

FloatArray = npt.NDArray[np.float64]
T = TypeVar("T")

_TOO_LARGE = "larger numbers overflow the solvers' products; choose other units"
_MU_TOO_LARGE = "beyond the solvers' precision; mu = 1000 already grips like infinite friction"
_SHOWN_NAMES = 10  # known names listed when a name names nothing
_SCALAR_CHECK = 32  # arrays of at most this many entries are range-checked in Python, larger ones by numpy
_FRICTION_TEXT_LENGTH = 40  # longer text is no friction model ("pyramid:" and a thousand digits)


def checked_array(value: Any, path: str, ndim: int = 1) -> FloatArray:
    """A read-only float array of ``ndim`` dimensions, every entry finite and within :data:`MAX_MAGNITUDE`."""
    what = "a list of numbers" if ndim == 1 else "a matrix (list of rows) of numbers"
    if isinstance(value, (str, bytes, bool)):
        raise SceneError(path, value, f"expected {what}")
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise SceneError(path, value, f"expected {what}") from None
    if array.ndim != ndim:
        raise SceneError(path, value, f"expected {what}")
    if array.size and not _within_magnitude(array):
        if not np.all(np.isfinite(array)):
            raise SceneError(path, value, "every entry must be a finite number (no NaN or inf)")
        raise SceneError(path, value, f"every entry must be at most {MAX_MAGNITUDE:g} in magnitude ({_TOO_LARGE})")
    array.setflags(write=False)
    return array


def _within_magnitude(array: FloatArray) -> bool:
    """Every entry finite and within :data:`MAX_MAGNITUDE` (NaN and inf fail); a few entries (a point, a twist,
    built several times a contact and a step) compared as Python floats, costing a third of two numpy calls."""
    if array.size <= _SCALAR_CHECK:
        return all(-MAX_MAGNITUDE <= x <= MAX_MAGNITUDE for x in array.ravel().tolist())
    return float(np.abs(array).max()) <= MAX_MAGNITUDE  # one reduction for both checks


def checked_number(value: Any, path: str, minimum: float | None = None, maximum: float = MAX_MAGNITUDE, why: str = "") -> float:
    """A finite float in ``[minimum, maximum]`` (and within :data:`MAX_MAGNITUDE`); ``why`` explains the maximum."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise SceneError(path, value, "expected a number")
    try:
        number = float(value)
    except OverflowError:
        raise SceneError(path, value, f"must be at most {maximum:g} in magnitude ({why or _TOO_LARGE})") from None
    if not math.isfinite(number):
        raise SceneError(path, value, "must be a finite number (no NaN or inf)")
    if minimum is not None and number < minimum:
        raise SceneError(path, value, f"must be >= {minimum:g}")
    if abs(number) > maximum:
        raise SceneError(path, value, f"must be at most {maximum:g} in magnitude ({why or _TOO_LARGE})")
    return number


def _name(value: Any, path: str) -> str:
    """A name: non-empty printable text of at most :data:`MAX_NAME_LENGTH` characters (it is printed in tables)."""
    if not isinstance(value, str) or not value:
        raise SceneError(path, value, "names must be non-empty strings")
    if len(value) > MAX_NAME_LENGTH:
        raise SceneError(path, value, f"names must be at most {MAX_NAME_LENGTH} characters long (this one has {len(value)})")
    if not value.isprintable():
        raise SceneError(path, value, "names must be printable text: no newlines, tabs, escape or other control characters")
    return value


def _assign(obj: object, **values: Any) -> None:
    """Set the fields of a frozen part while it is being built (its own ``__init__`` only)."""
    for key, value in values.items():
        object.__setattr__(obj, key, value)


def _checked_copy(part: T, **changes: Any) -> T:
    """A copy of an already validated part with some fields replaced by values the caller has checked.

    ``dataclasses.replace`` would run the part's ``__init__`` again and check every field twice.
    """
    copy = object.__new__(type(part))
    copy.__dict__.update(part.__dict__, **changes)
    return cast(T, copy)


@dataclass(frozen=True, init=False)
class Stiffness:
    """A contact's stiffness: the force per unit deflection of its normal and tangential springs.

    Attributes
    ----------
    normal : float
        Normal stiffness k_n [force/length], > 0.
    tangential : float
        Tangential stiffness k_t [force/length], > 0, the same in every tangent direction;
        ``normal`` when not given (a Hertzian contact of like materials has k_t = 2(1 - nu)/(2 - nu)
        k_n, within 20 % of k_n for 0 <= nu <= 0.5).
    """

    normal: float
    tangential: float

    def __init__(self, normal: float, tangential: float | None = None) -> None:
        k_n = _positive(normal, "stiffness.normal")
        _assign(self, normal=k_n, tangential=k_n if tangential is None else _positive(tangential, "stiffness.tangential"))


def _positive(value: Any, path: str, what: str = "a stiffness") -> float:
    number = checked_number(value, path, minimum=0.0)
    if number <= 0.0:
        raise SceneError(path, value, f"{what} must be > 0 (leave the key out for none)")
    return number


@dataclass(frozen=True, init=False)
class Body:
    """A free rigid body: its motion is what is solved for.

    Attributes
    ----------
    name : str
    mass : float
        Mass [kg or any consistent unit], >= 0.
    com : array (d,)
        Centre of mass, world frame [length].
    wrench : array (3,) in 2-D or (6,) in 3-D, or None
        Applied wrench: force, then moment about the com. Zero once in a Scene if omitted.
    """

    name: str
    mass: float
    com: FloatArray
    wrench: FloatArray | None

    def __init__(self, name: str, mass: float, com: npt.ArrayLike, wrench: npt.ArrayLike | None = None) -> None:
        path = f"bodies.{_name(name, 'bodies')}"
        _assign(
            self,
            name=name,
            mass=checked_number(mass, f"{path}.mass", minimum=0.0),
            com=checked_array(com, f"{path}.com"),
            wrench=None if wrench is None else checked_array(wrench, f"{path}.wrench"),
        )


@dataclass(frozen=True, init=False)
class Mover:
    """A body whose motion is prescribed: fixed, a rigid twist, or a robot link.

    Attributes
    ----------
    name : str
    twist : array (3,) in 2-D or (6,) in 3-D, or None
        Linear velocity of the point ``origin``, then angular velocity (world frame); zero once in a Scene if omitted.
    origin : array (d,) or None
        Reference point of ``twist``; the world origin once in a Scene if omitted.
    robot : str, optional
        Name of the robot driving this link; its contacts then carry a ``jacobian``.
    """

    name: str
    twist: FloatArray | None
    origin: FloatArray | None
    robot: str | None

    def __init__(
        self, name: str, twist: npt.ArrayLike | None = None, origin: npt.ArrayLike | None = None, robot: str | None = None
    ) -> None:
        path = f"movers.{_name(name, 'movers')}"
        if robot is not None and not isinstance(robot, str):
            raise SceneError(f"{path}.robot", robot, "expected a robot's name")
        _assign(
            self,
            name=name,
            twist=None if twist is None else checked_array(twist, f"{path}.twist"),
            origin=None if origin is None else checked_array(origin, f"{path}.origin"),
            robot=None if robot is None else _name(robot, f"{path}.robot"),
        )


@dataclass(frozen=True, init=False)
class Robot:
    """A robot given by its joint velocities, one per column of its contacts' Jacobians.

    Attributes
    ----------
    name : str
    joint_velocities : array (n_joints,)
        [rad/time for a revolute joint, length/time for a prismatic one].
    joint_names : tuple of str or None
        One name per joint, for reports (a URDF robot's own); None labels them ``joint[j]``.
    torque_limits : array (n_joints,) or None
        Largest joint torque magnitude each joint can supply [force x length, or force for a
        prismatic joint], >= 0; a motion that needs more is reported as infeasible for this robot.
    joint_stiffness : array (n_joints,) or None
        Stiffness of each joint's servo or transmission [torque/rad for a revolute joint, force/length
        for a prismatic one], > 0: its links then yield, in series with the contact springs, when the
        compliant forces are worked out (:mod:`quasistatic.solvers.compliance`). None: rigid joints.
    """

    name: str
    joint_velocities: FloatArray
    joint_names: tuple[str, ...] | None
    torque_limits: FloatArray | None
    joint_stiffness: FloatArray | None

    def __init__(
        self,
        name: str,
        joint_velocities: npt.ArrayLike,
        *,
        joint_names: Iterable[str] | None = None,
        torque_limits: npt.ArrayLike | None = None,
        joint_stiffness: npt.ArrayLike | None = None,
    ) -> None:
        path = f"robots.{_name(name, 'robots')}"
        velocities = checked_array(joint_velocities, f"{path}.joint_velocities")
        _assign(
            self,
            name=name,
            joint_velocities=velocities,
            joint_names=None if joint_names is None else _joint_names(joint_names, velocities.size, f"{path}.joint_names"),
            torque_limits=None if torque_limits is None else _torque_limits(torque_limits, velocities.size, f"{path}.torque_limits"),
            joint_stiffness=None
            if joint_stiffness is None
            else _joint_stiffness(joint_stiffness, velocities.size, f"{path}.joint_stiffness"),
        )

    def joint_labels(self) -> tuple[str, ...]:
        """The joint names, or ``joint[0]``, ``joint[1]``, ... when none were given."""
        return self.joint_names or tuple(f"joint[{j}]" for j in range(self.joint_velocities.size))


def _joint_names(names: Iterable[str], count: int, path: str) -> tuple[str, ...]:
    if isinstance(names, str):
        raise SceneError(path, names, "expected a list of names, one per joint")
    checked = tuple(_name(n, path) for n in names)
    if len(checked) != count:
        raise SceneError(path, list(checked), f"expected {count} names, one per joint")
    if len(set(checked)) != count:
        raise SceneError(path, list(checked), "joint names must be unique")
    return checked


def _torque_limits(limits: npt.ArrayLike, count: int, path: str) -> FloatArray:
    array = checked_array(limits, path)
    if array.shape != (count,):
        raise SceneError(path, array.tolist(), f"expected {count} numbers, one per joint (as joint_velocities)")
    if np.any(array < 0.0):
        raise SceneError(path, array.tolist(), "every limit is a torque magnitude: >= 0")
    return array


def _joint_stiffness(values: npt.ArrayLike, count: int, path: str) -> FloatArray:
    array = checked_array(values, path)
    if array.shape != (count,):
        raise SceneError(path, array.tolist(), f"expected {count} numbers, one per joint (as joint_velocities)")
    if not np.all(array > 0.0):
        raise SceneError(path, array.tolist(), "every joint stiffness must be > 0 (leave the key out for rigid joints)")
    return array


@dataclass(frozen=True, init=False)
class Contact:
    """A point contact between a free body and another body.

    Attributes
    ----------
    body : str
        The free body; ``normal`` points into it and ``force`` acts on it.
    other : str
        A mover or another free body.
    point : array (d,)
        Contact point, world frame [length].
    normal : array (d,)
        Unit normal into ``body`` (normalised once in a Scene if within 1e-3 of unit length).
    mu : float
        Coulomb friction coefficient [-], >= 0.
    jacobian : array (d, n_joints), optional
        For a robot-driven ``other``: world velocity of its material point at
        ``point`` per unit joint velocity.
    stiffness : Stiffness, optional
        The contact's springs; None (default) is rigid, or the Scene's default stiffness once in a Scene.
    """

    body: str
    other: str
    point: FloatArray
    normal: FloatArray
    mu: float
    jacobian: FloatArray | None
    stiffness: Stiffness | None

    def __init__(
        self,
        body: str,
        other: str,
        point: npt.ArrayLike,
        normal: npt.ArrayLike,
        mu: float = 0.0,
        jacobian: npt.ArrayLike | None = None,
        stiffness: Stiffness | None = None,
    ) -> None:
        if stiffness is not None and not isinstance(stiffness, Stiffness):
            raise SceneError("contact.stiffness", stiffness, "expected a Stiffness(normal, tangential)")
        _assign(
            self,
            body=_name(body, "contact.body"),
            other=_name(other, "contact.other"),
            point=checked_array(point, "contact.point"),
            normal=checked_array(normal, "contact.normal"),
            mu=checked_number(mu, "contact.mu", minimum=0.0, maximum=MAX_FRICTION, why=_MU_TOO_LARGE),
            jacobian=None if jacobian is None else checked_array(jacobian, "contact.jacobian", ndim=2),
            stiffness=stiffness,
        )

    @classmethod
    def from_trusted_arrays(
        cls,
        body: str,
        other: str,
        point: FloatArray,
        normal: FloatArray,
        mu: float,
        jacobian: FloatArray | None = None,
        stiffness: Stiffness | None = None,
    ) -> Contact:
        """A contact from values this package computed from validated ones (contact detection, point Jacobians).

        For inner loops (a simulation finds its contacts at every step): the names, numbers and arrays are
        not checked again here; the :class:`Scene` they go into still checks the whole. The arrays are made
        read-only, not copied: the caller hands them over.
        """
        contact = cls.__new__(cls)
        for array in (point, normal) if jacobian is None else (point, normal, jacobian):
            array.setflags(write=False)
        _assign(contact, body=body, other=other, point=point, normal=normal, mu=float(mu), jacobian=jacobian, stiffness=stiffness)
        return contact


@dataclass(frozen=True, init=False)
class Scene:
    """A validated, frozen scene. Construction checks everything.

    Attributes
    ----------
    bodies, movers, robots, contacts : tuples of the parts above
        Contacts keep their order in every output.
    dimension : {2, 3}
        2 means planar, in the x-y plane.
    gravity : array (d,)
        Gravitational acceleration; [0, 0, -9.81] (3-D) or [0, -9.81] (2-D) when given as None.
    friction : FrictionModel
        ``exact`` (default), ``pyramid:K`` or ``none`` (a string is parsed).
    stiffness : Stiffness or None
        The default stiffness of every contact that gives none of its own (filled into those
        contacts once in a Scene); None leaves them rigid.
    closing_time : float or None
        How long the commanded motion acts against the contact springs [time], > 0: each mover
        advances its velocity times this, and the compliant step (:mod:`quasistatic.solvers.compliance`)
        finds the squeeze forces and the bodies' small displacement when the rigid answer is
        ``jammed`` or ``ambiguous``. None: no step.
    """

    bodies: tuple[Body, ...]
    contacts: tuple[Contact, ...]
    movers: tuple[Mover, ...]
    robots: tuple[Robot, ...]
    dimension: int
    gravity: FloatArray
    friction: FrictionModel
    stiffness: Stiffness | None
    closing_time: float | None
    _derived: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __init__(
        self,
        bodies: Iterable[Body],
        contacts: Iterable[Contact],
        movers: Iterable[Mover] = (),
        robots: Iterable[Robot] = (),
        dimension: int = 3,
        gravity: npt.ArrayLike | None = None,
        friction: FrictionModel | str = "exact",
        stiffness: Stiffness | None = None,
        closing_time: float | None = None,
    ) -> None:
        if stiffness is not None and not isinstance(stiffness, Stiffness):
            raise SceneError("stiffness", stiffness, "expected a Stiffness(normal, tangential)")
        if closing_time is not None:
            closing_time = _positive(closing_time, "closing_time", "a time over which the movers advance")
        if isinstance(dimension, bool) or not isinstance(dimension, (int, np.integer)) or dimension not in (2, 3):
            raise SceneError("dimension", dimension, "must be 2 or 3")
        dimension = int(dimension)
        model = _friction(friction, dimension)
        default_gravity = [0.0, -9.81] if dimension == 2 else [0.0, 0.0, -9.81]
        gravity_vector = _sized(checked_array(default_gravity if gravity is None else gravity, "gravity"), dimension, "gravity")
        parts = _Parts(dimension, tuple(bodies), tuple(movers), tuple(robots), stiffness)
        _assign(
            self,
            bodies=parts.bodies,
            movers=parts.movers,
            robots=parts.robots,
            contacts=tuple(parts.contact(c, f"contacts[{i}]") for i, c in enumerate(contacts)),
            dimension=dimension,
            gravity=gravity_vector,
            friction=model,
            stiffness=stiffness,
            closing_time=closing_time,
            _derived={},
        )

    def __getstate__(self) -> dict[str, Any]:
        # What later stages derived from this scene is rebuilt where it is needed, not pickled.
        return {key: value for key, value in self.__dict__.items() if key != "_derived"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state, _derived={})

    def derived(self, key: str, build: Callable[[Scene], T]) -> T:
        """``build(self)``, computed once and kept with this scene (scenes are frozen).

        For what every solve of the scene reads the same way (the audit's arrays):
        solving one scene again, as simulations and interactive use do, skips that work.
        """
        values = self._derived
        if key not in values:
            values[key] = build(self)
        return cast(T, values[key])

    def replaced(
        self,
        *,
        bodies: Mapping[str, Body] | None = None,
        movers: Mapping[str, Mover] | None = None,
        contacts: Mapping[int, Contact] | None = None,
        gravity: npt.ArrayLike | None = None,
    ) -> Scene:
        """This scene with some parts replaced by new ones of the same names (contacts by index), gravity too.

        Only the new parts are checked, against this scene as the constructor checks them (the same errors);
        the rest was checked when this scene was made. For a sweep that changes a few numbers at every point.

        Raises
        ------
        SceneError
            As :class:`Scene` would, for a new part or gravity; or naming a part this scene does not have.
        """
        parts = _Parts.of(self)
        changes: dict[str, Any] = {"_derived": {}}
        if bodies:
            changes["bodies"] = _swapped(self.bodies, bodies, Body, "bodies", parts.body)
        if movers:
            changes["movers"] = _swapped(self.movers, movers, Mover, "movers", parts.mover)
        if contacts:
            unknown = sorted(set(contacts) - set(range(len(self.contacts))))
            if unknown:
                raise SceneError("contacts", unknown, f"the scene has {len(self.contacts)} contacts")
            changes["contacts"] = tuple(
                parts.contact(contacts[i], f"contacts[{i}]") if i in contacts else c for i, c in enumerate(self.contacts)
            )
        if gravity is not None:
            changes["gravity"] = _sized(checked_array(gravity, "gravity"), self.dimension, "gravity")
        return _checked_copy(self, **changes)

    def moved(
        self,
        coms: Sequence[npt.ArrayLike],
        mover_places: Sequence[tuple[npt.ArrayLike | None, npt.ArrayLike | None]],
        contacts: Sequence[Contact],
    ) -> Scene | None:
        """This scene at another instant: new centres of mass (one per body), mover ``(twist, origin)`` pairs (one
        per mover) and contacts, or None when the contacts' pairs differ from this scene's (then make a Scene).

        Each new number is checked as the constructor checks it (the same errors); what an instant does not change
        (names, masses, wrenches, gravity, friction, which pairs touch) was checked when this scene was made. For a
        simulation step, whose bodies move but whose structure mostly stays; scenes with robots are not restated.
        """
        if self.robots or [(c.body, c.other) for c in contacts] != [(c.body, c.other) for c in self.contacts]:
            return None
        parts, d = _Parts.of(self), self.dimension
        bodies = tuple(
            _checked_copy(body, com=_sized(checked_array(com, f"bodies.{body.name}.com"), d, f"bodies.{body.name}.com"))
            for body, com in zip(self.bodies, coms, strict=True)
        )
        movers = tuple(parts.mover_numbers(mover, twist, origin) for mover, (twist, origin) in zip(self.movers, mover_places, strict=True))
        checked = tuple(parts.contact_numbers(_contact_of(contact), f"contacts[{i}]") for i, contact in enumerate(contacts))
        return _checked_copy(self, bodies=bodies, movers=movers, contacts=checked, _derived={})

    def body_index(self, name: str) -> int:
        """Index of a free body by name."""
        return [b.name for b in self.bodies].index(name)

    def mover(self, name: str) -> Mover:
        """A mover by name."""
        return next(m for m in self.movers if m.name == name)

    def robot(self, name: str) -> Robot:
        """A robot by name."""
        return next(r for r in self.robots if r.name == name)

    def load(self, body: Body) -> FloatArray:
        """Gravity plus applied wrench on ``body``, about its com [force, force x length]."""
        wrench = np.zeros(self.twist_size) if body.wrench is None else np.array(body.wrench, dtype=float)
        wrench[: self.dimension] += body.mass * self.gravity
        return wrench

    @property
    def compliant(self) -> bool:
        """Whether some contact or robot joint has a stiffness: compliance then picks the forces of a motion."""
        return any(c.stiffness is not None for c in self.contacts) or any(r.joint_stiffness is not None for r in self.robots)

    @property
    def twist_size(self) -> int:
        """Entries in one body twist: 3 in 2-D, 6 in 3-D."""
        return 3 if self.dimension == 2 else 6


def _friction(friction: FrictionModel | str, dimension: int) -> FrictionModel:
    """The friction model, parsed from text if need be; a pyramid has at most :data:`MAX_PYRAMID_EDGES` edges, in 3-D only."""
    model = _parse_friction(friction) if isinstance(friction, str) else friction
    if not isinstance(model, FrictionModel):
        raise SceneError("friction", friction, "expected 'exact', 'none' or 'pyramid:K'")
    if model.kind == "pyramid" and dimension == 2:
        raise SceneError("friction", str(model), "pyramid:K is for 3-D; the 2-D cone is already exact")
    if model.kind == "pyramid" and not 3 <= model.edges <= MAX_PYRAMID_EDGES:
        reason = f"a pyramid has 3 to {MAX_PYRAMID_EDGES} edges; for a finer cone use 'exact'"
        raise SceneError("friction", str(model), reason)
    return model


def _parse_friction(text: str) -> FrictionModel:
    """:func:`parse_friction`, for any text: too long to be a model (ten thousand digits) or with digits
    ``int()`` refuses (``pyramid:²``), it is a SceneError too."""
    if len(text) > _FRICTION_TEXT_LENGTH:
        raise SceneError("friction", text, "expected 'exact', 'none' or 'pyramid:K'")
    try:
        return parse_friction(text)
    except SceneError:
        raise
    except ValueError:
        raise SceneError("friction", text, "pyramid needs an integer number of edges K >= 3, e.g. 'pyramid:8'") from None


def _sized(vector: FloatArray, length: int, path: str) -> FloatArray:
    if vector.shape != (length,):
        raise SceneError(path, vector.tolist(), f"expected a list of {length} numbers")
    return vector


def _contact_of(contact: Any) -> Contact:
    if not isinstance(contact, Contact):
        raise SceneError("contacts", type(contact).__name__, "expected a Contact")
    return contact


def _swapped(kept: tuple[T, ...], new: Mapping[str, Any], kind: type, path: str, check: Callable[[Any], T]) -> tuple[T, ...]:
    """``kept`` with the parts named in ``new`` replaced, each checked; a new part keeps its name."""
    names = [cast(Any, part).name for part in kept]
    for name, part in new.items():
        if name not in names:
            raise SceneError(f"{path}.{name}", name, _unknown(kind.__name__.lower(), name, names))
        if not isinstance(part, kind) or getattr(part, "name", None) != name:
            raise SceneError(f"{path}.{name}", type(part).__name__, f"expected a {kind.__name__} named {name!r}")
    return tuple(check(new[name]) if name in new else part for name, part in zip(names, kept, strict=True))


class _Parts:
    """The scene's bodies, movers and robots checked together, with their defaults filled in (new objects)."""

    @classmethod
    def of(cls, scene: Scene) -> _Parts:
        """The context of an already checked scene, to check new parts against it (nothing is checked again)."""
        parts = cls.__new__(cls)
        parts.dimension, parts.stiffness, parts.twist_size = scene.dimension, scene.stiffness, scene.twist_size
        parts.robots, parts.bodies, parts.movers = scene.robots, scene.bodies, scene.movers
        parts.robot_joints = {r.name: r.joint_velocities.size for r in scene.robots}
        parts.body_names = {b.name for b in scene.bodies}
        parts.mover_robot = {m.name: m.robot for m in scene.movers}
        return parts

    def __init__(
        self, dimension: int, bodies: tuple[Body, ...], movers: tuple[Mover, ...], robots: tuple[Robot, ...], stiffness: Stiffness | None
    ) -> None:
        self.dimension = dimension
        self.stiffness = stiffness
        self.twist_size = 3 if dimension == 2 else 6
        if not bodies:
            raise SceneError("bodies", [], "at least one free body is required")
        _check_types(bodies, Body, "bodies")
        _check_types(movers, Mover, "movers")
        _check_types(robots, Robot, "robots")
        _check_unique_names(bodies, movers, robots)
        self.robots = robots
        self.robot_joints = {r.name: r.joint_velocities.size for r in robots}
        self.bodies = tuple(self.body(b) for b in bodies)
        self.movers = tuple(self.mover(m) for m in movers)
        self.body_names = {b.name for b in bodies}
        self.mover_robot = {m.name: m.robot for m in movers}

    def body(self, body: Body) -> Body:
        path = f"bodies.{body.name}"
        wrench = np.zeros(self.twist_size) if body.wrench is None else body.wrench
        return _checked_copy(
            body,
            com=_sized(body.com, self.dimension, f"{path}.com"),
            wrench=_sized(checked_array(wrench, path), self.twist_size, f"{path}.wrench"),
        )

    def mover(self, mover: Mover) -> Mover:
        path = f"movers.{mover.name}"
        if mover.robot is not None:
            if mover.twist is not None:
                raise SceneError(
                    f"{path}.twist", mover.twist.tolist(), "a robot-driven mover takes its motion from the robot; give no twist"
                )
            if mover.robot not in self.robot_joints:
                raise SceneError(f"{path}.robot", mover.robot, _unknown("robot", mover.robot, self.robot_joints))
        twist = np.zeros(self.twist_size) if mover.twist is None else mover.twist
        origin = np.zeros(self.dimension) if mover.origin is None else mover.origin
        return _checked_copy(
            mover,
            twist=_sized(checked_array(twist, path), self.twist_size, f"{path}.twist"),
            origin=_sized(checked_array(origin, path), self.dimension, f"{path}.origin"),
        )

    def mover_numbers(self, mover: Mover, twist: npt.ArrayLike | None, origin: npt.ArrayLike | None) -> Mover:
        """A checked rigid mover with a new twist and origin, each checked once as ``Mover`` and :meth:`mover` would."""
        path = f"movers.{mover.name}"
        twist = checked_array(np.zeros(self.twist_size) if twist is None else twist, f"{path}.twist")
        origin = checked_array(np.zeros(self.dimension) if origin is None else origin, f"{path}.origin")
        return _checked_copy(
            mover, twist=_sized(twist, self.twist_size, f"{path}.twist"), origin=_sized(origin, self.dimension, f"{path}.origin")
        )

    def contact(self, contact: Contact, path: str) -> Contact:
        if not isinstance(contact, Contact):
            raise SceneError(path, type(contact).__name__, "expected a Contact")
        self._check_pair(contact, path)
        return self.contact_numbers(contact, path)

    def contact_numbers(self, contact: Contact, path: str) -> Contact:
        """A contact whose pair is known to be valid here: its point, unit normal, jacobian and stiffness checked."""
        point = _sized(contact.point, self.dimension, f"{path}.point")
        normal = _sized(contact.normal, self.dimension, f"{path}.normal")
        length = math.sqrt(float(normal @ normal))  # np.linalg.norm's own arithmetic for a vector, without its checks
        if abs(length - 1.0) > NORMAL_LENGTH:
            raise SceneError(f"{path}.normal", normal.tolist(), f"must be a unit vector (its length is {length:.6g})")
        unit = normal / length
        unit.setflags(write=False)
        stiffness = self.stiffness if contact.stiffness is None else contact.stiffness
        return _checked_copy(contact, point=point, normal=unit, jacobian=self._jacobian(contact, path), stiffness=stiffness)

    def _check_pair(self, contact: Contact, path: str) -> None:
        if contact.body not in self.body_names:
            reason = (
                f"must be a free body; {contact.body!r} is a mover (contacts between two movers do not constrain anything)"
                if contact.body in self.mover_robot
                else _unknown("free body", contact.body, self.body_names)
            )
            raise SceneError(f"{path}.body", contact.body, reason)
        if contact.other not in self.body_names and contact.other not in self.mover_robot:
            raise SceneError(
                f"{path}.other", contact.other, _unknown("body or mover", contact.other, self.body_names | set(self.mover_robot))
            )
        if contact.other == contact.body:
            raise SceneError(f"{path}.other", contact.other, "a body cannot touch itself")

    def _jacobian(self, contact: Contact, path: str) -> FloatArray | None:
        robot = self.mover_robot.get(contact.other)
        if robot is None:
            if contact.jacobian is not None:
                reason = f"only contacts with a robot-driven mover take a jacobian; {contact.other!r} is not one"
                raise SceneError(f"{path}.jacobian", contact.jacobian.tolist(), reason)
            return None
        dim, joints = self.dimension, self.robot_joints[robot]
        if contact.jacobian is None:
            reason = f"required: {contact.other!r} is driven by robot {robot!r} ({dim} x {joints} expected)"
            raise SceneError(f"{path}.jacobian", None, reason)
        if contact.jacobian.shape != (dim, joints):
            reason = f"expected shape ({dim}, {joints}): {dim} rows, one column per joint of robot {robot!r}"
            raise SceneError(f"{path}.jacobian", f"shape {contact.jacobian.shape}", reason)
        return contact.jacobian


def _check_types(items: tuple[Any, ...], kind: type, path: str) -> None:
    for index, item in enumerate(items):
        if not isinstance(item, kind):
            raise SceneError(f"{path}[{index}]", type(item).__name__, f"expected a {kind.__name__}")


def _check_unique_names(bodies: tuple[Body, ...], movers: tuple[Mover, ...], robots: tuple[Robot, ...]) -> None:
    names: dict[str, str] = {}
    for kind, items in (("bodies", bodies), ("movers", movers)):
        for item in items:
            if item.name in names:
                raise SceneError(f"{kind}.{item.name}", item.name, f"name already used in {names[item.name]}")
            names[item.name] = kind
    robot_names = [r.name for r in robots]
    if len(set(robot_names)) != len(robot_names):
        raise SceneError("robots", robot_names, "robot names must be unique")


def _unknown(kind: str, name: Any, known: Collection[str] | Mapping[str, Any]) -> str:
    """The reason for a name that names nothing: the closest known name, or the first few known ones."""
    names = sorted(known)
    close = difflib.get_close_matches(str(name), names, n=1)
    shown = ", ".join(map(repr, names[:_SHOWN_NAMES])) + (f", ... ({len(names)} in all)" if len(names) > _SHOWN_NAMES else "")
    hint = f"; did you mean {close[0]!r}?" if close else f"; known: {shown or 'none'}"
    return f"no {kind} of that name{hint}"
