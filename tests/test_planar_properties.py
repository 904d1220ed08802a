"""Planar detection's properties over random worlds of two shapes (hypothesis), and hostile planar scene files
through the console script.

Properties: a rigid motion of the whole world moves every contact with it; scaling every length scales points and
gaps; swapping which shape is the free body reverses the normals only; gaps agree with distances computed here
independently (analytic for disks, brute-force vertex-to-edge distances for polygons); every normal is a unit vector
into the free body. Nothing here needs coal.
"""

from __future__ import annotations

import json
import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from console_script import run_console
from quasistatic.adapters import ContactDetection, Disk, HalfPlane, PlanarBody, PlanarMover, PlanarWorld, Polygon, Rectangle, planar_pose
from quasistatic.adapters.planar import PlanarShape
from quasistatic.tolerances import DUPLICATE_POINT, MAX_MAGNITUDE, MAX_POLYGON_VERTICES, MAX_VALUES, SMALLEST_LENGTH

SCRIPT = Path(sys.executable).with_name("quasistatic")
EXAMPLES = settings(max_examples=int(os.environ.get("PLANAR_EXAMPLES", "150")), deadline=None, suppress_health_check=[HealthCheck.too_slow])
# Round-off allowed on a point or gap, relative to the world's size (its shapes and how far they sit from the
# origin): detection does a few dozen flops per point, each off by 1e-16 of the coordinates.
ROUNDOFF = 1e-9


Found = list[tuple[np.ndarray, np.ndarray, float]]  # (point, normal into the body, gap) of each contact


@dataclass(frozen=True)
class Placed:
    """A shape and its planar pose [x, y, angle]."""

    shape: PlanarShape
    pose: tuple[float, float, float]

    def moved(self, turn: float, shift: tuple[float, float]) -> Placed:
        c, s = math.cos(turn), math.sin(turn)
        x, y, angle = self.pose
        return Placed(self.shape, (c * x - s * y + shift[0], s * x + c * y + shift[1], angle + turn))

    def scaled(self, factor: float) -> Placed:
        x, y, angle = self.pose
        return Placed(scaled_shape(self.shape, factor), (factor * x, factor * y, angle))

    def vertices(self) -> np.ndarray:
        """A polygon's world vertices (n, 2)."""
        assert isinstance(self.shape, Polygon)
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        return self.shape.vertices @ np.array([[c, s], [-s, c]]) + np.array(self.pose[:2])

    def line(self) -> tuple[np.ndarray, float]:
        """A halfplane's world normal and offset."""
        assert isinstance(self.shape, HalfPlane)
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        normal = np.array([c * self.shape.normal[0] - s * self.shape.normal[1], s * self.shape.normal[0] + c * self.shape.normal[1]])
        return normal, self.shape.offset + float(normal @ self.pose[:2])


def scaled_shape(shape: PlanarShape, factor: float) -> PlanarShape:
    if isinstance(shape, Disk):
        return Disk(factor * shape.radius)
    if isinstance(shape, Rectangle):
        return Rectangle([factor * shape.width, factor * shape.height])
    if isinstance(shape, Polygon):
        return Polygon(factor * shape.vertices)
    return HalfPlane(shape.normal, factor * shape.offset)


@dataclass(frozen=True)
class Pair:
    """A free body and a fixed mover near it, and the contact margin."""

    body: Placed
    other: Placed
    margin: float

    def world(self) -> PlanarWorld:
        return PlanarWorld(
            bodies=(PlanarBody("a", 1.0, self.body.shape, planar_pose(self.body.pose[:2], self.body.pose[2])),),
            movers=(PlanarMover("b", self.other.shape, planar_pose(self.other.pose[:2], self.other.pose[2])),),
            detection=ContactDetection(margin=self.margin),
        )

    def contacts(self) -> Found:
        """(point, normal into the body, gap) of each contact found."""
        detection = self.world().detect()
        for contact in detection.contacts:
            assert (contact.body, contact.other) == ("a", "b")
        return [(np.array(c.point), np.array(c.normal), g) for c, g in zip(detection.contacts, detection.gaps, strict=True)]

    @property
    def size(self) -> float:
        """The world's length: its shapes and how far they sit from the origin."""
        parts = [abs(v) for p in (self.body, self.other) for v in p.pose[:2]]
        return max([self.margin, extent(self.body.shape), extent(self.other.shape), *parts])


def extent(shape: PlanarShape) -> float:
    return shape.extent if math.isfinite(shape.extent) else 0.0


# --------------------------------------------------------------------------- random worlds

