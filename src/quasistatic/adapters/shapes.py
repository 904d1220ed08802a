"""Poses and collision shapes in 3-D: frozen values, validated once when built.

Every constructor takes a ``field``, the path of the value in the caller's
input (``bodies.cube.shape.box``), so a bad number is reported where the user
wrote it. Shapes carry no coal type: contact detection builds its coal
geometry from them once and keeps it with the shape (:meth:`derived`).

Meshes are used through their convex hull: contact patches, the exact contact
polygons :mod:`.detect` reports, exist only between convex shapes, and coal's
triangle-soup queries return a zero normal when a point lies on a triangle.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import checked_array, checked_number
from ..tolerances import NORMAL_LENGTH, QUATERNION_NORM, ROTATION_ORTHONORMAL
from ._coal import import_coal

__all__ = [
    "Pose",
    "Box",
    "Sphere",
    "Cylinder",
    "Capsule",
    "Halfspace",
    "Convex",
    "Mesh",
    "Shape",
    "shape_from_coal",
    "FloatArray",
    "IntArray",
]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
T = TypeVar("T")


# --------------------------------------------------------------------------- number checks (the model's, with shapes)


def _vector(value: Any, path: str, shape: tuple[int, ...]) -> FloatArray:
    """A read-only float array of the given shape, every entry finite and within :data:`MAX_MAGNITUDE`."""
    array = checked_array(value, path, ndim=len(shape))
    if array.shape != shape:
        raise SceneError(path, value, f"expected an array of shape {shape}, got shape {array.shape}")
    return array


def _number(value: Any, path: str) -> float:
    return checked_number(value, path)


def _positive(value: Any, path: str) -> float:
    """A size: a finite number > 0 [length]."""
    number = _number(value, path)
    if number <= 0.0:
        raise SceneError(path, value, "must be > 0 (a size)")
    return number


def _positive_vector(value: Any, path: str) -> FloatArray:
    array = _vector(value, path, (3,))
    if np.any(array <= 0.0):
        raise SceneError(path, value, "every entry must be > 0 (sizes)")
    return array


def _assign(obj: object, **values: Any) -> None:
    """Set the fields of a frozen value while it is being built (its own ``__init__`` only)."""
    for key, value in values.items():
        object.__setattr__(obj, key, value)


# --------------------------------------------------------------------------- poses


def _rotation(value: Any, path: str) -> FloatArray:
    """A rotation matrix, projected onto SO(3) when within :data:`ROTATION_ORTHONORMAL` of it."""
    matrix = np.array(_vector(value, path, (3, 3)))
    error = float(np.max(np.abs(matrix.T @ matrix - np.eye(3))))
    if error > ROTATION_ORTHONORMAL or np.linalg.det(matrix) <= 0.0:
        raise SceneError(path, value, f"not a rotation matrix (|R^T R - I| = {error:.2g}, det = {np.linalg.det(matrix):.3g})")
    u, _, vt = np.linalg.svd(matrix)
    projected = u @ vt
    projected.setflags(write=False)
    return projected


@dataclass(frozen=True, init=False)
class Pose:
    """A rigid placement: ``x_world = rotation @ x_local + position``.

    Attributes
    ----------
    position : array (3,)
        Origin of the local frame in the world [length].
    rotation : array (3, 3)
        Columns: the local axes in the world (a proper rotation).
    """

    position: FloatArray
    rotation: FloatArray

    def __init__(self, position: npt.ArrayLike = (0.0, 0.0, 0.0), rotation: npt.ArrayLike | None = None, field: str = "pose") -> None:
        _assign(
            self,
            position=_vector(position, f"{field}.position", (3,)),
            rotation=_rotation(np.eye(3) if rotation is None else rotation, f"{field}.rotation"),
        )

    @classmethod
    def from_trusted_arrays(cls, position: FloatArray, rotation: FloatArray) -> Pose:
        """A pose from arrays computed by this package from validated ones (forward kinematics, an inverse).

        For inner loops over arrays already known good: no check, no projection onto SO(3), which would cost
        more than the forward kinematics itself (a robot builds one pose per collider per configuration).
        The arrays are made read-only, not copied: the caller hands them over.
        """
        pose = cls.__new__(cls)
        position.setflags(write=False)
        rotation.setflags(write=False)
        _assign(pose, position=position, rotation=rotation)
        return pose

    @classmethod
    def from_rpy(cls, position: npt.ArrayLike, rpy: npt.ArrayLike, field: str = "pose") -> Pose:
        """A pose from roll, pitch, yaw [rad] about the fixed x, y, z axes: ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (URDF)."""
        roll, pitch, yaw = _vector(rpy, f"{field}.rpy", (3,))
        cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
        rotation = [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
        return cls(position, rotation, field)

    @classmethod
    def from_quaternion(cls, position: npt.ArrayLike, wxyz: npt.ArrayLike, field: str = "pose") -> Pose:
        """A pose from a unit quaternion ``(w, x, y, z)``, normalised when within :data:`QUATERNION_NORM` of unit length."""
        q = _vector(wxyz, f"{field}.quaternion", (4,))
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > QUATERNION_NORM:
            raise SceneError(f"{field}.quaternion", wxyz, f"must be a unit quaternion (its norm is {norm:.6g})")
        w, x, y, z = q / norm
        rotation = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
        return cls(position, rotation, field)

    def matrix(self) -> FloatArray:
        """The 4x4 homogeneous matrix ``[[R, p], [0, 1]]``."""
        out = np.eye(4)
        out[:3, :3] = self.rotation
        out[:3, 3] = self.position
        return out

    def compose(self, other: Pose) -> Pose:
        """``self * other``: ``other`` given in this pose's frame, placed in the world."""
        return Pose(self.rotation @ other.position + self.position, self.rotation @ other.rotation)

    def inverse(self) -> Pose:
        """The pose that undoes this one: ``self.compose(self.inverse())`` is the identity."""
        return Pose.from_trusted_arrays(-(self.rotation.T @ self.position), np.array(self.rotation.T))  # R^T of a rotation is one

    def apply(self, points: npt.ArrayLike) -> FloatArray:
        """World coordinates of local points, shape (3,) or (n, 3) [length]."""
        return np.asarray(points, dtype=float) @ self.rotation.T + self.position


