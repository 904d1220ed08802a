"""A scene file with shapes, poses and URDF robots, read into a :class:`World`.

The file's keys are checked by the schema in :mod:`quasistatic.model.io`
(``SceneFile``); this module builds the parts, resolving file paths (URDFs,
meshes, package folders) relative to the scene file's folder. An error in a
part names its field in the file (``bodies.cube.shape.box``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..errors import MISSING, SceneError
from ..model import Contact, Robot
from ..model.io import (
    BodyFile,
    ContactFile,
    DetectionFile,
    HalfspaceFile,
    MoverFile,
    PoseFile,
    RobotFile,
    SceneFile,
    ShapeFile,
    StiffnessFile,
    StiffnessPairFile,
    plain_robot,
    stiffness_of,
)
from ..tolerances import MAX_FRICTION
from .planar import Disk, HalfPlane, PlanarShape, Polygon, Rectangle, planar_pose
from .planar_world import PlanarBody, PlanarMover, PlanarWorld
from .robot import UrdfRobot
from .shapes import Box, Capsule, Cylinder, Halfspace, Mesh, Pose, Shape, Sphere
from .world import ContactDetection, FrictionPair, ShapedMover, SolidBody, StiffnessPair, World

__all__ = ["world_from_file"]

_SHAPE_KINDS = ("box", "sphere", "cylinder", "capsule", "halfspace", "mesh")
_PLANAR_KINDS = ("disk", "box", "polygon", "halfplane")


def world_from_file(parsed: SceneFile, folder: Path) -> World | PlanarWorld:
    """The World a checked scene file describes (a PlanarWorld for ``dimension: 2``); relative paths start from ``folder``."""
    if parsed.dimension == 2:
        return _planar_world(parsed)
    urdf_robots = {name: r for name, r in parsed.robots.items() if r.urdf is not None}
    plain_robots = {name: r for name, r in parsed.robots.items() if r.urdf is None}
    return World(
        bodies=tuple(_body(name, b, folder) for name, b in parsed.bodies.items()),
        movers=tuple(_mover(name, m, folder) for name, m in parsed.movers.items()),
        robots=tuple(_robot(name, r, folder) for name, r in urdf_robots.items()),
        explicit_robots=tuple(_plain_robot(name, r) for name, r in plain_robots.items()),
        contacts=tuple(_contact(c, index) for index, c in enumerate(parsed.contacts)),
        detection=_detection(parsed.contact_detection),
        gravity=parsed.gravity,
        friction=parsed.friction,
        stiffness=stiffness_of(parsed.stiffness, "stiffness"),
        closing_time=parsed.closing_time,
    )


@contextlib.contextmanager
def _within(field: str) -> Iterator[None]:
    """Errors of a part built here name its place in the file."""
    try:
        yield
    except SceneError as exc:
        if exc.field.startswith(field):
            raise
        inner = f".{exc.field}" if exc.field and not exc.field.startswith("[") else exc.field
        raise SceneError(f"{field}{inner}", exc.value, exc.reason) from None


def _body(name: str, entry: BodyFile, folder: Path) -> SolidBody:
    field = f"bodies.{name}"
    with _within(field):
        shape = None if entry.shape is None else _shape(entry.shape, folder, f"{field}.shape")
        pose = _pose(entry.pose, f"{field}.pose")
        com = entry.com if entry.com is not None else [0.0, 0.0, 0.0]
        return SolidBody(name, entry.mass, shape, pose, _vector(com, f"{field}.com"), entry.wrench)


def _mover(name: str, entry: MoverFile | None, folder: Path) -> ShapedMover:
    field = f"movers.{name}"
    if entry is None:
        return ShapedMover(name)
    reason = "in a scene with shapes, a mover's twist is about its pose's position, and robot links come from the urdf"
    _refuse_robot_and_origin(entry, field, reason)
    with _within(field):
        shape = None if entry.shape is None else _shape(entry.shape, folder, f"{field}.shape")
        return ShapedMover(name, shape, _pose(entry.pose, f"{field}.pose"), entry.twist)


def _robot(name: str, entry: RobotFile, folder: Path) -> UrdfRobot:
    field = f"robots.{name}"
    assert entry.urdf is not None
    if entry.joint_names is not None:
        raise SceneError(f"{field}.joint_names", entry.joint_names, "a robot with a urdf has its own joint names")
    with _within(field):
        return UrdfRobot(
            name,
            entry.urdf if entry.urdf.startswith("package://") else _path(entry.urdf, folder),
            package_dirs=[_path(d, folder) for d in entry.package_dirs],
            base=_pose(entry.base, f"{field}.base"),
            q=entry.q,
            joint_velocities=entry.joint_velocities,
            torque_limits=entry.torque_limits,
            joint_stiffness=entry.joint_stiffness,
            field=field,
        )


def _plain_robot(name: str, entry: RobotFile) -> Robot:
    """A robot with no model: its contacts are listed with their Jacobians."""
    field = f"robots.{name}"
    for key in ("package_dirs", "base", "q"):
        if key in entry.model_fields_set:
            raise SceneError(f"{field}.{key}", getattr(entry, key), "only a robot with a urdf takes this key")
    if entry.joint_velocities is None:
        raise SceneError(f"{field}.joint_velocities", MISSING, "required key is missing (or give the robot a urdf)")
    if isinstance(entry.joint_velocities, dict):
        reason = "joints can be named only for a robot with a urdf; give a list, one per Jacobian column"
        raise SceneError(f"{field}.joint_velocities", entry.joint_velocities, reason)
    return plain_robot(name, entry)


def _shape(entry: ShapeFile, folder: Path, field: str) -> Shape:
    planar = [kind for kind in _PLANAR_KINDS if kind != "box" and getattr(entry, kind) is not None]
    if planar:
        value = getattr(entry, planar[0])
        value = value.model_dump() if isinstance(value, HalfspaceFile) else value  # the file's words, not the class's
        raise SceneError(f"{field}.{planar[0]}", value, "a planar shape: give the scene dimension: 2")
    given = [kind for kind in _SHAPE_KINDS if getattr(entry, kind) is not None]
    if len(given) != 1:
        reason = f"give exactly one of {', '.join(_SHAPE_KINDS)}" + (f" (given: {', '.join(given)})" if given else "")
        raise SceneError(field, given or None, reason)
    kind = given[0]
    if entry.scale is not None and kind != "mesh":
        raise SceneError(f"{field}.scale", entry.scale, "only a mesh takes a scale")
    try:
        return _built_shape(entry, kind, folder)
    except SceneError as exc:
        # The shape classes name their own parts (``box.size``, ``mesh.path``): report the file's key instead.
        key = "scale" if exc.field.endswith(".scale") else kind
        raise SceneError(f"{field}.{key}", exc.value, exc.reason) from None


def _built_shape(entry: ShapeFile, kind: str, folder: Path) -> Shape:
    if entry.box is not None:
        return Box(entry.box)
    if entry.sphere is not None:
        return Sphere(entry.sphere)
    if entry.cylinder is not None:
        return Cylinder(entry.cylinder.radius, entry.cylinder.length)
    if entry.capsule is not None:
        return Capsule(entry.capsule.radius, entry.capsule.length)
    if entry.halfspace is not None:
        return Halfspace(entry.halfspace.normal, entry.halfspace.offset)
    assert entry.mesh is not None and kind == "mesh"
    return Mesh(_path(entry.mesh, folder), 1.0 if entry.scale is None else entry.scale)


def _pose(entry: PoseFile | None, field: str) -> Pose:
    if entry is None:
        return Pose()
    if entry.angle is not None:
        raise SceneError(f"{field}.angle", entry.angle, "an angle places a planar shape (dimension: 2); in 3-D give a rotation")
    position = _vector(entry.position, f"{field}.position")
    rotation = entry.rotation
    if rotation is None:
        return Pose(position)
    given = [key for key in ("rpy", "quaternion", "matrix") if getattr(rotation, key) is not None]
    if len(given) != 1:
        raise SceneError(f"{field}.rotation", given or None, "give exactly one of rpy, quaternion (w, x, y, z) or matrix")
    try:
        if rotation.rpy is not None:
            return Pose.from_rpy(position, rotation.rpy)
        if rotation.quaternion is not None:
            return Pose.from_quaternion(position, rotation.quaternion)
        return Pose(position, np.array(rotation.matrix, dtype=float))
    except SceneError as exc:  # Pose names its own parts (``pose.quaternion``): report the file's key
        raise SceneError(f"{field}.rotation.{given[0]}", exc.value, exc.reason) from None


def _vector(values: list[float], field: str) -> np.ndarray:
    if len(values) != 3:
        raise SceneError(field, values, "expected a list of 3 numbers")
    array = np.array(values, dtype=float)
    if not np.all(np.isfinite(array)):
        raise SceneError(field, values, "every entry must be a finite number (no NaN or inf)")
    return array


def _path(text: str, folder: Path) -> Path:
    path = Path(text).expanduser()
    return path if path.is_absolute() else folder / path


def _detection(entry: DetectionFile | None) -> ContactDetection:
    if entry is None:
        return ContactDetection()
    if entry.margin is not None and not (np.isfinite(entry.margin) and entry.margin >= 0):
        raise SceneError("contact_detection.margin", entry.margin, "must be a finite length >= 0")
    pairs = []
    for index, pair in enumerate(entry.friction.pairs):
        field = f"contact_detection.friction.pairs[{index}]"
        if len(pair.between) != 2:
            raise SceneError(f"{field}.between", pair.between, "expected two names")
        pairs.append(FrictionPair((pair.between[0], pair.between[1]), _mu(pair.mu, f"{field}.mu")))
    default = stiffness_of(entry.stiffness.default, "contact_detection.stiffness.default")
    mu = _mu(entry.friction.default, "contact_detection.friction.default")
    return ContactDetection(entry.margin, mu, tuple(pairs), default, _stiffness_pairs(entry.stiffness.pairs))


def _stiffness_pairs(entries: list[StiffnessPairFile]) -> tuple[StiffnessPair, ...]:
    pairs = []
    for index, pair in enumerate(entries):
        field = f"contact_detection.stiffness.pairs[{index}]"
        if len(pair.between) != 2:
            raise SceneError(f"{field}.between", pair.between, "expected two names")
        stiffness = stiffness_of(StiffnessFile(normal=pair.normal, tangential=pair.tangential), field)
        assert stiffness is not None  # an entry was given
        pairs.append(StiffnessPair((pair.between[0], pair.between[1]), stiffness))
    return tuple(pairs)


def _mu(value: float, field: str) -> float:
    # The Scene bounds mu per contact as well; checking here names the setting rather than a detected contact.
    if not (np.isfinite(value) and 0 <= value <= MAX_FRICTION):
        raise SceneError(field, value, f"must be a finite number between 0 and {MAX_FRICTION:g}")
    return float(value)


def _contact(entry: ContactFile, index: int) -> Contact:
    with _within(f"contacts[{index}]"):
        try:
            stiffness = stiffness_of(entry.stiffness, "stiffness")
            return Contact(entry.body, entry.other, entry.point, entry.normal, entry.mu, entry.jacobian, stiffness)
        except SceneError as exc:
            raise SceneError(exc.field.removeprefix("contact."), exc.value, exc.reason) from None


# --------------------------------------------------------------------------- planar scenes (dimension: 2)


def _planar_world(parsed: SceneFile) -> PlanarWorld:
    """The PlanarWorld of a ``dimension: 2`` file: planar shapes and poses, no URDF robots."""
    for name, robot in parsed.robots.items():
        if robot.urdf is not None:
            raise SceneError(f"robots.{name}.urdf", robot.urdf, "URDF robots are 3-D; a planar scene (dimension: 2) takes shapes only")
    return PlanarWorld(
        bodies=tuple(_planar_body(name, b) for name, b in parsed.bodies.items()),
        movers=tuple(_planar_mover(name, m) for name, m in parsed.movers.items()),
        explicit_robots=tuple(_plain_robot(name, r) for name, r in parsed.robots.items()),
        contacts=tuple(_contact(c, index) for index, c in enumerate(parsed.contacts)),
        detection=_detection(parsed.contact_detection),
        gravity=parsed.gravity,
        friction=parsed.friction,
        stiffness=stiffness_of(parsed.stiffness, "stiffness"),
        closing_time=parsed.closing_time,
    )


def _planar_body(name: str, entry: BodyFile) -> PlanarBody:
    field = f"bodies.{name}"
    shape = None if entry.shape is None else _planar_shape(entry.shape, f"{field}.shape")
    pose = _planar_pose(entry.pose, f"{field}.pose")
    com = [0.0, 0.0] if entry.com is None else entry.com
    if len(com) != 2 or not np.all(np.isfinite(com)):
        raise SceneError(f"{field}.com", com, "expected [x, y], finite, in a planar scene")
    return PlanarBody(name, entry.mass, shape, pose, np.array(com, dtype=float), entry.wrench)


def _planar_mover(name: str, entry: MoverFile | None) -> PlanarMover:
    field = f"movers.{name}"
    if entry is None:
        return PlanarMover(name)
    _refuse_robot_and_origin(entry, field, "in a planar scene of shapes, a mover's twist [vx, vy, w] is about its pose's position")
    shape = None if entry.shape is None else _planar_shape(entry.shape, f"{field}.shape")
    return PlanarMover(name, shape, _planar_pose(entry.pose, f"{field}.pose"), entry.twist)


def _refuse_robot_and_origin(entry: MoverFile, field: str, reason: str) -> None:
    """A mover of a scene of shapes takes neither ``robot`` nor ``origin`` (its twist is about its pose's position)."""
    if entry.robot is not None or entry.origin is not None:
        key = "robot" if entry.robot is not None else "origin"
        raise SceneError(f"{field}.{key}", getattr(entry, key), reason)


def _planar_shape(entry: ShapeFile, field: str) -> PlanarShape:
    given = [kind for kind in (*_PLANAR_KINDS, *_SHAPE_KINDS[1:]) if getattr(entry, kind) is not None]
    if given and given[0] not in _PLANAR_KINDS:
        reason = "a 3-D shape; a planar scene takes disk, box, polygon or halfplane"
        raise SceneError(f"{field}.{given[0]}", getattr(entry, given[0]), reason)
    if len(given) != 1:
        raise SceneError(field, given or None, f"give exactly one of {', '.join(_PLANAR_KINDS)}")
    if entry.scale is not None:
        raise SceneError(f"{field}.scale", entry.scale, "only a mesh takes a scale (3-D)")
    kind = given[0]
    path = f"{field}.{kind}"
    if entry.disk is not None:
        return Disk(entry.disk, path)
    if entry.box is not None:
        return Rectangle(entry.box, path)
    if entry.polygon is not None:
        return Polygon(entry.polygon, path)
    assert entry.halfplane is not None
    return HalfPlane(entry.halfplane.normal, entry.halfplane.offset, path)


def _planar_pose(entry: PoseFile | None, field: str) -> Pose:
    if entry is None:
        return planar_pose()
    if entry.rotation is not None:
        raise SceneError(f"{field}.rotation", "rotation", "a planar pose turns by an angle: {position: [x, y], angle: theta}")
    position = entry.position if "position" in entry.model_fields_set else [0.0, 0.0]
    return planar_pose(position, 0.0 if entry.angle is None else entry.angle, field)
