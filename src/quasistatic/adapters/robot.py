"""Robots from their URDF, through Pinocchio: forward kinematics, collision geometry and point Jacobians.

A :class:`UrdfRobot` is one robot at one configuration: its joint positions,
joint velocities and base pose. The URDF is parsed once; :meth:`UrdfRobot.at`
gives the same robot at another configuration without parsing again (what a
simulation step does). Everything it hands out is numpy and :class:`Pose`:
no Pinocchio type leaves this module.

Joint positions and velocities have one entry per joint degree of freedom in
the model's order (:attr:`UrdfRobot.joint_names`): revolute, continuous and
prismatic joints, in rad or length units. Fixed joints are merged away by
Pinocchio; other joint types (floating, planar, spherical) are rejected.
"""

from __future__ import annotations

import sysconfig
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import BackendUnavailableError, SceneError
from ..model import checked_number
from ..model.io import read_text
from ..stdio import captured_stderr, first_lines
from ..tolerances import MAX_MAGNITUDE
from .shapes import Pose, Shape, shape_from_coal

__all__ = [
    "UrdfRobot",
    "RobotCollider",
    "RobotVisual",
    "JointValues",
    "ROBOTS_INSTALL_HINT",
    "link_owner",
    "installed_model_folders",
    "resolve_package_path",
]

FloatArray = npt.NDArray[np.float64]
JointValues = Sequence[float] | Mapping[str, float] | FloatArray
"""Joint positions or velocities: a list or array in model order, or a mapping by joint name (others at 0)."""

ROBOTS_INSTALL_HINT = "install the robots extra: pip install 'quasistatic[robots]'"
_PACKAGE = "package://"


def installed_model_folders() -> list[Path]:
    """Where pip-installed robot model packages put their files (``example-robot-data`` among them): searched for
    ``package://`` paths after the scene's own ``package_dirs``. Nothing is downloaded."""
    share = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share"
    return [share] if share.is_dir() else []


def resolve_package_path(text: str, folders: Sequence[Path], field: str) -> Path:
    """A path, or ``package://name/rest`` found as ``folder/name/rest`` in the first folder that has it."""
    if not text.startswith(_PACKAGE):
        return Path(text)
    relative = text.removeprefix(_PACKAGE)
    for folder in folders:
        if (folder / relative).exists():
            return folder / relative
    searched = ", ".join(str(f) for f in folders) or "none (give package_dirs)"
    hint = "; example-robot-data's models install with: pip install 'quasistatic[models]'" if "example-robot-data" in text else ""
    raise SceneError(field, text, f"no such file in the package folders searched: {searched}{hint}")


def link_owner(robot: str, link: str) -> str:
    """The name of a robot link as a mover in the Scene: ``hand/link_3.0_tip``."""
    return f"{robot}/{link}"


@dataclass(frozen=True)
class RobotCollider:
    """One collision shape of a robot link, placed in the world at the robot's configuration."""

    owner: str
    link: str
    shape: Shape
    pose: Pose


@dataclass(frozen=True)
class RobotVisual:
    """One visual geometry of a robot link at the robot's configuration: a triangle mesh in the link's frame, placed.

    ``vertices`` (n, 3) are in the geometry's own frame, scaled [length]; ``faces`` (f, 3) index them;
    ``colour`` is the URDF's RGBA. A primitive visual (box, sphere...) has no mesh: ``shape`` holds it.
    """

    link: str
    pose: Pose
    colour: tuple[float, float, float, float]
    vertices: FloatArray | None = None
    faces: npt.NDArray[np.int64] | None = None
    shape: Shape | None = None


@dataclass(frozen=True)
class _VisualPart:
    """A visual geometry as parsed once: its joint, its placement in the joint's frame, and what to draw."""

    joint: int
    in_joint: FloatArray
    link: str
    colour: tuple[float, float, float, float]
    vertices: FloatArray | None
    faces: npt.NDArray[np.int64] | None
    shape: Shape | None