# --------------------------------------------------------------------------- shapes


class _Derived:
    """What later stages derive from a frozen value (its coal geometry), kept with it and never pickled."""

    def derived(self, key: str, build: Callable[[Any], T]) -> T:
        """``build(self)``, computed once and kept with this shape (shapes are frozen)."""
        values: dict[str, Any] = self.__dict__.setdefault("_derived", {})
        if key not in values:
            values[key] = build(self)
        return cast(T, values[key])

    def __getstate__(self) -> dict[str, Any]:
        return {key: value for key, value in self.__dict__.items() if key != "_derived"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)


@dataclass(frozen=True, init=False)
class Box(_Derived):
    """A box centred on its frame's origin, edges along its axes.

    Attributes
    ----------
    size : array (3,)
        Full edge lengths along x, y, z [length], each > 0.
    """

    size: FloatArray

    def __init__(self, size: npt.ArrayLike, field: str = "box") -> None:
        _assign(self, size=_positive_vector(size, f"{field}.size"))

    @property
    def extent(self) -> float:
        """Largest dimension [length]: the scale of the tolerances of its contacts."""
        return max(self.size.tolist())  # plain floats: detection asks for it per pair


@dataclass(frozen=True, init=False)
class Sphere(_Derived):
    """A sphere centred on its frame's origin; ``radius`` [length] > 0."""

    radius: float

    def __init__(self, radius: float, field: str = "sphere") -> None:
        _assign(self, radius=_positive(radius, f"{field}.radius"))

    @property
    def extent(self) -> float:
        """Diameter [length]."""
        return 2.0 * self.radius


@dataclass(frozen=True, init=False)
class Cylinder(_Derived):
    """A cylinder centred on its frame's origin, axis along local z (as in URDF).

    Attributes
    ----------
    radius, length : float
        Radius and full length along z [length], each > 0.
    """

    radius: float
    length: float

    def __init__(self, radius: float, length: float, field: str = "cylinder") -> None:
        _assign(self, radius=_positive(radius, f"{field}.radius"), length=_positive(length, f"{field}.length"))

    @property
    def extent(self) -> float:
        """Largest dimension [length]."""
        return max(2.0 * self.radius, self.length)


