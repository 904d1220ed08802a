"""Contact detection with coal (adapters/shapes.py, adapters/detect.py), on cases derived by hand.

Conventions under test: a ContactPoint's ``first`` owner is the collider listed
first, its normal points from ``second`` into ``first``, and ``gap`` is the signed
distance along it (> 0 apart, < 0 overlapping).
"""

from __future__ import annotations

import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

coal = pytest.importorskip("coal")

from quasistatic.adapters import (  # noqa: E402  (after the skip: coal is optional)
    Box,
    Capsule,
    Collider,
    ContactPoint,
    Convex,
    Cylinder,
    Halfspace,
    Layout,
    Mesh,
    Pose,
    Sphere,
    candidate_pairs,
    detect,
    shape_from_coal,
)
from quasistatic.errors import BackendUnavailableError, SceneError  # noqa: E402

SIZE = np.array([0.1, 0.2, 0.3])
EXACT = 1e-9  # coal's box-halfspace query reports touching faces 1.5e-11 apart; everything else is round-off
TABLE = Collider("table", Halfspace((0.0, 0.0, 1.0), 0.0))
MARGIN = 1e-3


def _points(contacts: list[ContactPoint]) -> np.ndarray:
    return np.array([c.point for c in contacts])


def _same_points(found: np.ndarray, expected: np.ndarray, tol: float = EXACT) -> None:
    """The same set of points, in any order."""
    assert found.shape == np.shape(expected), (found, expected)
    for point in expected:
        assert np.min(np.linalg.norm(found - point, axis=1)) < tol, (point, found)


def _box_corners(size: np.ndarray, z: float) -> np.ndarray:
    x, y = size[0] / 2.0, size[1] / 2.0
    return np.array([[sx * x, sy * y, z] for sx in (-1, 1) for sy in (-1, 1)])


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return Pose.from_quaternion((0, 0, 0), q / np.linalg.norm(q)).rotation


# --------------------------------------------------------------------------- a box on a table


def test_a_box_flat_on_the_table_touches_at_its_four_bottom_corners() -> None:
    box = Collider("box", Box(SIZE), Pose((0.0, 0.0, 0.15)))
    contacts = detect([box, TABLE])
    _same_points(_points(contacts), _box_corners(SIZE, 0.0))
    for c in contacts:
        assert (c.first, c.second) == ("box", "table")
        np.testing.assert_allclose(c.normal, [0, 0, 1], atol=1e-12)
        assert abs(c.gap) < EXACT


def test_a_box_tilted_about_a_bottom_edge_touches_along_that_edge() -> None:
    tilt = np.radians(3.0)
    pose = Pose.from_rpy((0, 0, 0), (0.0, tilt, 0.0))
    edge = np.array([0.05, 0.0, 0.0])  # the bottom edge at x = +0.05 stays on the table
    centre = edge + pose.rotation @ (np.array([0.0, 0.0, 0.15]) - edge)
    box = Collider("box", Box(SIZE), Pose(centre, pose.rotation))
    contacts = detect([box, TABLE], margin=MARGIN)  # the other edge is 5 mm up: beyond the margin
    _same_points(_points(contacts), [[0.05, -0.1, 0.0], [0.05, 0.1, 0.0]])
    assert all(abs(c.gap) < EXACT for c in contacts)


def test_a_box_tilted_less_than_the_margin_touches_at_four_corners_with_their_own_gaps() -> None:
    rise = MARGIN / 2.0  # the far bottom edge, 0.1 away, is this far up
    tilt = np.arcsin(rise / 0.1)
    pose = Pose.from_rpy((0, 0, 0), (0.0, tilt, 0.0))
    edge = np.array([0.05, 0.0, 0.0])
    box = Collider("box", Box(SIZE), Pose(edge + pose.rotation @ (np.array([0.0, 0.0, 0.15]) - edge), pose.rotation))
    contacts = detect([box, TABLE], margin=MARGIN)
    near = [c for c in contacts if c.point[0] > 0.0]
    far = [c for c in contacts if c.point[0] < 0.0]
    assert len(near) == len(far) == 2
    assert all(abs(c.gap) < EXACT for c in near)
    assert all(c.gap == pytest.approx(rise, abs=EXACT) for c in far)
    np.testing.assert_allclose([c.point[2] for c in far], rise / 2.0, atol=EXACT)  # midway up the gap