sizes = st.floats(0.05, 1.0)
angles = st.floats(-math.pi, math.pi)
disks = st.builds(Disk, sizes)
rectangles = st.builds(lambda w, h: Rectangle([w, h]), sizes, sizes)


@st.composite
def polygons(draw: st.DrawFn) -> Polygon:
    """A convex polygon: 3 to 8 points on a circle, at least 0.3 rad apart, about a centre off the origin."""
    count = draw(st.integers(3, 8))
    gaps = np.array(draw(st.lists(st.floats(0.3, 1.0), min_size=count, max_size=count)))
    turns = np.cumsum(gaps / gaps.sum() * 2.0 * math.pi) + draw(angles)
    radius, centre = draw(sizes), np.array(draw(st.tuples(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))))
    return Polygon(centre * radius + radius * np.column_stack([np.cos(turns), np.sin(turns)]))


bounded = st.one_of(disks, rectangles, polygons())
halfplanes = st.builds(lambda a, offset: HalfPlane([math.cos(a), math.sin(a)], offset), angles, st.floats(-0.2, 0.2))
ANY_SHAPE = st.one_of(bounded, halfplanes)


@st.composite
def pairs(draw: st.DrawFn, others: st.SearchStrategy[PlanarShape] = ANY_SHAPE) -> Pair:
    """A body placed near the mover, so that most pairs touch, overlapping by at most a little: against a halfplane
    by a tenth of its size; against a shape, its centre at least half their sizes away and neither centre inside the
    other shape. Deeper, the contact's normal is a guess (concentric disks have none), and a guess need not move
    with the world."""
    body, other, margin = draw(bounded), draw(others), draw(st.floats(1e-3, 0.2))
    other_pose = (draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0)), draw(angles))
    placed_other, angle = Placed(other, other_pose), draw(angles)
    if isinstance(other, HalfPlane):
        normal, offset = placed_other.line()
        below = support(Placed(body, (0.0, 0.0, angle)), -normal)  # how far the body reaches below its centre
        height = draw(st.floats(-0.1 * body.extent, 2.0 * margin)) + below
        centre = normal * (offset + height) + draw(st.floats(-1.0, 1.0)) * np.array([-normal[1], normal[0]])
    else:
        direction = draw(angles)
        reach = body.extent + other.extent
        distance = draw(st.floats(0.5 * reach, reach + 2.0 * margin))
        centre = np.array(other_pose[:2]) + distance * np.array([math.cos(direction), math.sin(direction)])
    placed_body = Placed(body, (float(centre[0]), float(centre[1]), angle))
    if not isinstance(other, HalfPlane):  # a centre inside the other shape: its way out is a near tie, round-off's pick
        assume(not inside(placed_body, np.array(other_pose[:2])) and not inside(placed_other, centre))
    return Pair(placed_body, placed_other, margin)


def inside(placed: Placed, point: np.ndarray) -> bool:
    """Whether ``point`` lies in the bounded shape or on its boundary (to round-off)."""
    slack = ROUNDOFF * extent(placed.shape)
    if isinstance(placed.shape, Disk):
        return bool(np.linalg.norm(point - placed.pose[:2]) <= placed.shape.radius + slack)
    corners = placed.vertices()
    edges = np.roll(corners, -1, axis=0) - corners
    inward = np.column_stack([-edges[:, 1], edges[:, 0]]) / np.linalg.norm(edges, axis=1)[:, None]  # counter-clockwise
    return bool(np.all(np.einsum("mk,mk->m", inward, point - corners) >= -slack))


def support(placed: Placed, direction: np.ndarray) -> float:
    """The largest ``direction @ x`` over the shape's points x."""
    if isinstance(placed.shape, Disk):
        return float(direction @ placed.pose[:2]) + placed.shape.radius
    return float(np.max(placed.vertices() @ direction))


def assert_same_contacts(got: Found, want: Found, tolerance: float, margin: float, turn: float = 1e-9) -> None:
    """The same contacts in any order: each wanted point matched to the nearest found one; points and gaps equal to
    ``tolerance`` [length], normals to ``turn`` [rad]. A point whose gap is the margin to round-off may be either
    side of it: left out."""
    got, want = ([c for c in found if abs(c[2] - margin) > tolerance] for found in (got, want))
    assert len(got) == len(want), (got, want)
    left = list(got)
    for point, normal, gap in want:
        nearest = min(range(len(left)), key=lambda k: float(np.linalg.norm(left[k][0] - point)))
        found_point, found_normal, found_gap = left.pop(nearest)
        np.testing.assert_allclose(found_point, point, atol=tolerance)
        np.testing.assert_allclose(found_normal, normal, atol=turn)
        assert found_gap == pytest.approx(gap, abs=tolerance)


