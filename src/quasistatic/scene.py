"""Scenes: free bodies, movers, robots and contacts, validated once and frozen.

A scene is built from Python objects (:class:`Scene`, :class:`Body`, ...) or
loaded from a YAML/JSON file or dict with :func:`load_scene`. Every check
happens here, so later stages can trust their input.
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pydantic
import yaml

from .errors import MISSING, SceneError
from .friction import FrictionModel, parse_friction

__all__ = ["Body", "Mover", "Robot", "Contact", "Scene", "load_scene", "FORMAT_VERSION"]

FORMAT_VERSION = 1
NORMAL_TOLERANCE = 1e-3  # |‖n‖ − 1| allowed before a normal is rejected


def _vector(value: Any, length: int, path: str) -> np.ndarray:
    """A finite float vector of the given length, read-only."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(path, value, f"expected a list of {length} numbers") from None
    if array.shape != (length,):
        raise SceneError(path, value, f"expected a list of {length} numbers")
    if not np.all(np.isfinite(array)):
        raise SceneError(path, value, "every entry must be a finite number (no NaN or inf)")
    array.setflags(write=False)
    return array


def _number(value: Any, path: str, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise SceneError(path, value, "expected a number")
    number = float(value)
    if not math.isfinite(number):
        raise SceneError(path, value, "must be a finite number (no NaN or inf)")
    if minimum is not None and number < minimum:
        raise SceneError(path, value, f"must be >= {minimum:g}")
    return number


@dataclass(frozen=True)
class Body:
    """A free rigid body: its motion is what is solved for.

    Attributes
    ----------
    name : str
    mass : float
        Mass [kg or any consistent unit], >= 0.
    com : array (d,)
        Centre of mass, world frame [length].
    wrench : array (3,) in 2-D or (6,) in 3-D
        Applied wrench: force, then moment about the com. Zero if omitted.
    """

    name: str
    mass: float
    com: Sequence[float]
    wrench: Sequence[float] | None = None


@dataclass(frozen=True)
class Mover:
    """A body whose motion is prescribed: fixed, a rigid twist, or a robot link.

    Attributes
    ----------
    name : str
    twist : array (3,) in 2-D or (6,) in 3-D, optional
        Linear velocity of the point ``origin``, then angular velocity (world frame).
    origin : array (d,), optional
        Reference point of ``twist``; the world origin by default.
    robot : str, optional
        Name of the robot driving this link; its contacts then carry a ``jacobian``.
    """

    name: str
    twist: Sequence[float] | None = None
    origin: Sequence[float] | None = None
    robot: str | None = None


@dataclass(frozen=True)
class Robot:
    """A robot given by its joint velocities [rad/s or length/s per joint]."""

    name: str
    joint_velocities: Sequence[float]


@dataclass(frozen=True)
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
        Unit normal into ``body`` (normalised if within 1e-3 of unit length).
    mu : float
        Coulomb friction coefficient [-], >= 0.
    jacobian : array (d, n_joints), optional
        For a robot-driven ``other``: world velocity of its material point at
        ``point`` per unit joint velocity.
    """

    body: str
    other: str
    point: Sequence[float]
    normal: Sequence[float]
    mu: float = 0.0
    jacobian: Sequence[Sequence[float]] | None = None


@dataclass(frozen=True)
class Scene:
    """A validated, frozen scene. Construction checks everything.

    Attributes
    ----------
    bodies, movers, robots, contacts : tuples of the objects above
        Contacts keep their order in every output.
    dimension : {2, 3}
        2 means planar, in the x-y plane.
    gravity : array (d,), optional
        Gravitational acceleration; [0, 0, -9.81] (3-D) or [0, -9.81] (2-D) by default.
    friction : FrictionModel or str
        ``exact`` (default), ``pyramid:K`` or ``none``.
    """

    bodies: tuple[Body, ...]
    contacts: tuple[Contact, ...]
    movers: tuple[Mover, ...] = ()
    robots: tuple[Robot, ...] = ()
    dimension: int = 3
    gravity: Sequence[float] | None = None
    friction: FrictionModel | str = field(default_factory=FrictionModel)

    def __post_init__(self) -> None:
        _validate_and_normalise(self)

    # Lookups used by assembly and reports.
    def body_index(self, name: str) -> int:
        """Index of a free body by name."""
        return [b.name for b in self.bodies].index(name)

    def mover(self, name: str) -> Mover:
        """A mover by name."""
        return {m.name: m for m in self.movers}[name]

    def robot(self, name: str) -> Robot:
        """A robot by name."""
        return {r.name: r for r in self.robots}[name]

    @property
    def twist_size(self) -> int:
        """Entries in one body twist: 3 in 2-D, 6 in 3-D."""
        return 3 if self.dimension == 2 else 6


def _set(obj: object, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


def _validate_and_normalise(scene: Scene) -> None:
    dim = scene.dimension
    if isinstance(dim, bool) or dim not in (2, 3):
        raise SceneError("dimension", dim, "must be 2 or 3")
    twist_size = 3 if dim == 2 else 6
    default_gravity = [0.0, -9.81] if dim == 2 else [0.0, 0.0, -9.81]
    _set(scene, "gravity", _vector(default_gravity if scene.gravity is None else scene.gravity, dim, "gravity"))
    if isinstance(scene.friction, str):
        _set(scene, "friction", parse_friction(scene.friction))
    if not isinstance(scene.friction, FrictionModel):
        raise SceneError("friction", scene.friction, "expected 'exact', 'none' or 'pyramid:K'")
    if scene.friction.kind == "pyramid" and dim == 2:
        raise SceneError("friction", str(scene.friction), "pyramid:K is for 3-D; the 2-D cone is already exact")

    for attr in ("bodies", "movers", "robots", "contacts"):
        _set(scene, attr, tuple(getattr(scene, attr)))
    if not scene.bodies:
        raise SceneError("bodies", [], "at least one free body is required")
    names: dict[str, str] = {}
    for kind, items in (("bodies", scene.bodies), ("movers", scene.movers), ("robots", scene.robots)):
        for item in items:
            _check_name(item.name, f"{kind}.{item.name}")
            if kind != "robots" and item.name in names:
                raise SceneError(f"{kind}.{item.name}", item.name, f"name already used in {names[item.name]}")
            if kind != "robots":
                names[item.name] = kind
    for body in scene.bodies:
        _validate_body(body, dim, twist_size)
    robots = {r.name: r for r in scene.robots}
    if len(robots) != len(scene.robots):
        raise SceneError("robots", [r.name for r in scene.robots], "robot names must be unique")
    for robot in scene.robots:
        velocities = np.array(robot.joint_velocities, dtype=float) if _is_numeric_list(robot.joint_velocities) else None
        if velocities is None or velocities.ndim != 1:
            raise SceneError(f"robots.{robot.name}.joint_velocities", robot.joint_velocities, "expected a list of numbers")
        _set(robot, "joint_velocities", _vector(velocities, velocities.size, f"robots.{robot.name}.joint_velocities"))
    for mover in scene.movers:
        _validate_mover(mover, dim, twist_size, robots)
    bodies = {b.name for b in scene.bodies}
    movers = {m.name: m for m in scene.movers}
    for index, contact in enumerate(scene.contacts):
        _validate_contact(contact, f"contacts[{index}]", dim, bodies, movers, robots)


def _check_name(name: Any, path: str) -> None:
    if not isinstance(name, str) or not name:
        raise SceneError(path, name, "names must be non-empty strings")


def _is_numeric_list(value: Any) -> bool:
    try:
        np.array(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


def _validate_body(body: Body, dim: int, twist_size: int) -> None:
    path = f"bodies.{body.name}"
    _set(body, "mass", _number(body.mass, f"{path}.mass", minimum=0.0))
    _set(body, "com", _vector(body.com, dim, f"{path}.com"))
    wrench = np.zeros(twist_size) if body.wrench is None else body.wrench
    _set(body, "wrench", _vector(wrench, twist_size, f"{path}.wrench"))


def _validate_mover(mover: Mover, dim: int, twist_size: int, robots: Mapping[str, Robot]) -> None:
    path = f"movers.{mover.name}"
    if mover.robot is not None:
        if mover.twist is not None:
            raise SceneError(f"{path}.twist", mover.twist, "a robot-driven mover takes its motion from the robot; give no twist")
        if mover.robot not in robots:
            raise SceneError(f"{path}.robot", mover.robot, _unknown("robot", mover.robot, robots))
    twist = np.zeros(twist_size) if mover.twist is None else mover.twist
    _set(mover, "twist", _vector(twist, twist_size, f"{path}.twist"))
    _set(mover, "origin", _vector(np.zeros(dim) if mover.origin is None else mover.origin, dim, f"{path}.origin"))


def _validate_contact(
    contact: Contact,
    path: str,
    dim: int,
    bodies: set[str],
    movers: Mapping[str, Mover],
    robots: Mapping[str, Robot],
) -> None:
    if contact.body not in bodies:
        reason = (
            f"must be a free body; {contact.body!r} is a mover (contacts between two movers do not constrain anything)"
            if contact.body in movers
            else _unknown("free body", contact.body, bodies)
        )
        raise SceneError(f"{path}.body", contact.body, reason)
    if contact.other not in bodies and contact.other not in movers:
        raise SceneError(f"{path}.other", contact.other, _unknown("body or mover", contact.other, bodies | set(movers)))
    if contact.other == contact.body:
        raise SceneError(f"{path}.other", contact.other, "a body cannot touch itself")
    _set(contact, "point", _vector(contact.point, dim, f"{path}.point"))
    normal = _vector(contact.normal, dim, f"{path}.normal")
    length = float(np.linalg.norm(normal))
    if abs(length - 1.0) > NORMAL_TOLERANCE:
        raise SceneError(f"{path}.normal", list(contact.normal), f"must be a unit vector (its length is {length:.6g})")
    unit = normal / length
    unit.setflags(write=False)
    _set(contact, "normal", unit)
    _set(contact, "mu", _number(contact.mu, f"{path}.mu", minimum=0.0))
    robot_name = movers[contact.other].robot if contact.other in movers else None
    if robot_name is None:
        if contact.jacobian is not None:
            reason = f"only contacts with a robot-driven mover take a jacobian; {contact.other!r} is not one"
            raise SceneError(f"{path}.jacobian", contact.jacobian, reason)
        return
    joints = robots[robot_name].joint_velocities
    n_joints = len(joints)
    if contact.jacobian is None:
        reason = f"required: {contact.other!r} is driven by robot {robot_name!r} ({dim} x {n_joints} expected)"
        raise SceneError(f"{path}.jacobian", None, reason)
    try:
        jac = np.array(contact.jacobian, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"{path}.jacobian", contact.jacobian, f"expected a {dim} x {n_joints} matrix of numbers") from None
    if jac.shape != (dim, n_joints):
        reason = f"expected shape ({dim}, {n_joints}): {dim} rows, one column per joint of robot {robot_name!r}"
        raise SceneError(f"{path}.jacobian", f"shape {jac.shape}", reason)
    if not np.all(np.isfinite(jac)):
        raise SceneError(f"{path}.jacobian", contact.jacobian, "every entry must be a finite number")
    jac.setflags(write=False)
    _set(contact, "jacobian", jac)


def _unknown(kind: str, name: Any, known: Any) -> str:
    known = sorted(known)
    close = difflib.get_close_matches(str(name), known, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else f"; known: {', '.join(map(repr, known)) or 'none'}"
    return f"no {kind} of that name{hint}"


# --------------------------------------------------------------------------- files

def _not_bool_or_text(value: Any) -> Any:
    """YAML's ``true`` or ``"0.1"`` is not a number here, whatever pydantic's lax mode says."""
    if isinstance(value, (bool, str)):
        raise ValueError("expected a number")
    return value


_Number = Annotated[float, pydantic.BeforeValidator(_not_bool_or_text)]


class _FileModel(pydantic.BaseModel):
    model_config = pydantic.ConfigDict(extra="forbid", allow_inf_nan=True, strict=False)


class _BodyFile(_FileModel):
    mass: _Number
    com: list[_Number]
    wrench: list[_Number] | None = None


class _MoverFile(_FileModel):
    twist: list[_Number] | None = None
    origin: list[_Number] | None = None
    robot: str | None = None


class _RobotFile(_FileModel):
    joint_velocities: list[_Number]


class _ContactFile(_FileModel):
    body: str
    other: str
    point: list[_Number]
    normal: list[_Number]
    mu: _Number = 0.0
    jacobian: list[list[_Number]] | None = None


class _SceneFile(_FileModel):
    quasistatic: int
    dimension: Literal[2, 3] = 3
    gravity: list[_Number] | None = None
    friction: str = "exact"
    bodies: dict[str, _BodyFile]
    movers: dict[str, _MoverFile | None] = {}
    robots: dict[str, _RobotFile] = {}
    contacts: list[_ContactFile]


def load_scene(source: str | Path | Mapping[str, Any]) -> Scene:
    """Load and validate a scene from a YAML/JSON file path or a dict of the file's keys.

    Raises
    ------
    SceneError
        Naming the field path and the offending value.
    """
    data = _read(source) if isinstance(source, (str, Path)) else source
    if not isinstance(data, Mapping):
        raise SceneError("", type(data).__name__, "a scene must be a mapping of keys (quasistatic, bodies, contacts, ...)")
    version = data.get("quasistatic")
    if "quasistatic" in data and version != FORMAT_VERSION:
        raise SceneError("quasistatic", version, f"unsupported format version; this library reads version {FORMAT_VERSION}")
    try:
        parsed = _SceneFile.model_validate(dict(data))
    except pydantic.ValidationError as exc:
        raise _scene_error(exc) from None
    return Scene(
        dimension=parsed.dimension,
        gravity=parsed.gravity,
        friction=parsed.friction,
        bodies=tuple(Body(name, b.mass, b.com, b.wrench) for name, b in parsed.bodies.items()),
        movers=tuple(
            Mover(name, m.twist, m.origin, m.robot) if m is not None else Mover(name)
            for name, m in parsed.movers.items()
        ),
        robots=tuple(Robot(name, r.joint_velocities) for name, r in parsed.robots.items()),
        contacts=tuple(Contact(c.body, c.other, c.point, c.normal, c.mu, c.jacobian) for c in parsed.contacts),
    )


def _read(path: str | Path) -> Any:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError("", str(path), f"cannot read the scene file: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise SceneError("", str(path), "the scene file is not UTF-8 text") from None
    try:
        if path.suffix.lower() == ".json":
            return json.loads(text)
        return yaml.safe_load(text)
    except json.JSONDecodeError as exc:
        raise SceneError("", str(path), f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise SceneError("", str(path), f"not valid YAML{where}: {getattr(exc, 'problem', None) or exc}") from None


_MODELS_BY_DEPTH: dict[str, type[pydantic.BaseModel]] = {
    "": _SceneFile,
    "bodies": _BodyFile,
    "movers": _MoverFile,
    "robots": _RobotFile,
    "contacts": _ContactFile,
}


def _scene_error(exc: pydantic.ValidationError) -> SceneError:
    errors = exc.errors()
    # A misspelt key shows as both "missing" and "extra": report the extra one, with a hint.
    error = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = [part for part in error["loc"] if part not in ("_MoverFile",)]
    path = _format_path(loc)
    kind = error["type"]
    if kind == "extra_forbidden":
        key = str(loc[-1])
        model = _MODELS_BY_DEPTH.get(str(loc[0]) if len(loc) > 1 else "", _SceneFile)
        close = difflib.get_close_matches(key, list(model.model_fields), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(model.model_fields)}"
        return SceneError(path, key, f"unknown key{hint}")
    if kind == "missing":
        return SceneError(path, MISSING, "required key is missing")
    return SceneError(path, error.get("input"), error["msg"].lower())


def _format_path(loc: Sequence[Any]) -> str:
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text
