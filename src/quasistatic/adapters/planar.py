"""Planar shapes and their contacts, in NumPy: the 2-D world of shapes needs no coal.

The plane is the vertical x-y plane (gravity along -y, as in Trinkle & Hunter's
examples). A planar pose is a :class:`~.shapes.Pose` restricted to the plane:
position ``[x, y, 0]``, rotation by ``angle`` about z (:func:`planar_pose`), so
simulations, trajectories and their files treat both worlds alike.

Shapes: :class:`Disk`, :class:`Rectangle` (``box: [width, height]``), convex
:class:`Polygon` and :class:`HalfPlane`. Detection (:class:`PlanarLayout`) keeps
what does not change while the shapes move (local vertices and face normals,
bounding radii, which pairs may touch), then per step: a broad phase by bounding
circles, and per near pair one exact kernel. Contact points follow the 3-D
detection's conventions (:class:`~.detect.ContactPoint`): the midpoint of the two
shapes' witness points, the normal from the second owner into the first, and each
point's own signed gap. Two polygons face on face give the two ends of their common
edge (the incident edge clipped to the reference face, as Box2D does), a polygon
on a halfplane the two extreme vertices within the margin.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import checked_array, checked_number
from ..tolerances import DUPLICATE_POINT, NORMAL_LENGTH
from .detect import ContactPoint
from .shapes import FloatArray, Pose

__all__ = ["Disk", "Rectangle", "Polygon", "HalfPlane", "PlanarShape", "PlanarLayout", "planar_pose", "pose_angle"]

Witnesses = list[tuple[FloatArray, FloatArray, float]]  # (point, normal from the second shape into the first, gap)


def planar_pose(position: npt.ArrayLike = (0.0, 0.0), angle: float = 0.0, field: str = "pose") -> Pose:
    """The pose at ``position`` [x, y] turned by ``angle`` [rad] counter-clockwise about z."""
    xy = checked_array(position, f"{field}.position")
    if xy.shape != (2,):
        raise SceneError(f"{field}.position", xy.tolist(), "expected [x, y] in a planar scene")
    theta = checked_number(angle, f"{field}.angle")
    c, s = math.cos(theta), math.sin(theta)
    return Pose.from_trusted_arrays(np.array([xy[0], xy[1], 0.0]), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))


def pose_angle(pose: Pose) -> float:
    """The angle [rad] of a planar pose's rotation about z."""
    return math.atan2(float(pose.rotation[1, 0]), float(pose.rotation[0, 0]))


def _size(value: Any, path: str) -> float:
    number = checked_number(value, path)
    if number <= 0.0:
        raise SceneError(path, value, "must be > 0 (a size)")
    return number


@dataclass(frozen=True, init=False)
class Disk:
    """A disk of ``radius`` [length] about its pose's origin."""

    radius: float

    def __init__(self, radius: float, field: str = "disk") -> None:
        object.__setattr__(self, "radius", _size(radius, field))

    @property
    def extent(self) -> float:
        """Bounding radius [length]."""
        return self.radius


@dataclass(frozen=True, init=False)
class Polygon:
    """A convex polygon (local frame).

    ``vertices`` (n, 2) may be given in either winding order, but in order around the boundary; they are kept
    counter-clockwise. Every vertex must be a corner: a repeated point, one on the segment between its
    neighbours (within :data:`DUPLICATE_POINT` of the size) or a reflex corner is rejected.
    """

    vertices: FloatArray

    def __init__(self, vertices: npt.ArrayLike, field: str = "polygon") -> None:
        points = checked_array(vertices, field, ndim=2)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3:
            raise SceneError(field, points.tolist(), "expected a list of at least 3 [x, y] vertices")
        object.__setattr__(self, "vertices", _convex_ccw(points, field))

    @property
    def extent(self) -> float:
        """Bounding radius about the local origin [length]."""
        return float(np.max(np.linalg.norm(self.vertices, axis=1)))