def test_a_box_lifted_within_the_margin_is_in_contact_and_beyond_it_is_not() -> None:
    lift = MARGIN / 2.0
    near = detect([Collider("box", Box(SIZE), Pose((0.0, 0.0, 0.15 + lift))), TABLE], margin=MARGIN)
    _same_points(_points(near), _box_corners(SIZE, lift / 2.0))  # midway between the box and the table
    assert all(c.gap == pytest.approx(lift, abs=EXACT) for c in near)
    far = detect([Collider("box", Box(SIZE), Pose((0.0, 0.0, 0.15 + 2.0 * MARGIN))), TABLE], margin=MARGIN)
    assert far == []


# --------------------------------------------------------------------------- boxes on boxes


def _box_on_box(world: Pose) -> list[ContactPoint]:
    """A 0.1 x 0.2 x 0.3 box on a 0.4 x 0.4 x 0.2 block whose top is z = 0, overhanging its corner."""
    small = Collider("box", Box(SIZE), world.compose(Pose((0.18, 0.15, 0.15))))
    block = Collider("block", Box((0.4, 0.4, 0.2)), world.compose(Pose((0.0, 0.0, -0.1))))
    return detect([small, block])


# The small box covers x in [0.13, 0.23], y in [0.05, 0.25]; the block's top ends at 0.2 on both.
OVERLAP = np.array([[0.13, 0.05, 0.0], [0.2, 0.05, 0.0], [0.2, 0.2, 0.0], [0.13, 0.2, 0.0]])


def test_a_box_overhanging_a_block_touches_at_the_corners_of_their_overlap() -> None:
    contacts = _box_on_box(Pose())
    _same_points(_points(contacts), OVERLAP)
    for c in contacts:
        np.testing.assert_allclose(c.normal, [0, 0, 1], atol=1e-9)
        assert abs(c.gap) < EXACT


def test_a_box_on_a_tilted_block_touches_at_the_rotated_corners() -> None:
    world = Pose.from_rpy((1.0, 2.0, 3.0), np.radians([10.0, 20.0, 30.0]))
    contacts = _box_on_box(world)
    _same_points(_points(contacts), world.apply(OVERLAP))
    for c in contacts:
        np.testing.assert_allclose(c.normal, world.rotation[:, 2], atol=1e-9)
        assert abs(c.gap) < EXACT


# --------------------------------------------------------------------------- curved shapes


def test_a_sphere_on_the_table_touches_at_its_bottom() -> None:
    contacts = detect([Collider("ball", Sphere(0.05), Pose((0.3, -0.2, 0.05))), TABLE])
    assert len(contacts) == 1
    np.testing.assert_allclose(contacts[0].point, [0.3, -0.2, 0.0], atol=EXACT)
    np.testing.assert_allclose(contacts[0].normal, [0, 0, 1], atol=1e-12)


def test_a_fingertip_touching_a_box_face_touches_at_the_known_point_along_the_face_normal() -> None:
    tip = Collider("finger", Sphere(0.01), Pose((0.06, 0.03, -0.04)))  # 0.01 beyond the +x face at x = 0.05
    contacts = detect([tip, Collider("box", Box(SIZE))])
    assert len(contacts) == 1
    np.testing.assert_allclose(contacts[0].point, [0.05, 0.03, -0.04], atol=EXACT)
    np.testing.assert_allclose(contacts[0].normal, [1, 0, 0], atol=1e-12)  # from the box into the finger
    assert abs(contacts[0].gap) < EXACT


def test_a_cylinder_lying_on_its_side_touches_at_both_ends_of_its_line() -> None:
    lying = Pose.from_rpy((0.0, 0.0, 0.05), (np.pi / 2, 0.0, 0.0))  # axis along y
    contacts = detect([Collider("can", Cylinder(0.05, 0.4), lying), TABLE])
    _same_points(_points(contacts), [[0.0, -0.2, 0.0], [0.0, 0.2, 0.0]])


