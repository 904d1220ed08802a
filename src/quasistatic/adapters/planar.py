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
from typing import Any, TypeAlias, cast

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import checked_array, checked_number
from ..tolerances import DUPLICATE_POINT, MAX_POLYGON_VERTICES, NORMAL_LENGTH, SMALLEST_LENGTH
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
    if number < SMALLEST_LENGTH:  # below it the scene's length scale cannot be formed: every tolerance would be off
        raise SceneError(path, value, f"must be at least {SMALLEST_LENGTH:g} (a size; choose other units)")
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
    neighbours (within :data:`DUPLICATE_POINT` of the size) or a reflex corner is rejected, and so is a polygon of more
    than :data:`MAX_POLYGON_VERTICES` vertices.
    """

    vertices: FloatArray

    def __init__(self, vertices: npt.ArrayLike, field: str = "polygon") -> None:
        points = checked_array(vertices, field, ndim=2)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3:
            raise SceneError(field, points.tolist(), "expected a list of at least 3 [x, y] vertices")
        if points.shape[0] > MAX_POLYGON_VERTICES:
            reason = f"at most {MAX_POLYGON_VERTICES:,} vertices (detection compares every vertex with every face)"
            raise SceneError(field, f"{points.shape[0]:,} vertices", reason)
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
        raise SceneError(field, points.tolist(), "degenerate polygon: its vertices enclose no area (on one line, or edges that cross)")
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
        for k, side in enumerate(("width", "height")):
            _size(values[k], f"{field}.{side}")
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
    """What planar detection keeps while the shapes move: owners, shapes, each polygon's local faces, and the pairs
    that may ever touch.

    ``free``: the names of free bodies; only pairs with one constrain a motion (two movers never do),
    and two colliders of one owner never touch.
    """

    def __init__(self, owners: Sequence[str], shapes: Sequence[PlanarShape], free: Collection[str]) -> None:
        self.owners = list(owners)
        self.shapes = list(shapes)
        self.outlines = [_Outline(s.vertices) if isinstance(s, Polygon) else None for s in shapes]
        self.radii = np.array([s.extent for s in shapes])
        self.sizes = np.array([s.extent if math.isfinite(s.extent) else 0.0 for s in shapes])
        self.reach = np.where(np.isfinite(self.radii), self.radii, 0.0)  # a halfplane's bounding circle: none
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
        self.planes = [isinstance(shapes[i], HalfPlane) or isinstance(shapes[j], HalfPlane) for i, j in pairs]
        # the broad phase's Python floats: each pair's colliders, each reach, and for a pair with a halfplane, the
        # halfplane's collider and the other's
        self.pairs, self.reach_list = pairs, self.reach.tolist()
        self.plane_of = {k: (i, j) if isinstance(shapes[i], HalfPlane) else (j, i) for k, (i, j) in enumerate(pairs) if self.planes[k]}
        self.tolerances = [DUPLICATE_POINT * min(self.sizes[i] or math.inf, self.sizes[j] or math.inf) for i, j in pairs]

    def detect(self, poses: FloatArray, margin: float) -> list[ContactPoint]:
        """Contact points of every pair within ``margin``; ``poses`` (n, 3): each collider's [x, y, angle]."""
        placed = self._placed(poses)
        found: list[ContactPoint] = []
        for k in self._near(poses.tolist(), placed, margin):
            i, j = int(self.first[k]), int(self.second[k])
            for point, normal, gap in self.kernels[k](placed[i], placed[j], margin, self.tolerances[k]):
                found.append(ContactPoint(self.owners[i], self.owners[j], point, normal, gap))
        return found

    def nearest(self, poses: FloatArray, owners: Collection[str]) -> dict[str, tuple[str, float]]:
        """For each name in ``owners``: the nearest other owner it may touch and the gap (``("", inf)`` if none)."""
        placed = self._placed(poses)
        best: dict[str, tuple[str, float]] = {name: ("", math.inf) for name in owners}
        for k, (i, j) in enumerate(zip(self.first.tolist(), self.second.tolist(), strict=True)):
            for mine, theirs in ((i, j), (j, i)):
                if self.owners[mine] in best:
                    gap = _distance(self.kernels[k], placed[i], placed[j])
                    if gap < best[self.owners[mine]][1]:
                        best[self.owners[mine]] = (self.owners[theirs], gap)
        return best

    def _placed(self, poses: FloatArray) -> list[_Placed]:
        return [_Placed(shape, outline, pose) for shape, outline, pose in zip(self.shapes, self.outlines, poses.tolist(), strict=True)]

    def _near(self, poses: list[list[float]], placed: list[_Placed], margin: float) -> list[int]:
        """Broad phase, the pairs whose bounding circles are within ``margin``; against a halfplane, the circle's signed
        distance. In Python floats: for a few pairs numpy's calls cost more than the arithmetic, and the test only
        chooses which pairs the exact kernels look at (each applies the margin itself)."""
        reach = self.reach_list
        near = []
        for k, (i, j) in enumerate(self.pairs):
            if self.planes[k]:
                plane, other = self.plane_of[k]
                normal, offset = placed[plane].line()
                nx, ny = normal.tolist()
                x, y = poses[other][0], poses[other][1]
                close = nx * x + ny * y - offset <= reach[other] + margin
            else:
                close = math.hypot(poses[i][0] - poses[j][0], poses[i][1] - poses[j][1]) <= reach[i] + reach[j] + margin
            if close:
                near.append(k)
        return near