def _convex_ccw(points: FloatArray, field: str) -> FloatArray:
    """The vertices counter-clockwise, or a SceneError naming the first corner that is not convex."""
    size = float(np.max(np.ptp(points, axis=0)))
    area = 0.5 * float(np.sum(points[:, 0] * np.roll(points[:, 1], -1) - points[:, 1] * np.roll(points[:, 0], -1)))
    ordered = points if area > 0 else points[::-1]
    edges = np.roll(ordered, -1, axis=0) - ordered
    following = np.roll(edges, -1, axis=0)
    lengths = np.linalg.norm(edges, axis=1)
    turns = edges[:, 0] * following[:, 1] - edges[:, 1] * following[:, 0]
    # the turn at vertex k+1 as the distance of that corner from the line of edge k, relative to the size
    bent = turns / np.maximum(lengths, 1e-300) / max(size, 1e-300)
    if size <= 0.0 or abs(area) <= (DUPLICATE_POINT * size) ** 2:
        raise SceneError(field, points.tolist(), "degenerate polygon: its vertices enclose no area")
    if np.any(lengths <= DUPLICATE_POINT * size) or np.any(bent <= DUPLICATE_POINT):
        corner = ordered[(int(np.argmin(np.minimum(bent, lengths / size))) + 1) % len(ordered)].tolist()
        reason = f"not convex at vertex {corner}: give the corners of a convex polygon in order around it (either way round)"
        raise SceneError(field, points.tolist(), reason + ", with no repeated vertex and none on the segment between its neighbours")
    turning = float(np.sum(np.arctan2(turns, np.einsum("ij,ij->i", edges, following))))
    if turning > 3.0 * math.pi:  # 2 pi for a convex polygon; 4 pi or more for a star listed in order
        raise SceneError(field, points.tolist(), "not convex: the boundary winds around more than once (a star)")
    result = np.array(ordered, dtype=float)
    result.setflags(write=False)
    return result


@dataclass(frozen=True, init=False)
class Rectangle(Polygon):
    """A ``width`` x ``height`` rectangle centred on its pose's origin (a 2-D ``box``)."""

    width: float
    height: float

    def __init__(self, size: npt.ArrayLike, field: str = "box") -> None:
        values = checked_array(size, field)
        if values.shape != (2,) or np.any(values <= 0.0):
            raise SceneError(field, values.tolist(), "expected [width, height], both > 0, in a planar scene")
        w, h = float(values[0]) / 2.0, float(values[1]) / 2.0
        object.__setattr__(self, "width", 2.0 * w)
        object.__setattr__(self, "height", 2.0 * h)
        corners = np.array([[-w, -h], [w, -h], [w, h], [-w, h]])
        corners.setflags(write=False)
        object.__setattr__(self, "vertices", corners)


@dataclass(frozen=True, init=False)
class HalfPlane:
    """The points ``x`` (local frame) with ``normal @ x <= offset``: a table, a wall."""

    normal: FloatArray
    offset: float

    def __init__(self, normal: npt.ArrayLike = (0.0, 1.0), offset: float = 0.0, field: str = "halfplane") -> None:
        vector = checked_array(normal, f"{field}.normal")
        length = float(np.linalg.norm(vector)) if vector.shape == (2,) else 0.0
        if vector.shape != (2,) or abs(length - 1.0) > NORMAL_LENGTH:
            raise SceneError(f"{field}.normal", vector.tolist(), "expected a unit vector [nx, ny]")
        unit = vector / length
        unit.setflags(write=False)
        object.__setattr__(self, "normal", unit)
        object.__setattr__(self, "offset", checked_number(offset, f"{field}.offset"))

    @property
    def extent(self) -> float:
        """Unbounded."""
        return math.inf


PlanarShape: TypeAlias = Disk | Polygon | HalfPlane


# --------------------------------------------------------------------------- detection