def test_a_cylinder_on_its_end_touches_at_a_polygon_inscribed_in_its_base() -> None:
    contacts = detect([Collider("can", Cylinder(0.05, 0.4), Pose((0.0, 0.0, 0.2))), TABLE])
    radii = np.linalg.norm(_points(contacts)[:, :2], axis=1)
    assert len(contacts) >= 6
    np.testing.assert_allclose(radii, 0.05, atol=EXACT)


def test_a_capsule_lying_on_the_table_touches_at_the_ends_of_its_segment() -> None:
    lying = Pose.from_rpy((0.0, 0.0, 0.05), (0.0, np.pi / 2, 0.0))  # axis along x
    contacts = detect([Collider("pill", Capsule(0.05, 0.2), lying), TABLE])
    _same_points(_points(contacts), [[-0.1, 0.0, 0.0], [0.1, 0.0, 0.0]])


# --------------------------------------------------------------------------- meshes


CUBE_VERTICES = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
CUBE_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1)]  # -x, +x, -y faces
CUBE_FACES += [(2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]  # +y, -z, +z faces


def _cube_obj(folder: Path) -> Path:
    path = folder / "cube.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in CUBE_VERTICES] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in CUBE_FACES]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_mesh_cube_gives_the_contacts_of_the_primitive_box(tmp_path: Path) -> None:
    mesh = Mesh(_cube_obj(tmp_path), scale=SIZE)  # a unit cube scaled to the box
    assert mesh.convex.vertices.shape == (8, 3)
    pose = Pose.from_rpy((0.2, 0.1, 0.15), (0.0, 0.0, 0.3))
    from_mesh = detect([Collider("box", mesh, pose), TABLE])
    from_box = detect([Collider("box", Box(SIZE), pose), TABLE])
    _same_points(_points(from_mesh), _points(from_box))
    assert all(abs(c.gap) < EXACT for c in from_mesh)


def test_a_mesh_with_points_inside_is_used_through_its_hull() -> None:
    rng = np.random.default_rng(0)
    points = np.vstack([np.array(CUBE_VERTICES) * SIZE, rng.uniform(-0.04, 0.04, size=(20, 3))])
    contacts = detect([Collider("box", Convex(points), Pose((0.0, 0.0, 0.15))), TABLE])
    _same_points(_points(contacts), _box_corners(SIZE, 0.0))


# --------------------------------------------------------------------------- invariance


def _scene(world: Pose, scale: float = 1.0) -> list[Collider]:
    """A box on the table, a box overhanging a block, and a fingertip on the box's side."""
    s = scale
    return [
        Collider("box", Box(SIZE * s), world.compose(Pose((0.18 * s, 0.15 * s, 0.15 * s)))),
        Collider("finger", Sphere(0.01 * s), world.compose(Pose((0.24 * s, 0.16 * s, 0.2 * s)))),
        Collider("block", Box((0.4 * s, 0.4 * s, 0.2 * s)), world.compose(Pose((0.0, 0.0, -0.1 * s)))),
        Collider("table", Halfspace(world.rotation[:, 2], float(world.rotation[:, 2] @ world.position) - 0.2 * s)),
    ]


def test_one_rigid_transform_of_the_world_moves_every_point_and_normal_with_it() -> None:
    reference = detect(_scene(Pose()))
    assert len(reference) == 4 + 4 + 1  # the overlap, the block's bottom on the table, the fingertip
    rng = np.random.default_rng(7)
    for _ in range(4):
        world = Pose(rng.uniform(-2, 2, size=3), _rotation(rng))
        moved = detect(_scene(world))
        assert len(moved) == len(reference)
        for c in reference:
            match = min(moved, key=lambda m: float(np.linalg.norm(m.point - world.apply(c.point))))
            assert (match.first, match.second) == (c.first, c.second)
            np.testing.assert_allclose(match.point, world.apply(c.point), atol=1e-9)
            np.testing.assert_allclose(match.normal, world.rotation @ c.normal, atol=1e-9)
            assert match.gap == pytest.approx(c.gap, abs=1e-9)


def test_changing_units_scales_points_and_gaps_and_keeps_normals() -> None:
    metres = detect(_scene(Pose()), margin=MARGIN)
    millimetres = detect(_scene(Pose(), scale=1000.0), margin=1000.0 * MARGIN)
    assert [(c.first, c.second) for c in millimetres] == [(c.first, c.second) for c in metres]
    for m, mm in zip(metres, millimetres, strict=True):
        np.testing.assert_allclose(mm.point, 1000.0 * m.point, atol=1e-6)
        np.testing.assert_allclose(mm.normal, m.normal, atol=1e-9)
        assert mm.gap == pytest.approx(1000.0 * m.gap, abs=1e-6)


# --------------------------------------------------------------------------- degenerate normals


def test_a_sphere_centred_on_a_box_face_gets_the_face_normal(tmp_path: Path) -> None:
    for block in (Box((1.0, 1.0, 1.0)), Mesh(_cube_obj(tmp_path))):
        contacts = detect([Collider("ball", Sphere(0.05), Pose((0.1, 0.2, 0.5))), Collider("block", block)])
        assert len(contacts) == 1
        assert np.all(np.isfinite(contacts[0].normal)) and np.all(np.isfinite(contacts[0].point))
        np.testing.assert_allclose(contacts[0].normal, [0, 0, 1], atol=1e-9)
        assert contacts[0].gap == pytest.approx(-0.05, abs=1e-9)


def test_coaxial_capsules_where_coal_has_no_normal_get_a_finite_unit_one() -> None:
    # coal 3.0.3 returns a zero normal for two capsules on one axis (measured): the fallback takes over.
    result = coal.CollisionResult()
    coal.collide(coal.Capsule(0.05, 0.2), coal.Transform3s(), coal.Capsule(0.05, 0.2), coal.Transform3s(), coal.CollisionRequest(), result)
    assert not np.linalg.norm(result.getContact(0).normal) > 0.5
    contacts = detect([Collider("a", Capsule(0.05, 0.2)), Collider("b", Capsule(0.05, 0.2))])
    assert contacts
    for c in contacts:
        assert np.all(np.isfinite(c.point)) and np.linalg.norm(c.normal) == pytest.approx(1.0)
        assert abs(c.normal[2]) < 1e-12  # sideways, the direction of least overlap
        assert c.gap == pytest.approx(-0.1)  # two radii


# --------------------------------------------------------------------------- broad phase, filters, order


def test_two_hundred_balls_on_the_table_cost_two_hundred_queries() -> None:
    balls = [Collider(f"ball{i:03d}", Sphere(0.02), Pose((0.1 * (i % 20), 0.1 * (i // 20), 0.02))) for i in range(200)]
    colliders = [*balls, TABLE]
    assert candidate_pairs(colliders, MARGIN) == [(i, 200) for i in range(200)]  # each ball with the table only
    contacts = detect(colliders, margin=MARGIN)
    assert len(contacts) == 200
    assert [c.first for c in contacts] == [b.owner for b in balls]


def test_the_broad_phase_finds_every_pair_within_the_margin() -> None:
    rng = np.random.default_rng(3)
    colliders = [Collider(f"s{i}", Sphere(0.05), Pose(rng.uniform(0, 1, size=3))) for i in range(60)]
    centres = np.array([c.pose.position for c in colliders])
    distance = np.linalg.norm(centres[:, None] - centres[None], axis=2) - 0.1
    touching = {(i, j) for i in range(60) for j in range(i + 1, 60) if distance[i, j] <= 0.02}
    assert touching <= set(candidate_pairs(colliders, 0.02))
    found = {(c.first, c.second) for c in detect(colliders, margin=0.02)}
    assert found == {(f"s{i}", f"s{j}") for i, j in touching}


@pytest.mark.parametrize("count", [5, 40, 49, 150])
def test_the_sweep_gives_exactly_the_pairs_whose_boxes_meet(count: int) -> None:
    """Below and above the size where the broad phase switches from all pairs at once to the sweep."""
    rng = np.random.default_rng(count)
    shapes = [Box(rng.uniform(0.02, 0.2, size=3)), Sphere(0.05), Capsule(0.02, 0.1)]
    colliders = [Collider(f"c{i}", shapes[i % 3], Pose(rng.uniform(0, 1, size=3), _rotation(rng))) for i in range(count)]
    colliders.append(TABLE)
    corners = []
    for c in colliders[:-1]:
        local = {Box: lambda s: s.size / 2, Sphere: lambda s: np.full(3, s.radius), Capsule: lambda s: np.array([0.02, 0.02, 0.07])}
        half = np.abs(c.pose.rotation) @ local[type(c.shape)](c.shape)
        corners.append((c.pose.position - half - 0.005, c.pose.position + half + 0.005))
    expected = [
        (i, j)
        for i in range(count)
        for j in range(i + 1, count)
        if np.all(corners[i][0] <= corners[j][1]) and np.all(corners[j][0] <= corners[i][1])
    ]
    expected = sorted(expected + [(i, count) for i in range(count)])  # the table meets everything
    assert candidate_pairs(colliders, 0.01) == expected


@pytest.mark.parametrize("count", [3, 23, 48, 60])
def test_the_layout_gives_the_pairs_of_the_broad_phase(count: int) -> None:
    """The layout's pairs (one compiled loop where numba is installed) are the broad phase's, less what may not touch."""
    rng = np.random.default_rng(count)
    shapes = [Box(rng.uniform(0.02, 0.2, size=3)), Sphere(0.05), Capsule(0.02, 0.1)]
    colliders = [Collider(f"c{i % 7}", shapes[i % 3], Pose(rng.uniform(0, 0.6, size=3), _rotation(rng))) for i in range(count)]
    colliders.append(TABLE)
    layout = Layout([c.owner for c in colliders], [c.shape for c in colliders])
    positions = np.array([c.pose.position for c in colliders])
    rotations = np.array([c.pose.rotation for c in colliders])
    expected = [(i, j) for i, j in candidate_pairs(colliders, 0.01) if colliders[i].owner != colliders[j].owner]
    assert layout.pairs(positions, rotations, 0.01) == expected
    # Free bodies given as a set (decided for every pair at once) or as the same rule asked per pair: the same pairs.
    free = {"c1", "c4"}
    by_set = Layout([c.owner for c in colliders], [c.shape for c in colliders], free=free)
    by_rule = Layout([c.owner for c in colliders], [c.shape for c in colliders], lambda a, b: a in free or b in free)
    chosen = [(i, j) for i, j in expected if colliders[i].owner in free or colliders[j].owner in free]
    assert by_set.pairs(positions, rotations, 0.01) == by_rule.pairs(positions, rotations, 0.01) == chosen


def _face_down(rng: np.random.Generator, vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """A rotation that turns a random face of a convex hull to face straight down, then tilts it by up to 1e-4 rad."""
    a, b, c = vertices[triangles[rng.integers(len(triangles))]]
    outward = np.cross(b - a, c - a)
    outward /= np.linalg.norm(outward)
    axis = np.cross(outward, [0.0, 0.0, -1.0])
    angle = np.arctan2(np.linalg.norm(axis), outward @ [0.0, 0.0, -1.0])
    turn = _axis_angle(axis / max(np.linalg.norm(axis), 1e-300), angle) if np.linalg.norm(axis) > 1e-12 else np.eye(3)
    tilt = rng.normal(size=3)
    return _axis_angle(tilt / np.linalg.norm(tilt), rng.uniform(0.0, 1e-4)) @ turn


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def _coal_patch_corners(shape: Box | Convex, pose: Pose, margin: float) -> np.ndarray:
    """The corners of coal's own contact patch for a polytope on the table ``z <= 0``, projected on it (the reference)."""
    geometry = coal.Box(*shape.size) if isinstance(shape, Box) else _coal_convex(shape)
    placed, table = coal.Transform3s(pose.rotation, pose.position), coal.Transform3s()
    request, result = coal.CollisionRequest(), coal.CollisionResult()
    request.security_margin = margin
    coal.collide(geometry, placed, coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0), table, request, result)
    patch_request = coal.ContactPatchRequest(1, 8, margin - result.getContact(0).penetration_depth + 1e-12)
    patches = coal.ContactPatchResult(patch_request)
    coal.computeContactPatch(geometry, placed, coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0), table, result, patch_request, patches)
    patch = patches.getContactPatch(0)
    return np.array([patch.getPointShape1(k) for k in range(patch.size())])[:, :2]


def _coal_convex(shape: Convex) -> object:
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(shape.triangles), len(shape.vertices))
    model.addVertices(np.array(shape.vertices))
    model.addTriangles(np.array(shape.triangles))
    model.endModel()
    model.buildConvexRepresentation(False)
    return model.convex


@pytest.mark.parametrize("seed", range(12))
def test_a_polytope_face_down_on_the_table_touches_at_the_corners_of_coals_patch(seed: int) -> None:
    """Polytopes (boxes, random hulls) resting on a face tilted within the margin: the corners detection reports
    (from the vertices, without coal) are those of coal's contact patch, each with its own gap."""
    rng = np.random.default_rng(seed)
    shape: Box | Convex
    if seed % 2:
        shape = Box(rng.uniform(0.02, 0.2, size=3))
        vertices = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * shape.size / 2
        rotation = _face_down_box(rng)
    else:
        shape = Convex(rng.normal(size=(12, 3)) * 0.05)
        vertices = shape.vertices
        rotation = _face_down(rng, vertices, shape.triangles)
    lowest = float(np.min(vertices @ rotation.T, axis=0)[2])
    pose = Pose(rng.uniform(-0.1, 0.1, size=3) * [1, 1, 0] + [0.0, 0.0, -lowest + rng.uniform(-MARGIN, MARGIN) / 4], rotation)
    found = detect([Collider("part", shape, pose), TABLE], margin=MARGIN)
    world = vertices @ rotation.T + pose.position
    heights = world[:, 2]
    for contact in found:
        nearest = np.argmin(np.linalg.norm(world[:, :2] - contact.point[:2], axis=1))
        assert contact.gap == pytest.approx(heights[nearest], abs=EXACT)  # each corner's own gap
        assert contact.normal == pytest.approx([0.0, 0.0, 1.0])
    reference = _coal_patch_corners(shape, pose, MARGIN)
    distinct = [p for k, p in enumerate(reference) if all(np.linalg.norm(p - q) > 1e-7 for q in reference[:k])]
    _same_points(_points(found)[:, :2], np.array(distinct), tol=1e-7)


def _face_down_box(rng: np.random.Generator) -> np.ndarray:
    """A box turned by quarter turns onto a random face, tilted by up to 1e-4 rad about a random axis."""
    turns = [np.eye(3), _axis_angle(np.array([1.0, 0.0, 0.0]), np.pi / 2), _axis_angle(np.array([0.0, 1.0, 0.0]), np.pi / 2)]
    tilt = rng.normal(size=3)
    return _axis_angle(tilt / np.linalg.norm(tilt), rng.uniform(0.0, 1e-4)) @ turns[int(rng.integers(3))]


def test_pairs_the_caller_excludes_and_shapes_of_one_owner_never_touch() -> None:
    box = Collider("box", Box(SIZE), Pose((0.0, 0.0, 0.15)))
    assert detect([box, TABLE], pairs=lambda a, b: {a, b} != {"box", "table"}) == []
    assert detect([box, Collider("box", Halfspace())]) == []


def test_the_output_is_sorted_and_the_same_every_time() -> None:
    first = detect(_scene(Pose()))
    keys = [(c.first, c.second, tuple(c.point)) for c in first]
    assert keys == sorted(keys)
    assert _same_list(first, detect(_scene(Pose())))


def _same_list(a: list[ContactPoint], b: list[ContactPoint]) -> bool:
    return len(a) == len(b) and all(
        (x.first, x.second, x.gap) == (y.first, y.second, y.gap) and np.array_equal(x.point, y.point) and np.array_equal(x.normal, y.normal)
        for x, y in zip(a, b, strict=True)
    )


# --------------------------------------------------------------------------- poses


def test_poses_from_rpy_and_from_a_quaternion_agree_and_compose() -> None:
    half = np.pi / 4  # 90 degrees about z
    by_rpy = Pose.from_rpy((1, 2, 3), (0.0, 0.0, np.pi / 2))
    by_quaternion = Pose.from_quaternion((1, 2, 3), (np.cos(half), 0.0, 0.0, np.sin(half)))
    np.testing.assert_allclose(by_rpy.matrix(), by_quaternion.matrix(), atol=1e-15)
    np.testing.assert_allclose(by_rpy.apply([1.0, 0.0, 0.0]), [1, 3, 3], atol=1e-15)
    np.testing.assert_allclose(by_rpy.compose(by_rpy.inverse()).matrix(), np.eye(4), atol=1e-15)
    np.testing.assert_allclose(by_rpy.compose(by_quaternion).matrix(), by_rpy.matrix() @ by_quaternion.matrix(), atol=1e-15)
    nearly = Pose.from_quaternion((0, 0, 0), (1.0005, 0.0, 0.0, 0.0))  # normalised: within 1e-3 of unit
    np.testing.assert_allclose(nearly.rotation, np.eye(3), atol=1e-15)


def test_shapes_of_coal_geometries_and_pickled_shapes() -> None:
    assert np.array_equal(shape_from_coal(coal.Box(1.0, 2.0, 3.0)).size, [1, 2, 3])  # type: ignore[union-attr]
    cylinder = shape_from_coal(coal.Cylinder(0.1, 0.4))
    assert isinstance(cylinder, Cylinder) and (cylinder.radius, cylinder.length) == (0.1, 0.4)
    assert isinstance(shape_from_coal(coal.Capsule(0.1, 0.4)), Capsule)
    link = Collider("link", coal.Sphere(0.05), Pose((0.0, 0.0, 0.05)))  # as a Pinocchio geometry comes
    assert isinstance(link.shape, Sphere)
    assert len(detect([link, TABLE])) == 1
    restored = pickle.loads(pickle.dumps(link.shape))  # the coal geometry kept with it is not pickled
    assert restored.radius == 0.05 and len(detect([Collider("link", restored), TABLE], margin=0.1)) == 1


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: Box((0.1, -0.2, 0.3), field="bodies.cube.shape.box"), "bodies.cube.shape.box.size"),
        (lambda: Box((0.1, 0.2), field="bodies.cube.shape.box"), "bodies.cube.shape.box.size"),
        (lambda: Sphere(0.0, field="movers.finger.shape.sphere"), "movers.finger.shape.sphere.radius"),
        (lambda: Cylinder(0.1, float("nan")), "cylinder.length"),
        (lambda: Capsule(-1.0, 0.1), "capsule.radius"),
        (lambda: Halfspace((0.0, 0.0, 2.0)), "halfspace.normal"),
        (lambda: Pose.from_quaternion((0, 0, 0), (1.0, 1.0, 0.0, 0.0), field="bodies.cube.pose"), "bodies.cube.pose.quaternion"),
        (lambda: Pose((0, 0, 0), np.diag([1.0, 1.0, -1.0])), "pose.rotation"),
        (lambda: Pose((0, 0, 0), np.eye(3) * 1.01), "pose.rotation"),
        (lambda: Pose((0, float("inf"), 0)), "pose.position"),
        (lambda: Convex([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]), "convex.points"),
        (lambda: Mesh("/nonexistent/cube.obj", field="bodies.cube.shape.mesh"), "bodies.cube.shape.mesh.path"),
        (lambda: Mesh(__file__, scale=0.0), "mesh.scale"),
        (lambda: Collider("cube", coal.Cone(0.1, 0.2), field="bodies.cube"), "bodies.cube.shape"),
        (lambda: detect([TABLE], margin=-1.0), "margin"),
    ],
)
def test_bad_input_is_a_scene_error_naming_the_field(build, field: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(SceneError) as caught:
        build()
    assert caught.value.field == field
    assert field in str(caught.value)


def test_a_malformed_mesh_file_is_a_scene_error_naming_the_file(tmp_path: Path) -> None:
    folder = tmp_path / ("a-folder-deep-enough-that-the-whole-path-is-longer-than-the-message-shows" * 2)
    folder.mkdir()
    for name, text in [("junk.obj", "this is no mesh\n"), ("empty.stl", ""), ("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")]:
        path = folder / name
        path.write_text(text, encoding="utf-8")
        with pytest.raises(SceneError) as caught:
            Mesh(path, field="bodies.cube.shape.mesh")
        assert caught.value.field == "bodies.cube.shape.mesh.path"
        assert name in str(caught.value)


# --------------------------------------------------------------------------- coal stays optional


def test_importing_the_package_and_its_adapters_does_not_import_coal() -> None:
    code = "import sys, quasistatic, quasistatic.adapters; print('coal' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "False"


def test_without_coal_detection_says_how_to_install_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "coal", None)  # import coal now raises ImportError
    with pytest.raises(BackendUnavailableError, match=r"pip install 'quasistatic\[robots\]'"):
        detect([TABLE])