# --------------------------------------------------------------------------- (a) rigid motions, (b) scale, (c) swap


@EXAMPLES
@given(pair=pairs(), turn=angles, shift=st.tuples(st.floats(-10.0, 10.0), st.floats(-10.0, 10.0)))
def test_a_rigid_motion_of_the_world_moves_every_contact_with_it(pair: Pair, turn: float, shift: tuple[float, float]) -> None:
    moved = Pair(pair.body.moved(turn, shift), pair.other.moved(turn, shift), pair.margin)
    rotation = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    want = [(rotation @ p + shift, rotation @ n, g) for p, n, g in pair.contacts()]
    assert_same_contacts(moved.contacts(), want, ROUNDOFF * max(pair.size, moved.size), pair.margin)


@EXAMPLES
@given(pair=pairs(), factor=st.sampled_from([1e-3, 0.1, 7.3, 1e3]))
def test_scaling_every_length_scales_points_and_gaps(pair: Pair, factor: float) -> None:
    scaled = Pair(pair.body.scaled(factor), pair.other.scaled(factor), factor * pair.margin)
    want = [(factor * p, n, factor * g) for p, n, g in pair.contacts()]
    assert_same_contacts(scaled.contacts(), want, ROUNDOFF * factor * pair.size, scaled.margin)


@EXAMPLES
@given(pair=pairs(others=bounded))
def test_swapping_body_and_mover_reverses_the_normals_only(pair: Pair) -> None:
    swapped = Pair(pair.other, pair.body, pair.margin)
    want = [(p, -n, g) for p, n, g in pair.contacts()]
    got = swapped.contacts()
    if isinstance(pair.body.shape, Disk) or isinstance(pair.other.shape, Disk):
        assert_same_contacts(got, want, ROUNDOFF * pair.size, pair.margin)
    elif want and got:
        # Two polygons: where both faces separate them equally (to DUPLICATE_POINT of the size: two squares side by
        # side, one turned a little), either is the reference, and the tie goes to the mover's; swapped, the other
        # face's normal and its clipped points are as right. The depth (or distance) is the same either way.
        assert min(g for _, _, g in got) == pytest.approx(min(g for _, _, g in want), abs=10.0 * DUPLICATE_POINT * pair.size)
    else:
        assert [g for _, _, g in got + want if abs(g - pair.margin) > ROUNDOFF * pair.size] == []


# --------------------------------------------------------------------------- (d) independent distances, (e) normals


def segment_distances(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) to each edge (m,) of the closed polygon ``corners``, and where along it (0..1)."""
    starts, edges = corners, np.roll(corners, -1, axis=0) - corners
    t = np.clip(np.einsum("nmk,mk->nm", points[:, None, :] - starts[None], edges) / np.einsum("mk,mk->m", edges, edges), 0.0, 1.0)
    nearest = starts[None] + t[..., None] * edges[None]
    return np.stack([np.linalg.norm(points[:, None, :] - nearest, axis=2), t])


def polygon_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Brute force: the least vertex-to-edge distance between two separate convex polygons."""
    return min(float(segment_distances(points, corners)[0].min()) for points, corners in ((a, b), (b, a)))


def overlapping(a: np.ndarray, b: np.ndarray) -> bool:
    """Brute force: whether two convex polygons share interior points (no face of either separates them)."""
    for corners, others in ((a, b), (b, a)):
        edges = np.roll(corners, -1, axis=0) - corners
        outward = np.column_stack([edges[:, 1], -edges[:, 0]]) * np.sign(polygon_area(corners))
        heights = np.einsum("mk,nmk->nm", outward, others[:, None, :] - corners[None])
        if np.any(np.all(heights >= 0.0, axis=0)):
            return False
    return True


def polygon_area(corners: np.ndarray) -> float:
    return 0.5 * float(np.sum(corners[:, 0] * np.roll(corners[:, 1], -1) - corners[:, 1] * np.roll(corners[:, 0], -1)))