class _Kinematics:
    """Pinocchio's model and collision model of one URDF, parsed once and shared by every configuration."""

    def __init__(self, urdf: Path, package_dirs: Sequence[Path], field: str) -> None:
        pinocchio = _pinocchio()
        text = read_text(urdf, field, "the URDF")  # bounded read: a device or a huge file never reaches the parser
        with captured_stderr() as errors:
            try:
                self.model = pinocchio.buildModelFromXML(text)
            except (ValueError, RuntimeError) as exc:
                raise SceneError(field, Path(urdf), f"not a valid URDF: {first_lines(errors()) or exc}") from None
            try:
                # From the file, not the text: mesh paths relative to the URDF resolve from its folder.
                self.geometry = pinocchio.buildGeomFromUrdf(
                    self.model, str(urdf), pinocchio.GeometryType.COLLISION, package_dirs=[str(d) for d in package_dirs] or None
                )
            except (ValueError, RuntimeError) as exc:
                reason = f"its collision geometry cannot be loaded: {first_lines(errors()) or exc}"
                raise SceneError(field, Path(urdf), f"{reason} (package:// paths are resolved in package_dirs)") from None
        self.data = self.model.createData()
        self.geometry_data = pinocchio.GeometryData(self.geometry)
        self.urdf, self.package_dirs = urdf, tuple(package_dirs)
        self._visuals: tuple[_VisualPart, ...] | None = None
        self.joint_names = self._joint_names(field, urdf)
        links = [frame for frame in self.model.frames if frame.type == pinocchio.FrameType.BODY]
        self.link_names = tuple(frame.name for frame in links)
        # Constant offsets: a link's frame, and each collision geometry, in its parent joint's frame.
        self.link_in_joint = {frame.name: (int(frame.parentJoint), _matrix(frame.placement)) for frame in links}
        self.geometry_in_joint = np.array([_matrix(item.placement) for item in self.geometry.geometryObjects]).reshape(-1, 4, 4)
        self.geometry_joint = np.array([int(item.parentJoint) for item in self.geometry.geometryObjects], dtype=int)
        self.geometry_link = tuple(self.model.frames[item.parentFrame].name for item in self.geometry.geometryObjects)
        # Converted once: a Shape keeps the coal geometry built from it, so every configuration reuses it.
        self.shapes = tuple(
            shape_from_coal(item.geometry, f"{field}: collision geometry {item.name!r}") for item in self.geometry.geometryObjects
        )
        self.chain_columns = self._chain_columns()
        self.moves = self._moves()
        joints = [self.model.joints[joint_id] for joint_id in range(1, self.model.njoints)]
        self.plain_dof = np.array([i for i, j in enumerate(joints) if j.nq == 1], dtype=int)
        self.plain_q = np.array([j.idx_q for j in joints if j.nq == 1], dtype=int)
        self.circle_dof = np.array([i for i, j in enumerate(joints) if j.nq == 2], dtype=int)  # continuous: cos, sin
        self.circle_q = np.array([j.idx_q for j in joints if j.nq == 2], dtype=int)

    def visual_parts(self) -> tuple[_VisualPart, ...]:
        """The URDF's visual geometries, parsed on first use (only a viewer needs them); () if they cannot be loaded."""
        if self._visuals is None:
            self._visuals = _visual_parts(self)
        return self._visuals

    def _joint_names(self, field: str, urdf: Path) -> tuple[str, ...]:
        """One name per degree of freedom; a joint with other than one (revolute, prismatic, continuous) is rejected."""
        names = []
        for joint_id in range(1, self.model.njoints):
            joint, name = self.model.joints[joint_id], self.model.names[joint_id]
            if joint.nv != 1:
                raise SceneError(field, Path(urdf), f"joint {name!r} has {joint.nv} degrees of freedom; only 1-DOF joints are supported")
            names.append(name)
        return tuple(names)

    def _moves(self) -> FloatArray:
        """``[j, k]`` = 1 when the joint of velocity column j is a strict ancestor of that of column k (it moves it)."""
        moves = np.zeros((self.model.nv, self.model.nv))
        for joint_id in range(1, self.model.njoints):
            k = self.model.joints[joint_id].idx_v
            for ancestor in self.model.supports[joint_id]:
                if 0 < ancestor != joint_id:
                    moves[self.model.joints[ancestor].idx_v, k] = 1.0
        return moves

    def _chain_columns(self) -> FloatArray:
        """Per joint, a 0/1 row over the velocity columns of the joints that move it (its kinematic chain)."""
        columns = np.zeros((self.model.njoints, self.model.nv))
        for joint_id in range(1, self.model.njoints):
            for ancestor in self.model.supports[joint_id]:
                if ancestor > 0:
                    columns[joint_id, self.model.joints[ancestor].idx_v] = 1.0
        return columns

    def configuration(self, angles: FloatArray) -> FloatArray:
        """Pinocchio's configuration vector from one position per joint (a continuous joint is stored as cos, sin)."""
        q = np.zeros(self.model.nq)
        q[self.plain_q] = angles[self.plain_dof]
        q[self.circle_q] = np.cos(angles[self.circle_dof])
        q[self.circle_q + 1] = np.sin(angles[self.circle_dof])
        return q


