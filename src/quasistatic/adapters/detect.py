"""Contact detection with coal: the contact points of placed shapes, as exact contact polygons.

Three stages, each a function below:

1. broad phase (:func:`candidate_pairs`): a sweep over axis-aligned bounding
   boxes grown by the margin, so the work grows with the pairs that are near,
   not with all pairs;
2. narrow phase: ``coal.collide`` with the margin as security margin says
   whether a pair is within reach, and roughly along which normal (a polytope
   against a halfspace skips it: see 3);
3. manifold: a polytope (box, convex hull, mesh) against a halfspace gives the
   corners of its vertices within the margin (:mod:`.polygon`: exact, a few
   array operations). Any other pair is moved apart along coal's normal
   (coal's GJK is exact for separate shapes where EPA, for overlapping ones,
   is not), coal's contact
   patch gives the contact polygon, and its vertices are moved back: a box flat
   on a table gives its 4 corners, a box on an edge 2 points, a sphere 1. Coal
   puts all of a patch's points at the pair's deepest gap; each vertex's own
   gap is measured along the normal against the shapes themselves.

Coal's normal can be zero or NaN for deep overlaps (a capsule inside another on
the same axis); detection then takes the direction of least overlap among the
shapes' axes and the line between their centres, and never passes NaN on.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import SceneError, SolverError
from ..jit import HAVE_NUMBA, njit
from ..tolerances import CONTACT_SEPARATION, CURVED_PATCH_POINTS, DUPLICATE_POINT, GRAZING_FACE, NORMAL_LENGTH, PATCH_THICKNESS
from ._coal import import_coal
from .polygon import contact_corners, halfspace_polygon, plane_basis, polytope_faces, polytope_vertices
from .shapes import Box, Capsule, Convex, Cylinder, FloatArray, Halfspace, IntArray, Mesh, Pose, Shape, Sphere, shape_from_coal

BoolArray = npt.NDArray[np.bool_]

__all__ = ["Collider", "ContactPoint", "Layout", "candidate_pairs", "detect", "nearest_gaps"]

_ALL_PAIRS = 48  # up to this many colliders, testing every pair at once is cheaper than sorting them first


@dataclass(frozen=True, init=False)
class Collider:
    """One collision shape placed in the world.

    Attributes
    ----------
    owner : str
        The body, mover or robot link it belongs to; colliders of one owner never touch each other.
    shape : Shape
        Its shape. A coal geometry (a Pinocchio ``GeometryObject.geometry``) is converted
        with :func:`~quasistatic.adapters.shapes.shape_from_coal`; convert it once yourself
        to reuse the coal geometry built from it across poses.
    pose : Pose
        World pose of the shape's frame.
    """

    owner: str
    shape: Shape
    pose: Pose

    def __init__(self, owner: str, shape: Shape | object, pose: Pose | None = None, field: str = "colliders") -> None:
        if not isinstance(owner, str) or not owner:
            raise SceneError(f"{field}.owner", owner, "expected a non-empty name")
        if pose is not None and not isinstance(pose, Pose):
            raise SceneError(f"{field}.pose", pose, "expected a Pose")
        placed = shape if isinstance(shape, Shape) else shape_from_coal(shape, f"{field}.shape")
        object.__setattr__(self, "owner", owner)
        object.__setattr__(self, "shape", placed)
        object.__setattr__(self, "pose", Pose() if pose is None else pose)


@dataclass(frozen=True)
class ContactPoint:
    """One point of contact between two colliders' owners.

    Attributes
    ----------
    first, second : str
        The owners; ``first`` is the one whose collider comes first in the input.
    point : array (3,)
        World point on the contact surface: the midpoint of the two shapes' witness points [length].
    normal : array (3,)
        Unit normal, from ``second`` into ``first``.
    gap : float
        Signed distance along ``normal`` [length]: > 0 apart (within the margin), < 0 overlapping.
    """

    first: str
    second: str
    point: FloatArray
    normal: FloatArray
    gap: float

    def flipped(self) -> ContactPoint:
        """The same contact seen from ``second``: owners swapped, normal reversed."""
        return ContactPoint(self.second, self.first, self.point, -self.normal, self.gap)


# --------------------------------------------------------------------------- broad phase


def candidate_pairs(colliders: Sequence[Collider], margin: float = 0.0) -> list[tuple[int, int]]:
    """Pairs ``(i, j)``, ``i < j``, of colliders whose bounding boxes come within ``margin``.

    A sweep along the axis where the boxes are most spread out: each box is
    compared only with those that overlap it along that axis, so ``n`` objects
    spread over a table cost about ``n log n``, not ``n^2``; a few dozen are
    tested all at once instead (one array operation beats the sort). A halfspace
    is unbounded and pairs with every collider.

    Parameters
    ----------
    colliders : sequence of Collider
    margin : float
        Distance within which two shapes count as near [length], >= 0.

    Returns
    -------
    list of (int, int)
        Sorted indices into ``colliders``.
    """
    margin = _margin(margin)
    if len(colliders) < 2:
        return []
    layout = Layout([c.owner for c in colliders], [c.shape for c in colliders])
    i, j = _near_pairs(*layout.bounds(*_placements(colliders), margin))
    return list(zip(i.tolist(), j.tolist(), strict=True))


def _near_pairs(low: FloatArray, high: FloatArray) -> tuple[IntArray, IntArray]:
    """Indices ``(i, j)``, ``i < j``, sorted, of the boxes ``[low, high]`` (n, 3) that meet: all at once or by a sweep."""
    if len(low) <= _ALL_PAIRS:
        starts_before_end = low.T[:, :, None] <= high.T[:, None, :]  # (axis, i, j): one contiguous plane per axis
        meet = starts_before_end[0] & starts_before_end[1] & starts_before_end[2]
        meet &= meet.T
        i, j = np.nonzero(meet)  # row by row: already in order
        upper = i < j
        return i[upper].astype(np.int64), j[upper].astype(np.int64)
    axis = _sweep_axis(low, high)
    order = np.argsort(low[:, axis], kind="stable")
    # Rank r meets the ranks after it that start before it ends along the axis: r+1 .. stops[r]-1.
    stops = np.searchsorted(low[order, axis], high[order, axis], side="right")
    counts = np.maximum(stops - np.arange(len(order)) - 1, 0)
    first = np.repeat(np.arange(len(order)), counts)
    second = first + 1 + np.arange(first.size) - np.repeat(np.cumsum(counts) - counts, counts)
    i, j = order[first], order[second]
    near = np.all((low[j] <= high[i]) & (low[i] <= high[j]), axis=1)
    lower, upper = np.minimum(i[near], j[near]), np.maximum(i[near], j[near])
    kept = np.lexsort((upper, lower))
    return lower[kept], upper[kept]


@njit
def _every_near_pair(
    positions: FloatArray, rotations: FloatArray, centres: FloatArray, halves: FloatArray, unbounded: BoolArray, grow: float
) -> tuple[IntArray, IntArray]:
    """:meth:`Layout.bounds` and :func:`_near_pairs` (every pair at once) as one compiled loop: ``(i, j)``, ``i < j``, sorted."""
    n = positions.shape[0]
    low, high = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        for a in range(3):
            centre, half = 0.0, 0.0
            for b in range(3):
                centre += rotations[k, a, b] * centres[k, b]
                half += abs(rotations[k, a, b]) * halves[k, b]
            centre += positions[k, a]
            half += grow
            low[k, a], high[k, a] = (-np.inf, np.inf) if unbounded[k] else (centre - half, centre + half)
    first, second = np.empty(n * (n - 1) // 2, np.int64), np.empty(n * (n - 1) // 2, np.int64)
    count = 0
    for i in range(n):
        for j in range(i + 1, n):
            if (
                low[i, 0] <= high[j, 0]
                and low[j, 0] <= high[i, 0]
                and low[i, 1] <= high[j, 1]
                and low[j, 1] <= high[i, 1]
                and low[i, 2] <= high[j, 2]
                and low[j, 2] <= high[i, 2]
            ):
                first[count], second[count] = i, j
                count += 1
    return first[:count], second[:count]


def _sweep_axis(low: FloatArray, high: FloatArray) -> int:
    """The axis along which the bounded boxes' centres spread most (unbounded ones overlap everything anyway)."""
    bounded = np.all(np.isfinite(low) & np.isfinite(high), axis=1)
    if np.count_nonzero(bounded) < 2:
        return 0
    centres = (low[bounded] + high[bounded]) / 2.0
    return int(np.argmax(np.var(centres, axis=0)))