@dataclass(frozen=True, init=False)
class Capsule(_Derived):
    """A capsule: the points within ``radius`` of a segment of ``length`` along local z, centred on the origin.

    Attributes
    ----------
    radius, length : float
        Radius and length of the segment (without the caps) [length], each > 0.
    """

    radius: float
    length: float

    def __init__(self, radius: float, length: float, field: str = "capsule") -> None:
        _assign(self, radius=_positive(radius, f"{field}.radius"), length=_positive(length, f"{field}.length"))

    @property
    def extent(self) -> float:
        """Largest dimension, caps included [length]."""
        return self.length + 2.0 * self.radius


@dataclass(frozen=True, init=False)
class Halfspace(_Derived):
    """The points ``x`` (local frame) with ``normal @ x <= offset``: a table, a wall.

    Attributes
    ----------
    normal : array (3,)
        Unit outward normal (normalised if within 1e-3 of unit length).
    offset : float
        Distance of the boundary plane from the origin along ``normal`` [length].
    """

    normal: FloatArray
    offset: float

    def __init__(self, normal: npt.ArrayLike = (0.0, 0.0, 1.0), offset: float = 0.0, field: str = "halfspace") -> None:
        vector = _vector(normal, f"{field}.normal", (3,))
        length = float(np.linalg.norm(vector))
        if abs(length - 1.0) > NORMAL_LENGTH:
            raise SceneError(f"{field}.normal", normal, f"must be a unit vector (its length is {length:.6g})")
        unit = vector / length
        unit.setflags(write=False)
        _assign(self, normal=unit, offset=_number(offset, f"{field}.offset"))

    @property
    def extent(self) -> float:
        """Unbounded: a halfspace's contacts take their scale from the other shape."""
        return math.inf


@dataclass(frozen=True, init=False)
class Convex(_Derived):
    """The convex hull of a set of points (local frame).

    Attributes
    ----------
    vertices : array (n, 3)
        The hull's vertices [length]; points inside it or on its faces are dropped.
    triangles : int array (m, 3)
        The hull's faces, as indices into ``vertices``, counter-clockwise seen from outside.
    """

    vertices: FloatArray
    triangles: IntArray

    def __init__(self, points: npt.ArrayLike, field: str = "convex") -> None:
        vertices, triangles = _hull(points, f"{field}.points")
        _assign(self, vertices=vertices, triangles=triangles)

    @property
    def extent(self) -> float:
        """Largest edge of its bounding box [length] (computed once: detection asks for it per pair)."""
        return self.derived("extent", lambda convex: float(np.max(np.ptp(convex.vertices, axis=0))))


def _hull(value: Any, path: str) -> tuple[FloatArray, IntArray]:
    """Vertices and outward-facing triangles of the convex hull of ``value`` (n, 3), n >= 4, not all in a plane."""
    from scipy.spatial import ConvexHull, QhullError

    if isinstance(value, (str, bytes)) or np.ndim(value) != 2:
        raise SceneError(path, value, "expected at least 4 points (an array of shape (n, 3))")
    points = checked_array(value, path, ndim=2)
    if points.shape[1] != 3 or len(points) < 4:
        raise SceneError(path, value, "expected at least 4 points (an array of shape (n, 3))")
    try:
        hull = ConvexHull(points)
    except QhullError:
        raise SceneError(path, value, "the points span no volume (all on a plane or a line)") from None
    index = np.full(len(points), -1, dtype=np.int64)
    index[hull.vertices] = np.arange(len(hull.vertices))
    triangles = index[hull.simplices]
    # qhull orders each triangle arbitrarily: turn those whose normal points inwards.
    vertices = points[hull.vertices]
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) < 0.0
    triangles[inward] = triangles[inward][:, ::-1]
    vertices.setflags(write=False)
    triangles.setflags(write=False)
    return vertices, triangles