@EXAMPLES
@given(pair=pairs(others=st.one_of(disks, halfplanes)), data=st.data())
def test_a_disk_against_a_disk_or_halfplane_has_the_analytic_gap(pair: Pair, data: st.DataObject) -> None:
    disk = data.draw(disks)
    pair = Pair(Placed(disk, pair.body.pose), pair.other, pair.margin)
    centre = np.array(pair.body.pose[:2])
    if isinstance(pair.other.shape, Disk):
        offset = centre - np.array(pair.other.pose[:2])
        distance = float(np.linalg.norm(offset))
        gap, normal = distance - disk.radius - pair.other.shape.radius, offset / distance
    else:
        normal, offset_along = pair.other.line()
        gap = float(normal @ centre) - offset_along - disk.radius
    found = pair.contacts()
    tolerance = ROUNDOFF * pair.size
    if gap > pair.margin + tolerance:
        assert found == []
    elif gap <= pair.margin - tolerance:
        ((point, found_normal, found_gap),) = found
        assert found_gap == pytest.approx(gap, abs=tolerance)
        np.testing.assert_allclose(found_normal, normal, atol=1e-9)
        np.testing.assert_allclose(point, centre - (disk.radius + 0.5 * gap) * normal, atol=tolerance)  # midway


@EXAMPLES
@given(pair=pairs(others=st.one_of(rectangles, polygons())), data=st.data())
def test_separate_polygons_agree_with_the_brute_force_distance(pair: Pair, data: st.DataObject) -> None:
    body = data.draw(st.one_of(rectangles, polygons()))
    pair = Pair(Placed(body, pair.body.pose), pair.other, pair.margin)
    a, b = pair.body.vertices(), pair.other.vertices()
    if overlapping(a, b):
        return
    distance = polygon_distance(a, b)
    found = pair.contacts()
    tolerance = ROUNDOFF * pair.size
    if distance > pair.margin + tolerance:
        assert found == [], (distance, found)
        return
    if distance <= pair.margin - tolerance:
        assert found, distance  # corner to corner too
    if found:
        # the nearest point's gap is their distance (a vertex facing an edge: along the face's normal; corner to
        # corner: along the line between them); every other point's gap, along the same normal, is no less
        gaps = [g for _, _, g in found]
        assert min(gaps) == pytest.approx(distance, abs=tolerance)


def lowest_and_highest(placed: Placed, normal: np.ndarray) -> tuple[float, float]:
    """The least and largest ``normal @ x`` over a bounded shape's points x."""
    return -support(placed, -normal), support(placed, normal)


@EXAMPLES
@given(pair=pairs())
def test_every_normal_is_a_unit_vector_into_the_body(pair: Pair) -> None:
    found = pair.contacts()
    apart = all(gap >= 0.0 for _, _, gap in found)
    tolerance = ROUNDOFF * pair.size
    for _, normal, gap in found:
        assert float(np.linalg.norm(normal)) == pytest.approx(1.0, abs=1e-12)
        body_lowest, _ = lowest_and_highest(pair.body, normal)
        if isinstance(pair.other.shape, HalfPlane):
            plane_normal, offset = pair.other.line()
            np.testing.assert_allclose(normal, plane_normal, atol=1e-12)  # out of the halfplane
            other_highest = offset
        else:
            other_highest = lowest_and_highest(pair.other, normal)[1]
        # Along the normal, the body's lowest point is at most the point's gap above the other's highest one (the
        # gap is measured between the two sides at the point); when the shapes are apart, at least level with it:
        # the normal separates them with the body on its positive side (reversed, the body would lie below).
        assert body_lowest - other_highest <= gap + tolerance
        if apart:
            assert body_lowest - other_highest >= -tolerance, (body_lowest - other_highest, gap)


# --------------------------------------------------------------------------- hostile planar scene files

PLANAR = "quasistatic: 1\ndimension: 2\n"
FLOOR = "movers: {floor: {shape: {halfplane: {normal: [0, 1]}}}}\n"
HANG = 10.0  # [s] wall time: a process still running after this has hung
FAST = 5.0  # [s] CPU time of a rejection, the process's imports included (~0.7 s measured on the 2-core dev machine)


def body(shape: str, pose: str = "") -> str:
    return PLANAR + f"bodies: {{a: {{mass: 1, shape: {{{shape}}}{', pose: {' + pose + '}' if pose else ''}}}}}\n" + FLOOR


def circle(count: int) -> list[list[float]]:
    return [[math.cos(2 * math.pi * k / count), math.sin(2 * math.pi * k / count)] for k in range(count)]


def huge_polygon_json(count: int) -> str:
    """A polygon of ``count`` vertices on a circle, to 2 decimals (a million of them stay under the file size limit)."""
    shape = {"polygon": [[round(x, 2), round(y, 2)] for x, y in circle(count)]}
    return json.dumps({"quasistatic": 1, "dimension": 2, "bodies": {"a": {"mass": 1, "shape": shape}}})