def _local_box(shape: Shape) -> tuple[FloatArray, FloatArray]:
    """Centre and half extents of a shape's box in its own frame [length]; zero for a halfspace (unbounded: the callers handle it)."""
    if isinstance(shape, Halfspace):
        return np.zeros(3), np.zeros(3)
    if isinstance(shape, Mesh):
        shape = shape.convex
    if isinstance(shape, Box):
        return np.zeros(3), shape.size / 2.0
    if isinstance(shape, Sphere):
        return np.zeros(3), np.full(3, shape.radius)
    if isinstance(shape, Cylinder):
        return np.zeros(3), np.array([shape.radius, shape.radius, shape.length / 2.0])
    if isinstance(shape, Capsule):
        return np.zeros(3), np.array([shape.radius, shape.radius, shape.length / 2.0 + shape.radius])
    assert isinstance(shape, Convex)
    low, high = shape.vertices.min(axis=0), shape.vertices.max(axis=0)
    return (low + high) / 2.0, (high - low) / 2.0


# --------------------------------------------------------------------------- detection


def detect(
    colliders: Sequence[Collider],
    pairs: Callable[[str, str], bool] | None = None,
    margin: float = 0.0,
) -> list[ContactPoint]:
    """Every contact point between the colliders, within ``margin``.

    Parameters
    ----------
    colliders : sequence of Collider
        The placed shapes; a pair's ``first`` owner is the one listed first.
    pairs : callable (owner, owner) -> bool, optional
        Whether two owners may touch (e.g. not two links of one robot); called with
        the owners in input order. All pairs of different owners when omitted.
    margin : float
        Distance within which separate shapes are in contact [length], >= 0: points
        with ``gap <= margin`` are reported.

    Returns
    -------
    list of ContactPoint
        Sorted by owners, then by point: the same scene gives the same list.
        Each pair contributes the vertices of its contact polygon, without duplicates.

    Raises
    ------
    SceneError
        On a negative or non-finite margin.
    BackendUnavailableError
        When coal is not installed.
    SolverError
        When coal returns no finite normal even for shapes moved apart.

    See Also
    --------
    Layout : the same detection for colliders that keep their shapes while they move (a simulation's steps).
    """
    layout = Layout([c.owner for c in colliders], [c.shape for c in colliders], pairs)
    positions, rotations = _placements(colliders)
    return layout.detect(positions, rotations, margin, colliders)