@dataclass(frozen=True, init=False)
class Mesh(_Derived):
    """A mesh file (STL, OBJ, DAE... anything coal's loader reads), used through its convex hull.

    Attributes
    ----------
    path : str
        The file, as given.
    scale : array (3,)
        Scale along the mesh's x, y, z [-], each > 0 (a number scales all three).
    convex : Convex
        The scaled mesh's convex hull: what contact detection uses.

    Raises
    ------
    SceneError
        A missing, unreadable or malformed file, or a mesh that spans no volume.
    BackendUnavailableError
        When coal, which reads the file, is not installed.
    """

    path: str
    scale: FloatArray
    convex: Convex

    def __init__(self, path: str | os.PathLike[str], scale: float | npt.ArrayLike = 1.0, field: str = "mesh") -> None:
        if not isinstance(path, (str, os.PathLike)) or not str(path):
            raise SceneError(f"{field}.path", path, "expected the path of a mesh file")
        text = os.fspath(path)
        is_number = isinstance(scale, (int, float, np.integer, np.floating)) and not isinstance(scale, bool)
        factors = _positive_vector([scale] * 3 if is_number else scale, f"{field}.scale")
        if not os.path.isfile(text):
            reason = "not a regular file (a folder, device or pipe)" if os.path.exists(text) else "no such file"
            raise SceneError(f"{field}.path", PurePath(text), reason)
        vertices = _mesh_vertices(text, factors, f"{field}.path")
        try:
            convex = Convex(vertices, field)
        except SceneError as error:
            raise SceneError(f"{field}.path", PurePath(text), f"{error.reason} (the mesh's vertices)") from None
        _assign(self, path=text, scale=factors, convex=convex)

    @property
    def extent(self) -> float:
        """Largest edge of its hull's bounding box [length]."""
        return self.convex.extent


def _mesh_vertices(path: str, scale: FloatArray, field: str) -> FloatArray:
    """The vertices of a mesh file, scaled, read by coal's loader (assimp)."""
    coal = import_coal()
    try:
        model = coal.MeshLoader().load(path, np.asarray(scale, dtype=float))
    except (ValueError, RuntimeError) as error:
        # coal's message starts with its own source location; the last line says what is wrong.
        reason = str(error).strip().splitlines()[-1] if str(error).strip() else type(error).__name__
        raise SceneError(field, PurePath(path), f"could not read the mesh: {reason}") from None
    vertices: FloatArray = np.array(model.vertices(), dtype=float).reshape(-1, 3)
    return vertices


_SUPPORTED = "box, sphere, cylinder, capsule, halfspace, convex, mesh"

Shape = Box | Sphere | Cylinder | Capsule | Halfspace | Convex | Mesh
"""Every shape contact detection handles."""


def shape_from_coal(geometry: object, field: str = "geometry") -> Shape:
    """The :data:`Shape` of a coal collision geometry (a Pinocchio ``GeometryObject.geometry``).

    Meshes (coal's BVH models) and convex polytopes become their :class:`Convex` hull.
    Convert each geometry once, when the model is loaded: the shape then keeps the
    coal geometry detection builds from it.

    Raises
    ------
    SceneError
        For a geometry of another kind (cone, ellipsoid, plane, octree, height field)
        or one inflated by a swept-sphere radius.
    """
    coal = import_coal()
    inflation = getattr(geometry, "getSweptSphereRadius", None)
    if inflation is not None and inflation() > 0.0:
        raise SceneError(field, type(geometry).__name__, "geometries inflated by a swept-sphere radius are not supported")
    if isinstance(geometry, coal.Box):
        return Box(2.0 * np.asarray(geometry.halfSide), field)
    if isinstance(geometry, coal.Sphere):
        return Sphere(geometry.radius, field)
    if isinstance(geometry, coal.Cylinder):
        return Cylinder(geometry.radius, 2.0 * geometry.halfLength, field)
    if isinstance(geometry, coal.Capsule):
        return Capsule(geometry.radius, 2.0 * geometry.halfLength, field)
    if isinstance(geometry, coal.Halfspace):
        return Halfspace(np.asarray(geometry.n), geometry.d, field)
    if isinstance(geometry, coal.ConvexBase):
        return Convex(np.asarray(geometry.points()), field)
    if isinstance(geometry, coal.BVHModelBase):
        return Convex(np.asarray(geometry.vertices()), field)
    raise SceneError(field, type(geometry).__name__, f"unsupported geometry (supported: {_SUPPORTED})")