@dataclass(frozen=True)
class _Placement:
    """What the configuration fixes, copied out of Pinocchio's scratch data: joint frames and the Jacobian."""

    joints: FloatArray  # (joints, 4, 4): each joint's frame in the world (the base pose applied)
    jacobian: FloatArray  # (6, dofs): [v of the model origin; w] per joint velocity, in the model's root frame
    base: FloatArray  # (3, 3): the base's rotation, model root frame to world

    @cached_property
    def world_jacobian(self) -> tuple[FloatArray, FloatArray]:
        """The Jacobian's linear and angular rows (3, dofs) each turned into the world frame (the model origin's velocity)."""
        return self.base @ self.jacobian[:3], self.base @ self.jacobian[3:]


class UrdfRobot:
    """A robot described by a URDF, at one configuration.

    Parameters
    ----------
    name : str
        The robot's name in the scene; its links become movers named ``name/link``.
    urdf : path
        The URDF file. ``package://`` mesh paths are resolved in ``package_dirs``.
    package_dirs : paths, optional
        Folders that hold the packages the URDF names.
    base : Pose, optional
        World pose of the robot's root link (identity by default).
    q : list or mapping, optional
        Joint positions: a list in model order (:attr:`joint_names`), or a mapping by joint name
        (unnamed joints at 0). Zero by default.
    joint_velocities : list or mapping, optional
        Joint velocities, in the same forms. Zero by default.
    torque_limits : list or mapping, optional
        Largest torque magnitude of each joint, in the same forms (a mapping names every joint);
        a motion that needs more is reported as infeasible for this robot. None: no limits.
    joint_stiffness : list or mapping, optional
        Stiffness of each joint's servo or transmission [torque/rad, or force/length for a prismatic joint], > 0,
        in the same forms (a mapping names every joint): the links then yield in series with the contact springs
        when compliant forces are worked out, through the contacts' Jacobians at this configuration. None: rigid.
    field : str, optional
        Where the robot is in a scene file, for error messages (``robots.hand``).
    """

    def __init__(
        self,
        name: str,
        urdf: str | Path,
        *,
        package_dirs: Sequence[str | Path] = (),
        base: Pose | None = None,
        q: Sequence[float] | Mapping[str, float] | None = None,
        joint_velocities: Sequence[float] | Mapping[str, float] | None = None,
        torque_limits: Sequence[float] | Mapping[str, float] | None = None,
        joint_stiffness: Sequence[float] | Mapping[str, float] | None = None,
        field: str | None = None,
    ) -> None:
        field = field or f"robots.{name}"
        _pinocchio()  # the missing extra first: its install also brings the model folders searched below
        folders = [Path(d) for d in package_dirs] + installed_model_folders()
        path = resolve_package_path(str(urdf), folders, f"{field}.urdf")
        kinematics = _Kinematics(path, folders, f"{field}.urdf")
        names = kinematics.joint_names
        angles, velocities = _per_joint(q, names, f"{field}.q"), _per_joint(joint_velocities, names, f"{field}.joint_velocities")
        self._build(name, path, kinematics, base or Pose(), angles, velocities, field)
        self.torque_limits = _limits(torque_limits, kinematics.joint_names, f"{field}.torque_limits")
        self.joint_stiffness = _stiffness(joint_stiffness, kinematics.joint_names, f"{field}.joint_stiffness")

    def _build(
        self,
        name: str,
        urdf: Path,
        kinematics: _Kinematics,
        base: Pose,
        q: FloatArray,
        joint_velocities: FloatArray,
        field: str,
    ) -> None:
        """Set the robot at a configuration whose arrays are already checked (one entry per joint)."""
        self.name = name
        self.urdf = urdf
        self.base = base
        self._kinematics = kinematics
        self._field = field
        q.setflags(write=False)  # shared by the robots at() gives, so nobody changes them behind the others' back
        joint_velocities.setflags(write=False)
        self.q = q
        self.joint_velocities = joint_velocities
        self._placement = _place(kinematics, self.q, base)
        self._colliders: tuple[RobotCollider, ...] | None = None
        self._collider_placements: tuple[FloatArray, FloatArray] | None = None

    def at(
        self,
        q: Sequence[float] | Mapping[str, float] | FloatArray | None = None,
        joint_velocities: Sequence[float] | Mapping[str, float] | FloatArray | None = None,
        base: Pose | None = None,
    ) -> UrdfRobot:
        """The same robot at another configuration (what is not given is kept); the URDF is not parsed again."""
        names, field = self.joint_names, self._field
        angles = self.q if q is None else _per_joint(q, names, f"{field}.q")
        velocities = self.joint_velocities if joint_velocities is None else _per_joint(joint_velocities, names, f"{field}.joint_velocities")
        robot = UrdfRobot.__new__(UrdfRobot)
        robot.torque_limits = self.torque_limits
        robot.joint_stiffness = self.joint_stiffness
        robot._build(self.name, self.urdf, self._kinematics, self.base if base is None else base, angles, velocities, field)
        return robot

    @property
    def joint_names(self) -> tuple[str, ...]:
        """One name per joint degree of freedom, in the order of :attr:`q` and the Jacobians' columns."""
        return self._kinematics.joint_names

    @property
    def link_names(self) -> tuple[str, ...]:
        """Every link of the model."""
        return self._kinematics.link_names

    @property
    def colliders(self) -> tuple[RobotCollider, ...]:
        """The collision geometries of every link, placed in the world (built on first use)."""
        if self._colliders is None:
            kinematics = self._kinematics
            positions, rotations = self.collider_placements()
            self._colliders = tuple(
                RobotCollider(owner, link, shape, Pose.from_trusted_arrays(position, rotation))
                for owner, link, shape, position, rotation in zip(
                    self.collider_owners, kinematics.geometry_link, kinematics.shapes, positions, rotations, strict=True
                )
            )
        return self._colliders

    @property
    def visuals(self) -> tuple[RobotVisual, ...]:
        """The URDF's visual meshes (or primitives) of every link, placed at this configuration.

        Empty when the URDF has no visual geometry or its files cannot be read: a viewer then draws the
        collision shapes. Parsed once per URDF, on first use.
        """
        parts = self._kinematics.visual_parts()
        return tuple(
            RobotVisual(p.link, _pose(self._placement.joints[p.joint] @ p.in_joint), p.colour, p.vertices, p.faces, p.shape) for p in parts
        )

    @property
    def collider_owners(self) -> tuple[str, ...]:
        """Each collision geometry's link as a mover (``hand/link``), in the order of :attr:`collider_shapes`."""
        return tuple(link_owner(self.name, link) for link in self._kinematics.geometry_link)

    @property
    def collider_shapes(self) -> tuple[Shape, ...]:
        """Each collision geometry's shape in its own frame: the same objects at every configuration."""
        return self._kinematics.shapes

    def collider_placements(self) -> tuple[FloatArray, FloatArray]:
        """World positions (g, 3) and rotations (g, 3, 3) of the collision geometries, in one batch (read-only).

        What detection needs at each configuration, without a Pose per geometry.
        """
        if self._collider_placements is None:
            kinematics = self._kinematics
            placed = self._placement.joints[kinematics.geometry_joint] @ kinematics.geometry_in_joint
            positions, rotations = placed[:, :3, 3].copy(), placed[:, :3, :3].copy()
            positions.setflags(write=False)
            rotations.setflags(write=False)
            self._collider_placements = positions, rotations
        return self._collider_placements

    def link_pose(self, link: str) -> Pose:
        """World pose of a link's frame."""
        joint, offset = self._kinematics.link_in_joint[self._link(link)]
        return _pose(self._placement.joints[joint] @ offset)

    def point_jacobian(self, link: str, point: npt.ArrayLike) -> FloatArray:
        """World velocity of the material point of ``link`` at world ``point``, per unit joint velocity: (3, joints)."""
        return self.point_jacobians([link], np.asarray(point, dtype=float).reshape(1, 3))[0]

    def point_jacobians(self, links: Sequence[str], points: npt.ArrayLike) -> FloatArray:
        """:meth:`point_jacobian` of ``links[k]`` at ``points[k]`` (k, 3), in one batch: (k, 3, joints).

        The joint Jacobians of the configuration, shifted to each point (``v(p) = v(origin) + w x p``) and
        kept to the columns of the joints that move its link.
        """
        kinematics = self._kinematics
        chains = kinematics.chain_columns[[kinematics.link_in_joint[self._link(link)][0] for link in links]]  # (k, joints)
        linear, angular = self._placement.world_jacobian  # (3, joints) each, in the world
        r = np.asarray(points, dtype=float).reshape(-1, 3) - self.base.position  # from the model origin, world frame
        # The linear rows minus r x (angular rows), per point (np.cross costs more than writing it out).
        x, y, z = r[:, 0, None], r[:, 1, None], r[:, 2, None]
        wx, wy, wz = angular
        shifted = np.empty((len(r), 3, angular.shape[1]))
        shifted[:, 0], shifted[:, 1], shifted[:, 2] = y * wz - z * wy, z * wx - x * wz, x * wy - y * wx
        np.subtract(linear, shifted, out=shifted)
        shifted *= chains[:, None, :]
        return shifted

    def point_jacobian_rates(self, link: str, point: npt.ArrayLike) -> FloatArray:
        """How :meth:`point_jacobian` of ``link`` at the fixed world ``point`` changes with each joint position:
        (3, joints, joints), entry ``[:, j, k]`` = d(column k)/d(q_j) [per rad, or per length for a prismatic joint].

        Analytic, from the configuration's own spatial Jacobian: a joint's twist ``xi_k = (v_k, w_k)`` (velocity of
        the world origin's point, angular velocity) turns with every joint ``j`` that moves it by the Lie bracket
        ``[xi_j, xi_k] = (w_j x v_k - w_k x v_j, w_j x w_k)``; the point's column is ``v_k + w_k x p``.
        """
        kinematics = self._kinematics
        chain = kinematics.chain_columns[kinematics.link_in_joint[self._link(link)][0]]
        jacobian = self._placement.jacobian * chain  # (6, joints): only the joints that move the link
        v, w = jacobian[:3].T, jacobian[3:].T  # (joints, 3)
        local = (np.asarray(point, dtype=float).reshape(3) - self.base.position) @ self.base.rotation
        moves = kinematics.moves  # moves[j, k]: joint j is a strict ancestor of joint k
        dv = np.cross(w[:, None, :], v[None, :, :]) - np.cross(w[None, :, :], v[:, None, :])  # (j, k, 3)
        dw = np.cross(w[:, None, :], w[None, :, :])
        rates = (dv + np.cross(dw, local)) * moves[:, :, None]
        result: FloatArray = np.einsum("ab,jkb->ajk", self.base.rotation, rates)
        return result

    def _link(self, link: str) -> str:
        if link not in self._kinematics.link_in_joint:
            raise SceneError(f"{self._field}.links", link, f"no link of that name in {self.urdf.name}")
        return link