class _Outline:
    """A convex polygon's faces in its own frame, kept while it moves: face k runs from vertex k to k+1."""

    def __init__(self, vertices: FloatArray) -> None:
        self.vertices = vertices
        self.edges = np.roll(vertices, -1, axis=0) - vertices
        self.squared = np.einsum("ij,ij->i", self.edges, self.edges)
        self.normals = np.column_stack([self.edges[:, 1], -self.edges[:, 0]]) / np.sqrt(self.squared)[:, None]  # outward
        self.offsets = np.einsum("ij,ij->i", self.normals, vertices)
        self._faces = list(zip(vertices.tolist(), self.edges.tolist(), self.squared.tolist(), strict=True))

    def closest(self, point: FloatArray) -> FloatArray:
        """The point of the boundary nearest ``point`` (both in this frame); the first face's of equally near ones.

        Face by face in Python floats: a polygon's few faces cost less so than in numpy calls (each step
        of a simulation asks this of every disk near a polygon).
        """
        px, py = float(point[0]), float(point[1])
        best, nearest = math.inf, (0.0, 0.0)
        for (vx, vy), (ex, ey), squared in self._faces:
            t = min(max(((px - vx) * ex + (py - vy) * ey) / squared, 0.0), 1.0)
            cx, cy = vx + t * ex, vy + t * ey
            distance = math.hypot(cx - px, cy - py)
            if distance < best:
                best, nearest = distance, (cx, cy)
        return np.array(nearest)