class PlanarLayout:
    """What planar detection keeps while the shapes move: owners, shapes, and the pairs that may ever touch.

    ``free``: the names of free bodies; only pairs with one constrain a motion (two movers never do),
    and two colliders of one owner never touch.
    """

    def __init__(self, owners: Sequence[str], shapes: Sequence[PlanarShape], free: Collection[str]) -> None:
        self.owners = list(owners)
        self.shapes = list(shapes)
        self.radii = np.array([s.extent for s in shapes])
        self.sizes = np.array([s.extent if math.isfinite(s.extent) else 0.0 for s in shapes])
        pairs = [
            (i, j)
            for i in range(len(shapes))
            for j in range(i + 1, len(shapes))
            if owners[i] != owners[j]
            and (owners[i] in free or owners[j] in free)
            and not (isinstance(shapes[i], HalfPlane) and isinstance(shapes[j], HalfPlane))
        ]
        self.first = np.array([i for i, _ in pairs], dtype=int)
        self.second = np.array([j for _, j in pairs], dtype=int)
        self.kernels = [_kernel(shapes[i], shapes[j]) for i, j in pairs]

    def detect(self, poses: FloatArray, margin: float) -> list[ContactPoint]:
        """Contact points of every pair within ``margin``; ``poses`` (n, 3): each collider's [x, y, angle]."""
        placed = [_Placed(shape, pose) for shape, pose in zip(self.shapes, poses, strict=True)]
        found: list[ContactPoint] = []
        for k in np.flatnonzero(self._near(poses, margin)):
            i, j = int(self.first[k]), int(self.second[k])
            tolerance = DUPLICATE_POINT * max(min(self.sizes[i] or math.inf, self.sizes[j] or math.inf), 0.0)
            for point, normal, gap in self.kernels[k](placed[i], placed[j], margin, tolerance):
                found.append(ContactPoint(self.owners[i], self.owners[j], point, normal, gap))
        return found

    def nearest(self, poses: FloatArray, owners: Collection[str]) -> dict[str, tuple[str, float]]:
        """For each name in ``owners``: the nearest other owner it may touch and the gap (``("", inf)`` if none)."""
        placed = [_Placed(shape, pose) for shape, pose in zip(self.shapes, poses, strict=True)]
        best: dict[str, tuple[str, float]] = {name: ("", math.inf) for name in owners}
        for k, (i, j) in enumerate(zip(self.first.tolist(), self.second.tolist(), strict=True)):
            for mine, theirs in ((i, j), (j, i)):
                if self.owners[mine] in best:
                    gap = _distance(self.kernels[k], placed[i], placed[j])
                    if gap < best[self.owners[mine]][1]:
                        best[self.owners[mine]] = (self.owners[theirs], gap)
        return best

    def _near(self, poses: FloatArray, margin: float) -> npt.NDArray[np.bool_]:
        """Broad phase: bounding circles within ``margin``; against a halfplane, the circle's signed distance."""
        i, j = self.first, self.second
        centres = poses[:, :2]
        reach = np.where(np.isfinite(self.radii), self.radii, 0.0)
        distance = np.linalg.norm(centres[i] - centres[j], axis=1)
        near = distance <= reach[i] + reach[j] + margin
        for k in np.flatnonzero(~np.isfinite(self.radii[i]) | ~np.isfinite(self.radii[j])):
            plane, other = (i[k], j[k]) if not math.isfinite(self.radii[i[k]]) else (j[k], i[k])
            normal, offset = _plane_line(self.shapes[plane], poses[plane])  # type: ignore[arg-type]
            near[k] = float(normal @ centres[other]) - offset <= reach[other] + margin
        return near


class _Placed:
    """One shape at one pose, in world coordinates (vertices and outward face normals computed when asked)."""

    def __init__(self, shape: PlanarShape, pose: FloatArray) -> None:
        self.shape = shape
        self.pose = pose

    @property
    def centre(self) -> FloatArray:
        return self.pose[:2]

    def vertices(self) -> FloatArray:
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        local = self.shape.vertices  # type: ignore[union-attr]
        return np.asarray(local @ np.array([[c, s], [-s, c]]) + self.pose[:2])

    def line(self) -> tuple[FloatArray, float]:
        return _plane_line(self.shape, self.pose)  # type: ignore[arg-type]