class Layout:
    """What contact detection keeps while the colliders move: their owners, shapes, coal geometries and bounding boxes.

    :func:`detect` builds one per call. A simulation whose parts keep their shapes builds it once and
    calls :meth:`detect` with each step's placements: nothing is converted or checked again, and whether two
    colliders may touch is asked once per pair that comes near, not at every step.

    Parameters
    ----------
    owners : sequence of str
        Each collider's owner (a body, mover or robot link); colliders of one owner never touch.
    shapes : sequence of Shape
        Each collider's shape, in its own frame.
    pairs : callable (owner, owner) -> bool, optional
        Whether two owners may touch, as for :func:`detect`.
    free : collection of str, optional
        Instead of ``pairs``: the owners that are free bodies; only pairs with one of them may touch.
        Decided for every pair at once, where ``pairs`` is asked once per pair that comes near.
    """

    def __init__(
        self,
        owners: Sequence[str],
        shapes: Sequence[Shape],
        pairs: Callable[[str, str], bool] | None = None,
        *,
        free: Collection[str] | None = None,
    ) -> None:
        if pairs is not None and free is not None:
            raise SceneError("free", sorted(free), "give either pairs or free, not both")
        self.owners, self.shapes, self._pairs = tuple(owners), tuple(shapes), pairs
        self._free = None if free is None else frozenset(free)
        boxes = np.array([shape.derived("box", _local_box) for shape in self.shapes], dtype=float).reshape(-1, 2, 3)
        self._box_centres, self._box_halves = boxes[:, 0], boxes[:, 1]
        self._unbounded = np.array([isinstance(shape, Halfspace) for shape in self.shapes], dtype=bool)
        self._asked: dict[tuple[int, int], bool] = {}  # (i, j) -> may they touch: the owners never change
        size = len(self.owners) if len(self.owners) <= _ALL_PAIRS else 0
        self._allowed = np.full((size, size), -1, dtype=np.int8)  # the same, as a matrix for small layouts: -1 not asked yet
        if size and self._free is not None:
            self._allowed = self._free_pairs().astype(np.int8)

    def _free_pairs(self) -> BoolArray:
        """Which pairs may touch when only pairs with a free body do: different owners, not both unbounded, one free."""
        free_owners = self._free or frozenset()
        index = {owner: k for k, owner in enumerate(dict.fromkeys(self.owners))}
        owner = np.array([index[o] for o in self.owners])
        free = np.array([o in free_owners for o in self.owners], dtype=bool)
        unbounded = self._unbounded
        different = owner[:, None] != owner[None, :]
        either_free = np.logical_or(free[:, None], free[None, :])
        both_unbounded = np.logical_and(unbounded[:, None], unbounded[None, :])
        allowed: BoolArray = different & either_free & ~both_unbounded
        return allowed

    def __len__(self) -> int:
        return len(self.owners)

    def bounds(self, positions: FloatArray, rotations: FloatArray, margin: float) -> tuple[FloatArray, FloatArray]:
        """World axis-aligned boxes (lower, upper corners, each (n, 3)) grown by ``margin / 2``; a halfspace's is everything."""
        centres = np.einsum("nij,nj->ni", rotations, self._box_centres) + positions
        halves = np.einsum("nij,nj->ni", np.abs(rotations), self._box_halves) + margin / 2.0
        low, high = centres - halves, centres + halves
        low[self._unbounded], high[self._unbounded] = -math.inf, math.inf
        return low, high

    def pairs(self, positions: FloatArray, rotations: FloatArray, margin: float) -> list[tuple[int, int]]:
        """The pairs ``(i, j)``, ``i < j``, sorted, that are near and may touch: what the narrow phase gets."""
        if len(self) > _ALL_PAIRS:  # a matrix of every pair would be too large: sweep, and ask per pair
            i, j = _near_pairs(*self.bounds(positions, rotations, margin))
            return [(a, b) for a, b in zip(i.tolist(), j.tolist(), strict=True) if self._may_touch(a, b)]
        if HAVE_NUMBA:  # one compiled loop over every pair: the dozen numpy calls below cost ~40 us on a hand
            placed = np.ascontiguousarray(positions, dtype=float), np.ascontiguousarray(rotations, dtype=float)
            i, j = _every_near_pair(*placed, self._box_centres, self._box_halves, self._unbounded, margin / 2.0)
        else:
            i, j = _near_pairs(*self.bounds(positions, rotations, margin))
        allowed = self._allowed[i, j]
        for k in np.flatnonzero(allowed < 0):  # pairs never near before: ask once
            allowed[k] = self._allowed[i[k], j[k]] = self._may_touch(int(i[k]), int(j[k]))
        keep = allowed > 0
        return list(zip(i[keep].tolist(), j[keep].tolist(), strict=True))

    def detect(
        self, positions: FloatArray, rotations: FloatArray, margin: float, colliders: Sequence[Collider] | None = None
    ) -> list[ContactPoint]:
        """Every contact point within ``margin``, the colliders at ``positions`` (n, 3) and ``rotations`` (n, 3, 3).

        The placements are trusted (forward kinematics, validated poses): they are not checked again.
        ``colliders``, when the caller has them, are the same shapes already placed; else they are made
        for the colliders near something. See :func:`detect` for the result and errors.
        """
        query = _Query(import_coal(), _margin(margin), positions, rotations)
        found: list[ContactPoint] = []
        placed: dict[int, Collider] = {} if colliders is None else dict(enumerate(colliders))
        for i, j in self.pairs(positions, rotations, query.margin):
            for k in (i, j):
                if k not in placed:
                    placed[k] = _placed(self.owners[k], self.shapes[k], Pose.from_trusted_arrays(positions[k], rotations[k]))
            found += _pair_contacts(query, placed[i], placed[j], i, j)
        return sorted(found, key=lambda c: (c.first, c.second, c.point.tolist()))  # plain floats compare faster than numpy's

    def _may_touch(self, i: int, j: int) -> bool:
        """Colliders of different owners, not both unbounded, that the caller lets touch: asked once per pair."""
        known = self._asked.get((i, j))
        if known is None:
            a, b = self.owners[i], self.owners[j]
            unbounded = self._unbounded[i] and self._unbounded[j]  # environment against environment
            allowed = a in self._free or b in self._free if self._free is not None else self._pairs is None or self._pairs(a, b)
            known = self._asked[i, j] = a != b and not unbounded and allowed
        return known