def _place(kinematics: _Kinematics, angles: FloatArray, base: Pose) -> _Placement:
    """Forward kinematics and the joint Jacobians at ``angles`` (Pinocchio's data is scratch: copy what is kept)."""
    pinocchio = _pinocchio()
    model, data = kinematics.model, kinematics.data
    pinocchio.computeJointJacobians(model, data, kinematics.configuration(angles))  # runs the forward kinematics too
    joints = np.array([placement.homogeneous for placement in data.oMi.tolist()])  # a list iterates faster than Pinocchio's vector
    return _Placement(base.matrix() @ joints, np.array(data.J, dtype=float), base.rotation)


def _matrix(placement: Any) -> FloatArray:
    """Pinocchio's SE3 as a 4x4 homogeneous matrix."""
    return np.array(placement.homogeneous, dtype=float)


def _pose(matrix: FloatArray) -> Pose:
    """The pose of a rigid matrix from Pinocchio's forward kinematics: orthonormal to round-off, no check needed."""
    return Pose.from_trusted_arrays(matrix[:3, 3].copy(), matrix[:3, :3].copy())


def _per_joint(values: Any, names: tuple[str, ...], field: str) -> FloatArray:
    """One finite number per joint, from a list in model order or a mapping by name (missing names are 0)."""
    result = np.zeros(len(names))
    if values is None:
        return result
    if isinstance(values, Mapping):
        for joint, value in values.items():
            if joint not in names:
                shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "")
                raise SceneError(f"{field}.{joint}", joint, f"no joint of that name; the joints are {shown}")
            result[names.index(joint)] = checked_number(value, f"{field}.{joint}")
        return result
    if isinstance(values, (str, bytes)) or np.ndim(values) != 1:
        raise SceneError(field, values, "expected a list of numbers, one per joint, or a mapping by joint name")
    if len(values) != len(names):
        raise SceneError(field, f"{len(values)} values", f"expected {len(names)}, one per joint ({', '.join(names[:8])}, ...)")
    if isinstance(values, np.ndarray) and values.dtype.kind == "f" and np.all(np.abs(values) <= MAX_MAGNITUDE):
        return values.astype(float)  # a simulation's own arrays: checked at once (NaN fails the comparison)
    for index, value in enumerate(values):
        result[index] = checked_number(value, f"{field}[{index}]")
    return result