def _plane_line(shape: HalfPlane, pose: FloatArray) -> tuple[FloatArray, float]:
    """A placed halfplane's world normal and offset."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    normal = np.array([c * shape.normal[0] - s * shape.normal[1], s * shape.normal[0] + c * shape.normal[1]])
    return normal, shape.offset + float(normal @ pose[:2])


def _faces(vertices: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Outward unit normals (n, 2) of a counter-clockwise polygon's faces (face k from vertex k to k+1) and their offsets."""
    edges = np.roll(vertices, -1, axis=0) - vertices
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.linalg.norm(edges, axis=1)[:, None]
    return normals, np.einsum("ij,ij->i", normals, vertices)


Kernel = Callable[[_Placed, _Placed, float, float], Witnesses]


def _kernel(a: PlanarShape, b: PlanarShape) -> Kernel:
    """The narrow-phase function for a pair of shape kinds, its arguments in the pair's order."""
    kinds = {Disk: "disk", Rectangle: "polygon", Polygon: "polygon", HalfPlane: "halfplane"}
    key = (kinds[type(a)], kinds[type(b)])
    direct: dict[tuple[str, str], Kernel] = {
        ("disk", "disk"): _disk_disk,
        ("disk", "halfplane"): _disk_plane,
        ("disk", "polygon"): _disk_polygon,
        ("polygon", "halfplane"): _polygon_plane,
        ("polygon", "polygon"): _polygon_polygon,
    }
    if key in direct:
        return direct[key]
    swapped = direct[key[::-1]]
    return lambda p, q, margin, tolerance: [(x, -n, g) for x, n, g in swapped(q, p, margin, tolerance)]