def _placements(colliders: Sequence[Collider]) -> tuple[FloatArray, FloatArray]:
    """The colliders' positions (n, 3) and rotations (n, 3, 3)."""
    positions = np.array([c.pose.position for c in colliders], dtype=float).reshape(-1, 3)
    rotations = np.array([c.pose.rotation for c in colliders], dtype=float).reshape(-1, 3, 3)
    return positions, rotations


def _placed(owner: str, shape: Shape, pose: Pose) -> Collider:
    """A Collider from parts this module already holds checked: no validation again."""
    collider = object.__new__(Collider)
    object.__setattr__(collider, "owner", owner)
    object.__setattr__(collider, "shape", shape)
    object.__setattr__(collider, "pose", pose)
    return collider


class _Query:
    """coal's objects for one detection: the request and result, reused by every pair, and each collider's transform.

    Building them costs more than coal's own query on two primitives, so they are made once per
    detection, not per pair.
    """

    def __init__(self, coal: Any, margin: float, positions: FloatArray, rotations: FloatArray) -> None:
        self.coal, self.margin, self._positions, self._rotations = coal, margin, positions, rotations
        self.request = _request(coal, margin)
        self.result = coal.CollisionResult()
        self._placed: dict[int, Any] = {}
        self._moved_request: Any = None

    @property
    def moved_request(self) -> Any:
        """A request for pairs moved apart (its margin is set per pair); made when a pair first needs it.

        GJK stops on the duality gap: its default test stops at once when its first direction, the one the pair
        was moved along (EPA's, off by ~1e-6 rad), already meets faces that are parallel, and returns that direction.
        """
        if self._moved_request is None:
            self._moved_request = _request(self.coal, self.margin)
            self._moved_request.gjk_convergence_criterion = self.coal.GJKConvergenceCriterion.DualityGap
        return self._moved_request

    def transform(self, index: int) -> Any:
        if index not in self._placed:
            self._placed[index] = self.coal.Transform3s(self._rotations[index], self._positions[index])
        return self._placed[index]


def nearest_gaps(
    colliders: Sequence[Collider], owners: Sequence[str], pairs: Callable[[str, str], bool] | None = None
) -> dict[str, tuple[str, float]]:
    """For each of ``owners``, the nearest other owner it may touch and the distance to it [length].

    What a user needs when a body touches nothing: how far it is from the surface it was meant
    to rest on. ``("", inf)`` when no other collider may touch it. One distance query per
    collider pair of the owner: call it for the few owners with no contact, not for all.
    """
    coal = import_coal()
    result: dict[str, tuple[str, float]] = {}
    for owner in owners:
        best = ("", math.inf)
        for mine in (c for c in colliders if c.owner == owner):
            for other in colliders:
                if other.owner == owner or (pairs is not None and not pairs(owner, other.owner)):
                    continue
                gap = _distance(coal, mine, other)
                if gap < best[1]:
                    best = (other.owner, gap)
        result[owner] = best
    return result


def _distance(coal: Any, a: Collider, b: Collider) -> float:
    """Signed distance between two placed shapes (negative when they overlap)."""
    request, outcome = coal.DistanceRequest(), coal.DistanceResult()
    ga, gb = _geometry(coal, a.shape), _geometry(coal, b.shape)
    return float(coal.distance(ga, _transform(coal, a.pose), gb, _transform(coal, b.pose), request, outcome))