def _limits(values: Any, names: tuple[str, ...], field: str) -> FloatArray | None:
    """Torque limits as :func:`_per_joint` reads them, except that a mapping must name every joint (no limit is not 0)."""
    if values is None:
        return None
    if isinstance(values, Mapping) and set(values) != set(names) and set(values) <= set(names):
        missing = ", ".join(n for n in names if n not in values)
        raise SceneError(field, dict(values), f"name every joint (missing: {missing})")
    return _per_joint(values, names, field)


def _stiffness(values: Any, names: tuple[str, ...], field: str) -> FloatArray | None:
    """Joint stiffness as :func:`_limits` reads it (a mapping names every joint: a missing one is not 0), each > 0."""
    stiffness = _limits(values, names, field)
    if stiffness is not None and not np.all(stiffness > 0.0):
        shown = dict(values) if isinstance(values, Mapping) else stiffness.tolist()
        raise SceneError(field, shown, "every joint stiffness must be > 0 (leave the key out for rigid joints)")
    return stiffness


def _pinocchio() -> Any:
    try:
        import pinocchio
    except ImportError:
        raise BackendUnavailableError("Pinocchio", ROBOTS_INSTALL_HINT, needed_for="URDF robots") from None
    return pinocchio


def _visual_parts(kinematics: _Kinematics) -> tuple[_VisualPart, ...]:
    pinocchio = _pinocchio()
    with captured_stderr():
        try:
            visual = pinocchio.buildGeomFromUrdf(
                kinematics.model,
                str(kinematics.urdf),
                pinocchio.GeometryType.VISUAL,
                package_dirs=[str(d) for d in kinematics.package_dirs] or None,
            )
        except (ValueError, RuntimeError):
            return ()
    parts = []
    for item in visual.geometryObjects:
        link = kinematics.model.frames[item.parentFrame].name
        colour = tuple(float(c) for c in np.asarray(item.meshColor, dtype=float)[:4])
        mesh, shape = _triangles(item.geometry), None
        if mesh is None:
            try:
                shape = shape_from_coal(item.geometry, f"visual geometry {item.name!r}")
            except SceneError:
                continue  # a kind nobody draws (cone, ellipsoid): the collision shapes still show the link
        vertices, faces = (None, None) if mesh is None else mesh
        parts.append(_VisualPart(int(item.parentJoint), _matrix(item.placement), link, colour, vertices, faces, shape))  # type: ignore[arg-type]
    return tuple(parts)


def _triangles(geometry: Any) -> tuple[FloatArray, npt.NDArray[np.int64]] | None:
    """Vertices and triangles of a coal BVH mesh (pinocchio has applied the URDF's scale); None for other kinds."""
    if not hasattr(geometry, "tri_indices"):
        return None
    vertices = np.array(geometry.vertices(), dtype=float).reshape(-1, 3)
    faces = np.array([[t[0], t[1], t[2]] for t in (geometry.tri_indices(i) for i in range(geometry.num_tris))], dtype=np.int64).reshape(
        -1, 3
    )
    return vertices, faces
