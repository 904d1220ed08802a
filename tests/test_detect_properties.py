"""3-D detection's properties over random polytopes near a surface (hypothesis): boxes, thin plates and random convex
hulls, at any orientation or nearly face down, against a halfspace or resting over the top face of a large block.

A polytope's distance to a plane is taken at its vertices, so the contact constraints of such a pair are exactly
those of its vertices within the margin. The reported points must stand for them: each lies midway between the two
surfaces (its gap apart along the normal), and the lowest gaps they allow under every vertex within the margin, by
convex combination (their lower envelope), are no higher than that vertex's own gap. A deepest vertex left out
fails this, as does a point that lies on neither surface. Normals are unit and the surface's own, and a small pose
change moves the envelope and the deepest gap by no more than the motion.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

coal = pytest.importorskip("coal")

from quasistatic.adapters import Box, Collider, Convex, Halfspace, Pose, detect  # noqa: E402  (after the skip: coal is optional)
from quasistatic.tolerances import DUPLICATE_POINT  # noqa: E402

EXAMPLES = settings(max_examples=int(os.environ.get("DETECT_EXAMPLES", "120")), deadline=None, suppress_health_check=[HealthCheck.too_slow])
# Points closer than DUPLICATE_POINT of the size are merged, and a point that near an edge between two others is
# dropped: the envelope may be that much off, times a slope of at most 1 (a face at 45 degrees), and a little more.
SLACK = 4.0 * DUPLICATE_POINT
BLOCK = np.array([4.0, 4.0, 1.0])  # the block's size: its top face, z = 0, is far larger than any body


@dataclass(frozen=True)
class Scene:
    """A polytope placed near a surface: the world's ``frame`` turns everything (the surface's normal is its z)."""

    shape: Box | Convex
    pose: Pose  # the body's pose in the surface's frame
    frame: Pose
    margin: float
    on_block: bool  # over the top face of a block (coal's contact patch), else on a halfspace (from the vertices)

    @property
    def size(self) -> float:
        return self.shape.extent

    def local_vertices(self) -> np.ndarray:
        if isinstance(self.shape, Box):
            return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * self.shape.size / 2.0
        return np.asarray(self.shape.vertices)

    def vertices(self) -> np.ndarray:
        """The body's vertices in the surface's frame (n, 3): their z is their gap."""
        return self.local_vertices() @ self.pose.rotation.T + self.pose.position

    def local_planes(self) -> tuple[np.ndarray, np.ndarray]:
        """The body's outward face normals (m, 3) and offsets (m,) in its own frame."""
        if isinstance(self.shape, Box):
            return np.vstack([np.eye(3), -np.eye(3)]), np.concatenate([self.shape.size, self.shape.size]) / 2.0
        a, b, c = (self.shape.vertices[self.shape.triangles[:, k]] for k in range(3))
        normals = np.cross(b - a, c - a)
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        return normals, np.einsum("ij,ij->i", normals, a)

    def planes(self) -> tuple[np.ndarray, np.ndarray]:
        """The body's outward face normals (m, 3) and offsets (m,) in the surface's frame."""
        normals, offsets = self.local_planes()
        turned = normals @ self.pose.rotation.T
        return turned, offsets + turned @ self.pose.position

    def lower_vertices(self) -> np.ndarray:
        """Indices of the vertices on a face turned towards the surface by more than round-off: those whose
        constraint no other vertex implies (a face's top corners too, where it overhangs)."""
        local, offsets = self.local_planes()
        vertices = self.local_vertices()
        facing = (local @ self.pose.rotation.T)[:, 2] < -1e-6
        on_face = np.abs(vertices @ local.T - offsets) <= 1e-9 * self.size  # (n, m)
        return np.flatnonzero(np.any(on_face[:, facing], axis=1))

    def moved(self, turn: np.ndarray, shift: np.ndarray) -> Scene:
        """The body turned by the rotation vector ``turn`` about its centre and moved by ``shift``."""
        angle = float(np.linalg.norm(turn))
        rotation = axis_angle(turn / angle, angle) if angle > 0.0 else np.eye(3)
        pose = Pose(self.pose.position + shift, rotation @ self.pose.rotation)
        return Scene(self.shape, pose, self.frame, self.margin, self.on_block)

    def contacts(self) -> list[tuple[np.ndarray, np.ndarray, float]]:
        """(point, normal into the body, gap) of each contact found, in the surface's frame."""
        body = Collider("body", self.shape, self.frame.compose(self.pose))
        if self.on_block:
            other = Collider("surface", Box(BLOCK), self.frame.compose(Pose((0.0, 0.0, -BLOCK[2] / 2.0))))
        else:
            other = Collider("surface", Halfspace((0.0, 0.0, 1.0), 0.0), self.frame)
        found = detect([body, other], margin=self.margin)
        rotation, origin = self.frame.rotation, self.frame.position
        return [((c.point - origin) @ rotation, c.normal @ rotation, c.gap) for c in found]


def axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k


def quaternion_rotation(q: tuple[float, float, float, float]) -> np.ndarray:
    array = np.array(q)
    return Pose.from_quaternion((0.0, 0.0, 0.0), array / np.linalg.norm(array)).rotation


# --------------------------------------------------------------------------- random scenes

lengths = st.floats(0.02, 0.3)
quaternions = st.tuples(*[st.floats(-1.0, 1.0)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1)


@st.composite
def shapes(draw: st.DrawFn) -> Box | Convex:
    """A box, a thin plate (a box a hundredth as thick as it is wide) or the hull of 5 to 12 random points."""
    kind = draw(st.sampled_from(["box", "plate", "hull"]))
    if kind == "box":
        return Box([draw(lengths), draw(lengths), draw(lengths)])
    if kind == "plate":
        width = draw(lengths)
        return Box([width, draw(st.floats(0.5, 1.0)) * width, draw(st.floats(1e-3, 1e-2)) * width])
    seed = draw(st.integers(0, 2**32 - 1))
    points = np.random.default_rng(seed).normal(size=(draw(st.integers(5, 12)), 3)) * draw(lengths)
    return Convex(points)


@st.composite
def scenes(draw: st.DrawFn, on_block: bool | None = None, boxes_only: bool = False) -> Scene:
    """A body at any orientation or within a small tilt of resting on one of its faces, its lowest vertex from a
    tenth of the margin below the surface to twice the margin above it; the world turned and moved at random."""
    shape = draw(shapes().filter(lambda s: isinstance(s, Box) or not boxes_only))
    margin = draw(st.floats(1e-3, 0.3)) * shape.extent
    if draw(st.booleans()):
        rotation = quaternion_rotation(draw(quaternions))
    else:
        rotation = axis_angle(unit(draw(quaternions)[:3]), draw(st.floats(0.0, 2.0)) * margin / shape.extent) @ face_down(shape, draw)
    local = Scene(shape, Pose((0.0, 0.0, 0.0), rotation), Pose(), margin, False).vertices()
    height = draw(st.floats(-0.1, 2.0)) * margin - float(local[:, 2].min())
    position = np.array([draw(st.floats(-0.5, 0.5)), draw(st.floats(-0.5, 0.5)), height])
    frame = Pose(draw(st.tuples(*[st.floats(-2.0, 2.0)] * 3)), quaternion_rotation(draw(quaternions)))
    block = draw(st.booleans()) if on_block is None else on_block
    return Scene(shape, Pose(position, rotation), frame, margin, block)


def unit(vector: tuple[float, ...]) -> np.ndarray:
    array = np.array(vector, dtype=float)
    length = float(np.linalg.norm(array))
    return array / length if length > 1e-6 else np.array([0.0, 0.0, 1.0])


def face_down(shape: Box | Convex, draw: st.DrawFn) -> np.ndarray:
    """A rotation that lays one of the shape's faces flat on z = 0, the shape above it."""
    if isinstance(shape, Box):
        turns = [np.eye(3), axis_angle(np.array([1.0, 0.0, 0.0]), math.pi / 2), axis_angle(np.array([0.0, 1.0, 0.0]), math.pi / 2)]
        return turns[draw(st.integers(0, 2))]
    a, b, c = (shape.vertices[shape.triangles[:, k]] for k in range(3))
    normal = unit(tuple(np.cross(b - a, c - a)[draw(st.integers(0, len(shape.triangles) - 1))]))
    axis = np.cross(normal, [0.0, 0.0, -1.0])  # turn the face's outward normal onto -z
    if np.linalg.norm(axis) < 1e-9:
        return np.eye(3) if normal[2] < 0 else axis_angle(np.array([1.0, 0.0, 0.0]), math.pi)
    return axis_angle(axis / np.linalg.norm(axis), math.atan2(float(np.linalg.norm(axis)), float(-normal[2])))


# --------------------------------------------------------------------------- the lower envelope of the reported points


def envelope(points: np.ndarray, gaps: np.ndarray, at: np.ndarray, reach: float) -> float:
    """The least gap a convex combination of the reported points (their xy within ``reach`` of ``at``) allows:
    the constraints the points impose, at ``at`` (an LP); inf where no combination comes that near."""
    count = len(gaps)
    if count == 0:
        return math.inf
    rows = np.vstack([points[:, :2].T, -points[:, :2].T])
    bounds = np.concatenate([at + reach, -(at - reach)])
    solved = linprog(gaps, A_ub=rows, b_ub=bounds, A_eq=np.ones((1, count)), b_eq=[1.0], bounds=(0.0, None), method="highs")
    return float(solved.fun) if solved.status == 0 else math.inf


def found_arrays(found: list[tuple[np.ndarray, np.ndarray, float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    points = np.array([p for p, _, _ in found]).reshape(-1, 3)
    normals = np.array([n for _, n, _ in found]).reshape(-1, 3)
    return points, normals, np.array([g for _, _, g in found])


# --------------------------------------------------------------------------- properties


def _overhanging_plate() -> Scene:
    """A plate 0.002 thick tilted so one side face overhangs within ``GRAZING_FACE`` of parallel to the normal: the
    line through that face's top corner once took the bottom face's plane, 1.9e-6 outside the body (found by
    hypothesis)."""
    turn = np.array(
        [
            [0.998047511, -0.0441654072, 0.0441654072],
            [0.0441654072, 0.999023755, 0.00097624465],
            [-0.0441654072, 0.00097624465, 0.999023755],
        ]
    )
    u, _, vt = np.linalg.svd(turn)
    pose, frame = Pose((0.0, 0.0, 0.00661832), u @ vt), Pose((0.0, 0.0, 0.0), np.diag([-1.0, -1.0, 1.0]))
    return Scene(Box((0.25, 0.25, 0.00195312)), pose, frame, 0.015625, True)


@EXAMPLES
@given(scene=scenes())
@example(scene=_overhanging_plate())
def test_every_point_lies_midway_between_both_surfaces_along_the_surfaces_unit_normal(scene: Scene) -> None:
    points, normals, gaps = found_arrays(scene.contacts())
    tolerance = SLACK * scene.size
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)
    # out of the surface: against a block, to GJK's stopping rule (a relative duality gap of 1e-6; 3e-9 rad measured)
    np.testing.assert_allclose(normals, np.tile([0.0, 0.0, 1.0], (len(gaps), 1)), atol=1e-7)
    assert np.all(gaps <= scene.margin + tolerance)
    np.testing.assert_allclose(points[:, 2] - gaps / 2.0, 0.0, atol=tolerance)  # on the surface z = 0
    body_normals, body_offsets = scene.planes()
    on_body = points + gaps[:, None] / 2.0 * np.array([0.0, 0.0, 1.0])
    distance = np.max(on_body @ body_normals.T - body_offsets, axis=1, initial=-math.inf)  # 0 on the body's boundary
    np.testing.assert_allclose(distance, 0.0, atol=tolerance)


@EXAMPLES
@given(scene=scenes())
def test_the_points_stand_for_every_vertex_within_the_margin_and_the_deepest_one(scene: Scene) -> None:
    points, _, gaps = found_arrays(scene.contacts())
    vertices = scene.vertices()
    tolerance = SLACK * scene.size
    deepest = float(vertices[:, 2].min())
    if deepest > scene.margin + tolerance:
        assert len(gaps) == 0
        return
    if deepest <= scene.margin - tolerance:
        assert min(gaps) == pytest.approx(deepest, abs=tolerance), "the deepest vertex is not represented"
    for k in scene.lower_vertices():
        vertex = vertices[k]
        if vertex[2] <= scene.margin - tolerance:
            lowest = envelope(points, gaps, vertex[:2], tolerance)
            assert lowest <= vertex[2] + tolerance, (f"vertex {k} at gap {vertex[2]:.3g} has no point standing for it", lowest)


@EXAMPLES
@given(scene=scenes(boxes_only=True, on_block=False))
def test_a_box_over_a_blocks_top_face_touches_as_on_a_halfspace(scene: Scene) -> None:
    """coal's patch against the block's face and the vertices against the plane of that face: the same contacts."""
    plane = scene.contacts()
    block = Scene(scene.shape, scene.pose, scene.frame, scene.margin, True).contacts()
    tolerance = SLACK * scene.size
    _, _, plane_gaps = found_arrays(plane)
    points, _, gaps = found_arrays(block)
    for point, _, gap in plane:
        if gap <= scene.margin - tolerance:
            assert envelope(points, gaps, point[:2], tolerance) <= gap + tolerance, (point, gap, block)
    if len(plane_gaps) and min(plane_gaps) <= scene.margin - tolerance:
        assert min(gaps) == pytest.approx(min(plane_gaps), abs=tolerance)


@EXAMPLES
@given(scene=scenes(), turn=st.tuples(*[st.floats(-1.0, 1.0)] * 3), shift=st.tuples(*[st.floats(-1.0, 1.0)] * 3))
def test_a_small_motion_changes_the_deepest_gap_and_the_envelope_by_no_more_than_the_motion(
    scene: Scene, turn: tuple[float, float, float], shift: tuple[float, float, float]
) -> None:
    step = 1e-4  # the largest distance any point of the body moves [fraction of its size]
    turn_vector, shift_vector = np.array(turn) * step / math.sqrt(3.0) / 2.0, np.array(shift) * step * scene.size / math.sqrt(3.0) / 2.0
    moved = scene.moved(turn_vector, shift_vector)
    motion = float(np.max(np.linalg.norm(moved.vertices() - scene.vertices(), axis=1)))  # about step x size
    tolerance = SLACK * scene.size
    before, after = (found_arrays(s.contacts()) for s in (scene, moved))
    inner = scene.margin - motion - tolerance  # points this deep are within the margin before and after
    for (points, _, gaps), (other_points, _, other_gaps) in ((before, after), (after, before)):
        for point, gap in zip(points, gaps, strict=True):
            if gap <= inner:
                assert envelope(other_points, other_gaps, point[:2], motion + tolerance) <= gap + motion + tolerance
    deep = [g for g in (before[2], after[2]) if len(g) and g.min() <= inner]
    if len(deep) == 2:
        assert abs(float(deep[0].min()) - float(deep[1].min())) <= motion + tolerance


# --------------------------------------------------------------------------- the cases the properties found, by hand

TABLE = Collider("table", Halfspace((0.0, 0.0, 1.0), 0.0))


def block() -> Collider:
    return Collider("block", Box(BLOCK), Pose((0.0, 0.0, -BLOCK[2] / 2.0)))


def test_a_flat_pyramid_on_its_apex_touches_at_the_apex_and_its_base_corners() -> None:
    """The base's corners, 0.5 mm up, are within the 1 mm margin and their hull holds the apex: it stays."""
    points = [[0.05, 0.05, 5e-4], [-0.05, 0.05, 5e-4], [-0.05, -0.05, 5e-4], [0.05, -0.05, 5e-4], [0.0, 0.0, 0.0], [0.0, 0.0, 0.02]]
    found = detect([Collider("part", Convex(points), Pose((0.0, 0.0, -1e-5))), TABLE], margin=1e-3)
    assert sorted(round(c.gap, 9) for c in found) == [-1e-5] + [4.9e-4] * 4
    apex = next(c for c in found if c.gap < 0.0)
    np.testing.assert_allclose(apex.point, [0.0, 0.0, -5e-6], atol=1e-12)


@pytest.mark.parametrize("surface", ["table", "block"])
def test_a_thin_plate_tilted_within_the_margin_touches_at_its_lowest_corner(surface: str) -> None:
    """A 10 x 10 x 0.1 cm plate turned 4 and 6 mrad: its lowest corner lies inside the hull of the others seen from
    above (the top corners overhang it); it was left out, on the table and on the block."""
    size = np.array([0.1, 0.1, 0.001])
    rotation = Pose.from_rpy((0.0, 0.0, 0.0), (0.004, 0.006, 0.0)).rotation
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * size / 2.0 @ rotation.T
    plate = Collider("plate", Box(size), Pose((0.0, 0.0, -corners[:, 2].min()), rotation))
    found = detect([plate, TABLE if surface == "table" else block()], margin=2e-3)
    lowest = corners[np.argmin(corners[:, 2])]
    deepest = min(found, key=lambda c: c.gap)
    assert deepest.gap == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(deepest.point[:2], lowest[:2], atol=1e-12)
    assert len(found) == 7  # the 4 bottom corners and the 3 top ones on the faces turned down: not the highest


def test_a_box_tilted_a_hundred_thousandth_on_a_block_has_its_corners_own_gaps() -> None:
    """Its corners are 0, 2.5, 2.5 and 5 um up: coal's patch corners, off its edges by 1e-10, were measured along
    side faces 1e-5 rad off the normal, which moved their gaps by micrometres and swapped them."""
    rotation = Pose.from_rpy((0.0, 0.0, 0.0), (1e-5, 1e-5, 0.0)).rotation
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.125 @ rotation.T
    box = Collider("box", Box((0.25, 0.25, 0.25)), Pose((0.0, 0.0, -corners[:, 2].min()), rotation))
    found = detect([box, block()], margin=0.0625)
    bottom = corners[np.argsort(corners[:, 2])[:4]] - [0.0, 0.0, corners[:, 2].min()]
    assert len(found) == 4
    for contact in found:
        nearest = bottom[np.argmin(np.linalg.norm(bottom[:, :2] - contact.point[:2], axis=1))]
        assert contact.gap == pytest.approx(nearest[2], abs=1e-12)


def test_a_box_a_micrometre_above_a_block_is_a_micrometre_apart() -> None:
    """coal 3.0.3's box-box test says the two overlap by 1.1 m, its normal pointing down; the overlap is checked."""
    box = Collider("box", Box((0.0625, 0.0625, 0.1015625)), Pose((0.0, 0.0, 0.1015625 / 2.0 + 1e-6)))
    found = detect([box, block()], margin=1e-4)
    assert len(found) == 4
    for contact in found:
        assert contact.gap == pytest.approx(1e-6, abs=1e-12)
        np.testing.assert_allclose(contact.normal, [0.0, 0.0, 1.0], atol=1e-9)