POLYGON = "bodies.a.shape.polygon"
# case -> (file name, its text, the field the error names, fragments of the error line)
HOSTILE: dict[str, tuple[str, str, str, tuple[str, ...]]] = {
    "polygon-1e6-vertices": ("a.json", huge_polygon_json(1_000_000), POLYGON, (f"{MAX_VALUES:,} values",)),
    "polygon-2000-vertices": ("a.json", huge_polygon_json(2000), POLYGON, (f"at most {MAX_POLYGON_VERTICES:,} vertices", "2,000")),
    "xy-1e308": ("a.yaml", body("disk: 0.1", "position: [1.0e+308, 0.1]"), "bodies.a.pose.position", (f"{MAX_MAGNITUDE:g}", "1e+308")),
    "vertex-1e308": ("a.yaml", body("polygon: [[0, 0], [1.0e+308, 0], [0, 1]]"), POLYGON, (f"{MAX_MAGNITUDE:g}", "1e+308")),
    "angle-nan": ("a.yaml", body("disk: 0.1", "position: [0, 0.1], angle: .nan"), "bodies.a.pose.angle", ("finite", "nan")),
    "disk-radius-0": ("a.yaml", body("disk: 0"), "bodies.a.shape.disk", ("> 0", "0.0")),
    "disk-radius-negative": ("a.yaml", body("disk: -0.1"), "bodies.a.shape.disk", ("> 0", "-0.1")),
    "disk-radius-1e-300": ("a.yaml", body("disk: 1.0e-300"), "bodies.a.shape.disk", (f"at least {SMALLEST_LENGTH:g}",)),
    "box-width-1e-300": ("a.yaml", body("box: [1.0e-300, 1]"), "bodies.a.shape.box.width", (f"at least {SMALLEST_LENGTH:g}",)),
    "polygon-2-vertices": ("a.yaml", body("polygon: [[0, 0], [1, 0]]"), POLYGON, ("at least 3",)),
    "polygon-bow-tie": ("a.yaml", body("polygon: [[0, 0], [1, 1], [1, 0], [0, 1]]"), POLYGON, ("edges that cross",)),
    "polygon-crossing": ("a.yaml", body("polygon: [[0, 0], [2, 2], [2, 0], [0, 1]]"), POLYGON, ("not convex",)),
    "polygon-star": ("a.yaml", body(f"polygon: {[circle(5)[k % 5] for k in range(0, 10, 2)]}"), POLYGON, ("star",)),
    "duplicate-key": ("a.yaml", body("disk: 0.1, disk: 0.2"), "bodies.a.shape.disk", ("given twice",)),
    "box-3-numbers": ("a.yaml", body("box: [0.1, 0.1, 0.1]"), "bodies.a.shape.box", ("[width, height]", "[0.1, 0.1, 0.1]")),
    "sphere-in-2d": ("a.yaml", body("sphere: 0.1"), "bodies.a.shape.sphere", ("a 3-D shape", "disk")),
    "disk-in-3d": ("a.yaml", "quasistatic: 1\nbodies: {a: {mass: 1, shape: {disk: 0.1}}}\n", "bodies.a.shape.disk", ("dimension: 2",)),
    "halfplane-in-3d": (
        "a.yaml",
        "quasistatic: 1\nbodies: {a: {mass: 1, shape: {sphere: 0.1}}}\nmovers: {floor: {shape: {halfplane: {normal: [0, 1]}}}}\n",
        "movers.floor.shape.halfplane",
        ("dimension: 2", "{'normal': [0.0, 1.0], 'offset': 0.0}"),
    ),
}  # fmt: skip


@pytest.fixture(scope="module")
def hostile_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("planar-hostile")
    files = {}
    for case, (name, text, _, _) in HOSTILE.items():
        (root / case).mkdir()
        files[case] = root / case / name
        files[case].write_text(text)
    return files


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_a_hostile_planar_file_is_one_error_line(hostile_files: dict[str, Path], case: str) -> None:
    _, _, field, fragments = HOSTILE[case]
    run = run_console([str(SCRIPT), "solve", str(hostile_files[case])], HANG)
    result = run.result
    assert "Traceback" not in result.stderr, result.stderr[-2000:]
    assert (result.returncode, result.stdout) == (2, ""), result.stderr[-2000:]
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {field}"), result.stderr[-2000:]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert "File(" not in lines[0] and len(lines[0]) < 400  # the file's words, not a class's; bounded
    assert run.cpu_seconds < FAST, f"{run.cpu_seconds:.1f} s of CPU"