def _disk_disk(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    ra, rb = a.shape.radius, b.shape.radius  # type: ignore[union-attr]
    offset = a.centre - b.centre
    distance = float(np.hypot(*offset))
    if distance - ra - rb > margin:
        return []
    normal = offset / distance if distance > 0 else np.array([0.0, 1.0])  # concentric: any direction separates them
    witness_a, witness_b = a.centre - ra * normal, b.centre + rb * normal
    return [(0.5 * (witness_a + witness_b), normal, distance - ra - rb)]


def _disk_plane(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    normal, offset = b.line()
    radius = a.shape.radius  # type: ignore[union-attr]
    height = float(normal @ a.centre) - offset
    if height - radius > margin:
        return []
    return [(a.centre - 0.5 * (height + radius) * normal, normal, height - radius)]


def _disk_polygon(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    radius = a.shape.radius  # type: ignore[union-attr]
    vertices = b.vertices()
    normals, offsets = _faces(vertices)
    heights = normals @ a.centre - offsets
    face = int(np.argmax(heights))
    if heights[face] <= 0.0:  # the centre is inside: out through the nearest face
        normal, distance, on_b = normals[face], float(heights[face]), a.centre - heights[face] * normals[face]
    else:
        on_b = _closest_on_boundary(vertices, a.centre)
        offset = a.centre - on_b
        distance = float(np.hypot(*offset))
        normal = offset / distance
    if distance - radius > margin:
        return []
    on_a = a.centre - radius * normal
    return [(0.5 * (on_a + on_b), normal, distance - radius)]


def _closest_on_boundary(vertices: FloatArray, point: FloatArray) -> FloatArray:
    """The point of a polygon's boundary nearest ``point``."""
    edges = np.roll(vertices, -1, axis=0) - vertices
    t = np.clip(np.einsum("ij,ij->i", point - vertices, edges) / np.einsum("ij,ij->i", edges, edges), 0.0, 1.0)
    candidates = vertices + t[:, None] * edges
    return np.asarray(candidates[np.argmin(np.linalg.norm(candidates - point, axis=1))])


def _polygon_plane(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    """The extreme two vertices within the margin along the line (the corners of the support segment), each with its gap."""
    normal, offset = b.line()
    vertices = a.vertices()
    gaps = vertices @ normal - offset
    within = np.flatnonzero(gaps <= margin)
    if within.size == 0:
        return []
    along = vertices[within] @ np.array([-normal[1], normal[0]])
    ends = [int(within[np.argmin(along)]), int(within[np.argmax(along)])]
    if float(np.ptp(along)) <= tolerance:
        ends = ends[:1]
    return [(vertices[k] - 0.5 * gaps[k] * normal, normal, float(gaps[k])) for k in ends]


def _separation(reference: FloatArray, incident: FloatArray) -> tuple[float, int]:
    """The largest separation of ``incident``'s vertices from a face of ``reference``, and that face."""
    normals, offsets = _faces(reference)
    heights = (incident @ normals.T - offsets).min(axis=0)
    face = int(np.argmax(heights))
    return float(heights[face]), face


def _polygon_polygon(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    """Reference face: the face of either polygon that separates them most; the other's most opposed edge, clipped to
    it, gives the contact points (the two ends of a face-on-face contact)."""
    va, vb = a.vertices(), b.vertices()
    along_b, face_b = _separation(vb, va)
    along_a, face_a = _separation(va, vb)
    if max(along_a, along_b) > margin:
        return []
    # prefer b's face (normals then point from b into a) unless a's separates them clearly more
    if along_a > along_b + tolerance:
        return [(x, -n, g) for x, n, g in _clipped(va, face_a, vb, margin, tolerance)]
    return _clipped(vb, face_b, va, margin, tolerance)


def _clipped(reference: FloatArray, face: int, incident: FloatArray, margin: float, tolerance: float) -> Witnesses:
    """Points of the incident polygon's edge most opposed to the reference face, within the face's span and the margin;
    normals out of the reference polygon."""
    normals, offsets = _faces(reference)
    normal, start = normals[face], reference[face]
    end = reference[(face + 1) % len(reference)]
    incident_normals, _ = _faces(incident)
    edge = int(np.argmin(incident_normals @ normal))
    ends = np.array([incident[edge], incident[(edge + 1) % len(incident)]])
    tangent = (end - start) / float(np.hypot(*(end - start)))
    length = float(tangent @ (end - start))
    along = (ends - start) @ tangent
    points: Witnesses = []
    for bound, keep_below in ((0.0, False), (length, True)):  # clip the segment to 0 <= along <= length
        inside = along <= bound if keep_below else along >= bound
        if not inside.any():
            return []
        if not inside.all():
            t = (bound - along[0]) / (along[1] - along[0])
            cut = ends[0] + t * (ends[1] - ends[0])
            outside = int(np.flatnonzero(~inside)[0])
            ends[outside], along[outside] = cut, bound
    for point in ends:
        gap = float(normal @ (point - start))
        if gap <= margin and not any(float(np.hypot(*(point - p))) <= tolerance for p, _, _ in points):
            points.append((point - 0.5 * gap * normal, normal, gap))
    return points


def _distance(kernel: Kernel, a: _Placed, b: _Placed) -> float:
    """The signed distance between two placed shapes (for bodies with no contact): the kernel with no margin limit,
    and for two polygons apart, their nearest vertex-to-edge distance."""
    gaps = [g for _, _, g in kernel(a, b, math.inf, 0.0)]
    gap = min(gaps, default=math.inf)
    if gap > 0 and isinstance(a.shape, Polygon) and isinstance(b.shape, Polygon):
        va, vb = a.vertices(), b.vertices()
        gap = min(
            min(float(np.hypot(*(p - _closest_on_boundary(vb, p)))) for p in va),
            min(float(np.hypot(*(p - _closest_on_boundary(va, p)))) for p in vb),
        )
    return gap