class _Placed:
    """One shape at one pose; its world vertices and faces are worked out when first asked for."""

    def __init__(self, shape: PlanarShape, outline: _Outline | None, pose: list[float]) -> None:
        self.shape, self.outline = shape, outline
        self.centre = np.array(pose[:2])
        self.c, self.s = math.cos(pose[2]), math.sin(pose[2])
        self._faces: tuple[FloatArray, FloatArray, FloatArray] | None = None
        self._vertices: FloatArray | None = None
        self._line: tuple[FloatArray, float] | None = None

    @property
    def rotation_t(self) -> FloatArray:
        """The transposed rotation: local row vectors times it are world row vectors."""
        return np.array([[self.c, self.s], [-self.s, self.c]])

    def to_local(self, point: FloatArray) -> FloatArray:
        dx, dy = float(point[0] - self.centre[0]), float(point[1] - self.centre[1])
        return np.array([self.c * dx + self.s * dy, -self.s * dx + self.c * dy])

    def to_world(self, vector: FloatArray) -> FloatArray:
        """A local direction in the world (no translation)."""
        return np.array([self.c * vector[0] - self.s * vector[1], self.s * vector[0] + self.c * vector[1]])

    def vertices(self) -> FloatArray:
        """World vertices (k, 2) of a polygon (all a halfplane's kernel needs of its faces)."""
        if self._vertices is None:
            self._vertices = cast(_Outline, self.outline).vertices @ self.rotation_t + self.centre
        return self._vertices

    def faces(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """World vertices (k, 2), outward face normals (k, 2) and face offsets (k,) of a polygon."""
        if self._faces is None:
            outline = cast(_Outline, self.outline)
            normals = outline.normals @ self.rotation_t
            self._faces = (self.vertices(), normals, outline.offsets + normals @ self.centre)
        return self._faces

    def line(self) -> tuple[FloatArray, float]:
        """A halfplane's world normal and offset (worked out once: the broad phase and the pair's kernel both ask)."""
        if self._line is None:
            plane = cast(HalfPlane, self.shape)
            normal = self.to_world(plane.normal)
            self._line = (normal, plane.offset + float(normal @ self.centre))
        return self._line


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


def _radius(placed: _Placed) -> float:
    return cast(Disk, placed.shape).radius


def _disk_disk(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    ra, rb = _radius(a), _radius(b)
    offset = a.centre - b.centre
    distance = math.hypot(offset[0], offset[1])
    if distance - ra - rb > margin:
        return []
    normal = offset / distance if distance > 0 else np.array([0.0, 1.0])  # concentric: any direction separates them
    witness_a, witness_b = a.centre - ra * normal, b.centre + rb * normal
    return [(0.5 * (witness_a + witness_b), normal, distance - ra - rb)]


def _disk_plane(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    normal, offset = b.line()
    radius = _radius(a)
    height = float(normal @ a.centre) - offset
    if height - radius > margin:
        return []
    return [(a.centre - 0.5 * (height + radius) * normal, normal, height - radius)]


def _disk_polygon(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    """In the polygon's frame: out through the nearest face when the centre is inside, else to the nearest boundary point."""
    radius, outline = _radius(a), cast(_Outline, b.outline)
    centre = b.to_local(a.centre)
    heights = outline.normals @ centre - outline.offsets
    face = int(np.argmax(heights))
    if heights[face] <= 0.0:
        normal, distance = outline.normals[face], float(heights[face])
        on_b = centre - distance * normal
    else:
        on_b = outline.closest(centre)
        distance = math.hypot(centre[0] - on_b[0], centre[1] - on_b[1])
        normal = (centre - on_b) / distance
    if distance - radius > margin:
        return []
    world_normal = b.to_world(normal)
    point = b.to_world(on_b + 0.5 * (distance - radius) * normal) + b.centre
    return [(point, world_normal, distance - radius)]


def _polygon_plane(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    """The extreme two vertices within the margin along the line (the corners of the support segment) and the deepest
    one (a polygon standing on a corner whose neighbours are within the margin touches at that corner), each with its
    gap; of vertices at one place along the line, the deepest."""
    normal, offset = b.line()
    vertices = a.vertices()
    gaps = vertices @ normal - offset
    within = np.flatnonzero(gaps <= margin)
    if within.size == 0:
        return []
    along = (vertices @ np.array([-normal[1], normal[0]])).tolist()
    height = gaps.tolist()
    inside = within.tolist()

    def deepest(near: float) -> int:  # the deepest vertex within the margin at ``near`` along the line (the first of equal ones)
        return min((k for k in inside if abs(along[k] - near) <= tolerance), key=lambda k: height[k])

    kept: list[int] = []
    lowest = min(inside, key=lambda k: height[k])
    for k in (lowest, deepest(min(along[k] for k in inside)), deepest(max(along[k] for k in inside))):
        if all(abs(along[k] - along[j]) > tolerance for j in kept):
            kept.append(k)
    return [(vertices[k] - 0.5 * gaps[k] * normal, normal, height[k]) for k in sorted(kept, key=lambda k: along[k])]


def _separation(reference: _Placed, incident: FloatArray) -> tuple[float, int]:
    """The largest separation of ``incident``'s vertices from a face of ``reference``, and that face."""
    _, normals, offsets = reference.faces()
    heights = (incident @ normals.T - offsets).min(axis=0)
    face = int(np.argmax(heights))
    return float(heights[face]), face


def _polygon_polygon(a: _Placed, b: _Placed, margin: float, tolerance: float) -> Witnesses:
    """Reference face: the face of either polygon that separates them most; the other's most opposed edge, clipped to
    it, gives the contact points (the two ends of a face-on-face contact)."""
    along_b, face_b = _separation(b, a.faces()[0])
    along_a, face_a = _separation(a, b.faces()[0])
    if max(along_a, along_b) > margin:
        return []
    # prefer b's face (normals then point from b into a) unless a's separates them clearly more
    if along_a > along_b + tolerance:
        points = [(x, -n, g) for x, n, g in _clipped(a, face_a, b, margin, tolerance)]
        face_normal = -a.faces()[1][face_a]
    else:
        points = _clipped(b, face_b, a, margin, tolerance)
        face_normal = b.faces()[1][face_b]
    if max(along_a, along_b) >= 0.0 and _corner_nearer(a, b, points, tolerance):
        # the incident edge lies beyond the face's ends, wholly or in part: the nearest points are corner to corner
        return _corner(a, b, margin, tolerance, face_normal)
    return points


def _corner_nearer(a: _Placed, b: _Placed, points: Witnesses, tolerance: float) -> bool:
    """Whether two separate polygons are nearer each other than every clipped point's gap says."""
    return not points or _nearest_points(a, b)[2] < min(g for _, _, g in points) - tolerance


def _corner(a: _Placed, b: _Placed, margin: float, tolerance: float, face_normal: FloatArray) -> Witnesses:
    """Two separate polygons whose nearest points are a corner of one and a corner or edge of the other: one point
    midway between them, the normal along their line (from b into a), the gap their distance. Corners touching
    (closer than ``tolerance``) have no such line: the separating face's normal stands in."""
    on_a, on_b, distance = _nearest_points(a, b)
    offset = on_a - on_b
    if distance > margin:
        return []
    normal = offset / distance if distance > tolerance else face_normal
    return [(0.5 * (on_a + on_b), normal, distance)]


def _nearest_points(a: _Placed, b: _Placed) -> tuple[FloatArray, FloatArray, float]:
    """The nearest points (on a, on b) of two separate polygons, a vertex of one and the other's nearest boundary
    point, and their distance: every vertex against every edge, both ways."""
    best: tuple[FloatArray, FloatArray, float] = (a.centre, b.centre, math.inf)
    for mine, theirs, swap in ((a, b, False), (b, a, True)):
        vertices, corners = mine.faces()[0], theirs.faces()[0]
        edges = np.roll(corners, -1, axis=0) - corners
        t = np.einsum("nmk,mk->nm", vertices[:, None, :] - corners[None], edges) / np.einsum("mk,mk->m", edges, edges)
        nearest = corners[None] + np.clip(t, 0.0, 1.0)[..., None] * edges[None]
        distances = np.hypot(*(vertices[:, None, :] - nearest).transpose(2, 0, 1))
        i, j = np.unravel_index(int(np.argmin(distances)), distances.shape)
        if distances[i, j] < best[2]:
            pair = (nearest[i, j], vertices[i]) if swap else (vertices[i], nearest[i, j])
            best = (pair[0], pair[1], float(distances[i, j]))
    return best


def _clipped(reference: _Placed, face: int, incident: _Placed, margin: float, tolerance: float) -> Witnesses:
    """Points of the incident polygon's edge most opposed to the reference face, within the face's span and the margin;
    normals out of the reference polygon."""
    vertices, normals, _ = reference.faces()
    normal, start = normals[face], vertices[face]
    end = vertices[(face + 1) % len(vertices)]
    corners, incident_normals, _ = incident.faces()
    edge = int(np.argmin(incident_normals @ normal))
    ends = np.array([corners[edge], corners[(edge + 1) % len(corners)]])
    length = math.hypot(*(end - start))
    along = (ends - start) @ ((end - start) / length)
    for bound, keep_below in ((0.0, False), (length, True)):  # clip the segment to 0 <= along <= length
        inside = along <= bound if keep_below else along >= bound
        if not inside.any():
            return []
        if not inside.all():
            t = (bound - along[0]) / (along[1] - along[0])
            outside = int(np.flatnonzero(~inside)[0])
            ends[outside], along[outside] = ends[0] + t * (ends[1] - ends[0]), bound
    points: Witnesses = []
    for point in ends:
        gap = float(normal @ (point - start))
        if gap <= margin and not any(math.hypot(*(point - p)) <= tolerance for p, _, _ in points):
            points.append((point - 0.5 * gap * normal, normal, gap))
    return points


def _distance(kernel: Kernel, a: _Placed, b: _Placed) -> float:
    """The signed distance between two placed shapes (for bodies with no contact): the kernel with no margin limit,
    and for two polygons apart, their nearest vertex-to-edge distance."""
    gap = min((g for _, _, g in kernel(a, b, math.inf, 0.0)), default=math.inf)
    if gap > 0 and a.outline is not None and b.outline is not None:
        gap = min(_nearest_vertex(a, b), _nearest_vertex(b, a))
    return gap


def _nearest_vertex(a: _Placed, b: _Placed) -> float:
    """The least distance from a vertex of ``a`` to ``b``'s boundary."""
    outline = cast(_Outline, b.outline)
    distances = []
    for vertex in a.faces()[0]:
        local = b.to_local(vertex)
        nearest = outline.closest(local)
        distances.append(math.hypot(local[0] - nearest[0], local[1] - nearest[1]))
    return min(distances)