def _margin(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SceneError("margin", value, "expected a number")
    if not math.isfinite(float(value)) or value < 0:
        raise SceneError("margin", value, "must be a finite distance >= 0")
    return float(value)


def _pair_contacts(query: _Query, a: Collider, b: Collider, i: int, j: int) -> list[ContactPoint]:
    """The contact polygon of colliders ``a`` (index ``i``) and ``b`` (``j``) within the margin, as ContactPoints from ``b`` into ``a``."""
    coal, margin = query.coal, query.margin
    size = min(a.shape.extent, b.shape.extent)
    polygon = _halfspace_polygon(query, a, b, size)
    if polygon is not None:  # exact from the vertices: coal's answer would add nothing
        return polygon
    ga, gb = _geometry(coal, a.shape), _geometry(coal, b.shape)
    tb = query.transform(j)
    rough = _collide(query, ga, query.transform(i), gb, tb)
    if rough is None:
        return []
    direction, gap = rough
    if direction is not None and gap < -max(margin, CONTACT_SEPARATION * size):
        direction, gap = _checked_overlap(a, b, direction, gap, DUPLICATE_POINT * size)
    if direction is not None and _exact_normal(a, b, gap):
        return _one_point(query, a, b, direction, size)
    result = query.result
    if direction is not None and (isinstance(a.shape, Halfspace) or isinstance(b.shape, Halfspace)):
        # coal's test against a halfspace is analytic, not EPA: its normal is the halfspace's own, exact even
        # for overlapping shapes, so its first answer gives the patch without moving the pair apart.
        shift, moved = 0.0, query.transform(i)
    else:
        if direction is None:
            direction, gap = _least_overlap(a, b)
        # Move a away from b until they are apart by CONTACT_SEPARATION * size: GJK then gives the exact normal.
        shift = max(0.0, CONTACT_SEPARATION * size - gap)
        moved = _transform(coal, a.pose, direction * shift)
        request = query.moved_request
        request.security_margin = margin + 2.0 * shift
        result.clear()
        coal.collide(ga, moved, gb, tb, request, result)
        to_b = _unit(result.getContact(0).normal) if result.isCollision() else None
        if to_b is None:
            raise SolverError("coal", f"no finite contact normal between {a.owner!r} and {b.owner!r}, even moved apart")
        # Again, moved along GJK's exact normal where EPA's was off (1e-6 to 1e-4 rad): a's patch and witness points,
        # moved back, would sit beside b's by that error times the shift (3e-8 of a 0.25 box), and the line between
        # them miss the corner its gap is measured at, by more than a steep face forgives (beside by less, the gap
        # moves by less than GRAZING_FACE * DUPLICATE_POINT of the size).
        beside = float(np.linalg.norm(to_b + direction)) * shift
        if beside > GRAZING_FACE**2 * DUPLICATE_POINT * size:
            direction = -to_b
            moved = _transform(coal, a.pose, direction * shift)
            result.clear()
            coal.collide(ga, moved, gb, tb, request, result)
            if not result.isCollision():
                raise SolverError("coal", f"{a.owner!r} and {b.owner!r} moved apart along their normal no longer touch")
    thickness = max(margin - gap, 0.0) + PATCH_THICKNESS * size
    patch_request = coal.ContactPatchRequest(1, CURVED_PATCH_POINTS, thickness)
    patches = coal.ContactPatchResult(patch_request)
    coal.computeContactPatch(ga, moved, gb, tb, result, patch_request, patches)
    nearest = result.getContact(0)
    witness = np.array([nearest.getNearestPoint1(), nearest.getNearestPoint2()], dtype=float).reshape(2, 3)
    return _patch_points(a, b, patches.getContactPatch(0), witness, direction * shift, margin, size)


def _halfspace_polygon(query: _Query, a: Collider, b: Collider, size: float) -> list[ContactPoint] | None:
    """A polytope against a halfspace: the corners of its vertices within the margin (:mod:`.polygon`); None for other pairs."""
    plane, solid, sign = (b, a, 1.0) if isinstance(b.shape, Halfspace) else (a, b, -1.0)
    if not isinstance(plane.shape, Halfspace):
        return None
    local, faces = polytope_vertices(solid.shape), polytope_faces(solid.shape)
    if local is None or faces is None:
        return None
    normal = plane.pose.rotation @ plane.shape.normal
    offset = plane.shape.offset + float(normal @ plane.pose.position)
    reach, tolerance = query.margin + PATCH_THICKNESS * size, DUPLICATE_POINT * size
    points, gaps = halfspace_polygon(local, faces, solid.pose.rotation, solid.pose.position, normal, offset, reach, tolerance)
    into_first = sign * normal  # from the second collider into the first
    into_first.setflags(write=False)
    points.setflags(write=False)
    return [ContactPoint(a.owner, b.owner, points[k], into_first, float(gaps[k])) for k in range(len(gaps))]


def _exact_normal(a: Collider, b: Collider, gap: float) -> bool:
    """Whether coal's first answer is already exact: a sphere whose centre is outside the other shape.

    coal treats a sphere as its centre grown by the radius, so while the centre is outside the
    other shape (overlap below the radius) its normal and witness points are those of separate
    shapes, exact to round-off, and the contact is one point: no move apart, no patch needed.
    """
    radii = [c.shape.radius for c in (a, b) if isinstance(c.shape, Sphere)]
    return bool(radii) and gap > -0.5 * max(radii)


def _one_point(query: _Query, a: Collider, b: Collider, direction: FloatArray, size: float) -> list[ContactPoint]:
    """The single contact point of a pair with a sphere, from coal's witness points (in plain floats: three numbers)."""
    contact = query.result.getContact(0)
    (ax, ay, az), (bx, by, bz) = contact.getNearestPoint1().tolist(), contact.getNearestPoint2().tolist()
    dx, dy, dz = direction.tolist()
    gap = (ax - bx) * dx + (ay - by) * dy + (az - bz) * dz
    if not gap <= query.margin + PATCH_THICKNESS * size:
        return []
    direction.setflags(write=False)
    return [ContactPoint(a.owner, b.owner, _frozen(np.array([(ax + bx) / 2.0, (ay + by) / 2.0, (az + bz) / 2.0])), direction, gap)]


def _patch_points(
    a: Collider, b: Collider, patch: Any, witness: FloatArray, shift: FloatArray, margin: float, size: float
) -> list[ContactPoint]:
    """The patch's vertices within the margin, and the points inside it where the shapes come nearer than at its
    corners; ``a``'s points moved back by ``shift``.

    ``witness`` (2, 3): coal's nearest points of the pair (on a, on b). The patch is a polygon of the two shapes'
    surfaces within its thickness; where they are not flat against each other (a box standing on a corner, a plate
    tilted on a block, a hull resting on a face with others within the margin), the deepest point and a polytope's
    vertices on its faces turned to the other shape can lie inside that polygon, lower than its corners around
    them: they are added (each measured like the corners), the witness where it is deeper than every other point.
    """
    to_b = _unit(patch.getNormal())  # coal's normal points from a to b
    if to_b is None:
        raise SolverError("coal", f"contact patch without a finite normal between {a.owner!r} and {b.owner!r}")
    count = patch.size()
    on_a = np.array([patch.getPointShape1(k) for k in range(count)] + [witness[0]], dtype=float).reshape(-1, 3) - shift
    on_b = np.array([patch.getPointShape2(k) for k in range(count)] + [witness[1]], dtype=float).reshape(-1, 3)
    depth = float((on_b[count] - on_a[count]) @ -to_b) + margin + PATCH_THICKNESS * size  # below the deepest gap
    vertices = np.vstack([_facing_vertices(a, to_b, on_a[count], depth), _facing_vertices(b, -to_b, on_b[count], depth)])
    on_a, on_b = np.vstack([on_a, vertices]), np.vstack([on_b, vertices])
    # coal puts every patch point on one plane, at the pair's deepest gap: find each one's own
    # surfaces along the normal, so a face tilted within the margin gets its true gaps.
    slack = DUPLICATE_POINT * size
    mid = (on_a + on_b) / 2.0
    enter, _, in_a = _spans(a, mid, -to_b, slack)
    _, leave, in_b = _spans(b, mid, -to_b, slack)
    both = in_a & in_b
    on_a[both], on_b[both] = mid[both] - enter[both, None] * to_b, mid[both] - leave[both, None] * to_b
    gaps = (on_b - on_a) @ to_b
    within = (gaps <= margin + PATCH_THICKNESS * size) & np.isfinite(on_a + on_b).all(axis=1)
    within[count:] &= both[count:]  # the points added must lie on both shapes
    points = (on_a + on_b) / 2.0
    points.setflags(write=False)  # each contact's point is a (read-only) row of it
    normal = -to_b
    normal.setflags(write=False)
    rows = np.flatnonzero(within[:count])[_polygon_vertices(points[:count][within[:count]], slack)].tolist()
    added = (np.flatnonzero(within[count + 1 :]) + count + 1).tolist()
    if added:
        rows = _lowest_corners(points, gaps, rows + added, normal, slack)
    lowest = min((float(gaps[k]) for k in rows), default=math.inf)
    if within[count] and both[count] and gaps[count] < lowest - slack:
        rows.append(count)
    return [ContactPoint(a.owner, b.owner, points[k], normal, float(gaps[k])) for k in rows]


def _facing_vertices(collider: Collider, toward: FloatArray, anchor: FloatArray, depth: float) -> FloatArray:
    """A polytope's world vertices (k, 3) on its faces turned ``toward`` (unit, world), at most ``depth`` behind
    ``anchor`` along it; none for other shapes."""
    local, faces = polytope_vertices(collider.shape), polytope_faces(collider.shape)
    if local is None or faces is None:
        return np.empty((0, 3))
    rotation, position = collider.pose.rotation, collider.pose.position
    turned = rotation.T @ toward
    face_normals, members = faces
    facing = np.zeros(len(local), dtype=bool)
    facing[members[face_normals @ turned > 0.0]] = True
    near = facing & ((local - rotation.T @ (anchor - position)) @ turned >= -depth)
    placed: FloatArray = local[near] @ rotation.T + position
    return placed


def _lowest_corners(points: FloatArray, gaps: FloatArray, rows: list[int], normal: FloatArray, slack: float) -> list[int]:
    """Of ``rows`` of ``points`` (on one contact plane of ``normal``), those that carry a constraint: the corners of
    their hull seen along the normal and the lower points inside it (:func:`.polygon.contact_corners`)."""
    u, v = (np.array(axis) for axis in plane_basis(normal.tolist()))
    chosen = points[rows]
    flat = list(zip((chosen @ u).tolist(), (chosen @ v).tolist(), strict=True))
    return [rows[k] for k in contact_corners(flat, gaps[rows].tolist(), slack)]


def _polygon_vertices(points: FloatArray, tolerance: float) -> list[int]:
    """Indices of the corners of a polygon given in order (k, 3): no duplicates, no points along an edge.

    In plain floats: a patch has at most a few dozen points, where each numpy call costs more than the arithmetic.
    """
    rows = points.tolist()
    limit = tolerance * tolerance
    kept: list[int] = []
    for k, point in enumerate(rows):
        if all(_squared_distance(point, rows[m]) > limit for m in kept):
            kept.append(k)
    while len(kept) > 2:  # drop one edge point at a time: a removal can make its neighbour an edge point too
        count = len(kept)
        on_edge = (n for n in range(count) if _near_segment(rows[kept[n]], rows[kept[n - 1]], rows[kept[(n + 1) % count]], limit))
        edge_point = next(on_edge, None)
        if edge_point is None:
            break
        del kept[edge_point]
    return kept


def _squared_distance(p: list[float], q: list[float]) -> float:
    return (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2


def _near_segment(point: list[float], start: list[float], end: list[float], limit: float) -> bool:
    """Whether ``point`` is within ``sqrt(limit)`` of the segment from ``start`` to ``end``."""
    along = [end[0] - start[0], end[1] - start[1], end[2] - start[2]]
    length = max(along[0] ** 2 + along[1] ** 2 + along[2] ** 2, 1e-300)
    t = sum((point[i] - start[i]) * along[i] for i in range(3)) / length
    t = min(max(t, 0.0), 1.0)
    return _squared_distance(point, [start[i] + t * along[i] for i in range(3)]) <= limit


# --------------------------------------------------------------------------- a shape along a line


def _spans(collider: Collider, origins: FloatArray, direction: FloatArray, slack: float) -> tuple[FloatArray, FloatArray, BoolArray]:
    """``(t_in, t_out, hit)``, each (k,): the line ``origins[k] + t * direction`` (unit, world) is in the shape for t between them.

    ``hit`` is False where the line misses the shape by more than ``slack`` [length]. A patch corner
    lies on an edge, which round-off alone could miss: a line that grazes the shape within ``slack``
    still gets the (exact) heights where it passes, so a near miss never shifts a gap. All the lines
    of one patch share the direction, so they are measured together.
    """
    shape, pose = collider.shape, collider.pose
    q, u = (origins - pose.position) @ pose.rotation, pose.rotation.T @ direction
    if isinstance(shape, Sphere):
        return _in_ball(q, u, shape.radius, slack)
    if isinstance(shape, Cylinder):
        return _in_tube(q, u, shape.radius, shape.length / 2.0, slack)
    if isinstance(shape, Capsule):
        ends = np.array([0.0, 0.0, shape.length / 2.0])
        pieces = [_in_tube(q, u, shape.radius, shape.length / 2.0, slack), _in_ball(q - ends, u, shape.radius, slack)]
        pieces.append(_in_ball(q + ends, u, shape.radius, slack))
        # A capsule is the union of the three, and convex: one interval, from the pieces the line meets.
        enter = np.min([np.where(hit, low, math.inf) for low, _, hit in pieces], axis=0)
        leave = np.max([np.where(hit, high, -math.inf) for _, high, hit in pieces], axis=0)
        return enter, leave, np.any([hit for _, _, hit in pieces], axis=0)
    normals, offsets = shape.derived("planes", _planes)
    return _in_planes(normals, offsets, q, u, slack)


def _planes(shape: Shape) -> tuple[FloatArray, FloatArray]:
    """Outward unit normals (m, 3) and offsets (m,) of a polytope's faces: ``normals @ x <= offsets`` inside."""
    if isinstance(shape, Halfspace):
        return shape.normal[None, :], np.array([shape.offset])
    if isinstance(shape, Box):
        return np.vstack([np.eye(3), -np.eye(3)]), np.concatenate([shape.size, shape.size]) / 2.0
    assert isinstance(shape, (Convex, Mesh))  # the curved shapes have their own tests above
    convex = shape.convex if isinstance(shape, Mesh) else shape
    a, b, c = (convex.vertices[convex.triangles[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals, np.einsum("ij,ij->i", normals, a)


def _in_planes(
    normals: FloatArray, offsets: FloatArray, q: FloatArray, u: FloatArray, slack: float
) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Where ``q[k] + t u`` satisfies ``normals @ x <= offsets`` (unit normals): ``(t_in, t_out, hit)``.

    A plane within :data:`GRAZING_FACE` of parallel to the line bounds the ends only moved out by ``slack``: the
    line through a patch corner along the contact normal runs along the side faces at that corner, and their
    bounds ``room / rate`` would be round-off (coal's, on the corner) divided by a small rate, anything at all;
    moved out, a bound lies at least ``slack / rate`` beyond the corner, and where the face overhangs (a thin
    plate tilted by less than ``GRAZING_FACE``) it still stops the line within ``slack`` of the face, instead of
    at the far face's plane (0.002 low under a plate 0.002 thick, 1.9e-6 outside it). The line misses the shape
    where such a plane leaves it outside by more than ``slack`` all the way between the ends.
    """
    rate, room = normals @ u, offsets - q @ normals.T  # (m,), (k, m)
    steep = np.abs(rate) <= GRAZING_FACE
    entering, leaving = (rate < 0.0) & ~steep, (rate > 0.0) & ~steep
    low = (room[:, entering] / rate[entering]).max(axis=1, initial=-math.inf)
    high = (room[:, leaving] / rate[leaving]).min(axis=1, initial=math.inf)
    # the steep planes, each moved out by slack: t * rate <= room + slack
    loose, steep_rate = room[:, steep] + slack, rate[steep]
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        reach = loose / steep_rate  # a bound on t where rate != 0 (infinite where it is round-off)
    first = np.where(steep_rate < 0.0, reach, -math.inf).max(axis=1, initial=-math.inf)
    last = np.where(steep_rate > 0.0, reach, math.inf).min(axis=1, initial=math.inf)
    along = ((steep_rate == 0.0) & (loose < 0.0)).any(axis=1)  # exactly along a plane, outside it
    enter, leave = np.maximum(low, first), np.minimum(high, last)
    return enter, leave, ~along & (enter <= leave + slack)


def _in_ball(q: FloatArray, u: FloatArray, radius: float, slack: float) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Where ``q[k] + t u`` (u unit) is within ``radius`` of the origin."""
    middle = -(q @ u)
    room = middle**2 - np.einsum("ij,ij->i", q, q) + radius**2
    half = np.sqrt(np.maximum(room, 0.0))
    return middle - half, middle + half, room >= radius**2 - (radius + slack) ** 2


def _in_tube(q: FloatArray, u: FloatArray, radius: float, half_length: float, slack: float) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Where ``q[k] + t u`` (u unit) is within ``radius`` of the z axis and ``half_length`` of the xy plane."""
    slab = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]), np.array([half_length, half_length])
    low, high, hit = _in_planes(*slab, q, u, slack)
    across, off_axis = float(u[0] ** 2 + u[1] ** 2), q[:, 0] ** 2 + q[:, 1] ** 2
    if across == 0.0:  # along the axis: the slab, where the line is within the radius
        return low, high, hit & (off_axis <= (radius + slack) ** 2)
    middle = -(q[:, 0] * u[0] + q[:, 1] * u[1]) / across
    room = middle**2 - (off_axis - radius**2) / across
    half = np.sqrt(np.maximum(room, 0.0))
    low, high = np.maximum(low, middle - half), np.minimum(high, middle + half)
    return low, high, hit & (room >= -((radius + slack) ** 2 - radius**2) / across) & (low <= high + slack)


# --------------------------------------------------------------------------- coal queries


def _request(coal: Any, margin: float) -> Any:
    request = coal.CollisionRequest()
    request.security_margin = margin
    request.num_max_contacts = 1
    return request


def _collide(query: _Query, ga: Any, ta: Any, gb: Any, tb: Any) -> tuple[FloatArray | None, float] | None:
    """``(direction from b into a or None if coal's is not a unit vector, signed distance)``, or None when apart.

    coal's contact stays in ``query.result`` for the caller.
    """
    result = query.result
    result.clear()
    query.coal.collide(ga, ta, gb, tb, query.request, result)
    if not result.isCollision():
        return None
    contact = result.getContact(0)
    to_b = _unit(contact.normal)
    return (None if to_b is None else -to_b), float(contact.penetration_depth)  # coal 3: signed distance


def _unit(vector: Any) -> FloatArray | None:
    """``vector`` as a float array if it is a finite unit vector (within :data:`NORMAL_LENGTH`), else None."""
    x, y, z = np.asarray(vector, dtype=float).tolist()  # plain floats: three numpy scalars cost more than the test
    length = math.sqrt(x * x + y * y + z * z)  # NaN or inf stay so and fail the test below
    if not abs(length - 1.0) <= NORMAL_LENGTH:
        return None
    return np.array([x / length, y / length, z / length])


def _transform(coal: Any, pose: Pose, shift: FloatArray | None = None) -> Any:
    return coal.Transform3s(pose.rotation, pose.position if shift is None else pose.position + shift)


def _geometry(coal: Any, shape: Shape) -> Any:
    """The coal geometry of a shape, built once and kept with the shape."""
    return shape.derived("coal", lambda s: _build_geometry(coal, s))


def _build_geometry(coal: Any, shape: Shape) -> Any:
    if isinstance(shape, Box):
        return coal.Box(*shape.size)
    if isinstance(shape, Sphere):
        return coal.Sphere(shape.radius)
    if isinstance(shape, Cylinder):
        return coal.Cylinder(shape.radius, shape.length)
    if isinstance(shape, Capsule):
        return coal.Capsule(shape.radius, shape.length)
    if isinstance(shape, Halfspace):
        return coal.Halfspace(np.array(shape.normal), shape.offset)
    convex = shape.convex if isinstance(shape, Mesh) else shape
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(convex.triangles), len(convex.vertices))
    model.addVertices(np.array(convex.vertices))
    model.addTriangles(np.array(convex.triangles))
    model.endModel()
    model.buildConvexRepresentation(False)  # the hull is convex already: no qhull needed
    return model.convex


# --------------------------------------------------------------------------- fallback normal


def _least_overlap(a: Collider, b: Collider) -> tuple[FloatArray, float]:
    """Direction from ``b`` into ``a`` of least overlap, and the signed distance along it [length].

    Candidates: a halfspace's normal if there is one; else the shapes' own axes
    (both signs) and the line between their centres. The overlap along ``d`` is
    ``h_b(d) + h_a(-d)`` with ``h`` the support function: how far ``a`` must move
    along ``d`` to clear ``b``.
    """
    if isinstance(b.shape, Halfspace):
        candidates = [b.pose.rotation @ b.shape.normal]
    elif isinstance(a.shape, Halfspace):
        candidates = [-(a.pose.rotation @ a.shape.normal)]
    else:
        axes = np.hstack([a.pose.rotation, b.pose.rotation]).T
        line = _centre(a) - _centre(b)
        length = float(np.linalg.norm(line))
        candidates = ([line / length] if length > 0.0 else []) + [s * axis for axis in axes for s in (1.0, -1.0)]
    overlaps = [_support(b, d) + _support(a, -d) for d in candidates]
    best = int(np.argmin(overlaps))
    return np.asarray(candidates[best], dtype=float), -float(overlaps[best])


def _checked_overlap(a: Collider, b: Collider, direction: FloatArray, gap: float, slack: float) -> tuple[FloatArray, float]:
    """coal's answer for a deep overlap, or :func:`_least_overlap`'s where that finds the shapes apart by more: coal's
    box-box test says a 6 cm box 1 um above a 4 m block overlaps it by 1.1 m, its normal reversed (coal 3.0.3)."""
    other, separation = _least_overlap(a, b)
    return (other, separation) if separation > gap + slack else (direction, gap)


def _centre(collider: Collider) -> FloatArray:
    centre, _ = _local_box(collider.shape)
    return collider.pose.rotation @ centre + collider.pose.position


def _support(collider: Collider, direction: FloatArray) -> float:
    """``max over the shape of direction @ x`` (world) [length]; for a halfspace, only along its normal."""
    shape, pose = collider.shape, collider.pose
    u = pose.rotation.T @ direction
    base = float(pose.position @ direction)
    if isinstance(shape, Halfspace):
        return base + shape.offset * float(u @ shape.normal)  # only evaluated with u along the normal
    if isinstance(shape, Mesh):
        shape = shape.convex
    if isinstance(shape, Box):
        return base + float(np.abs(u) @ shape.size) / 2.0
    if isinstance(shape, Sphere):
        return base + shape.radius * float(np.linalg.norm(u))
    if isinstance(shape, Cylinder):
        return base + shape.radius * float(np.hypot(u[0], u[1])) + shape.length / 2.0 * abs(float(u[2]))
    if isinstance(shape, Capsule):
        return base + shape.radius * float(np.linalg.norm(u)) + shape.length / 2.0 * abs(float(u[2]))
    return base + float(np.max(shape.vertices @ u))


def _frozen(array: FloatArray) -> FloatArray:
    """``array`` made read-only (not copied: the caller hands over an array it just computed)."""
    array.setflags(write=False)
    return array
