"""Planar worlds of shapes (dimension: 2): detection against hand-derived contacts, the explicit twin, the command
line in a subprocess, bad input, and simulations against answers derived by hand. Nothing here needs coal."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.adapters import ContactDetection, Disk, HalfPlane, PlanarBody, PlanarMover, PlanarWorld, Polygon, Rectangle, planar_pose
from quasistatic.errors import SceneError
from quasistatic.sim import advance_pose, simulate

ROOT = Path(__file__).resolve().parents[1]
PUSH = ROOT / "examples" / "sim" / "push_planar.yaml"
TIP = ROOT / "examples" / "sim" / "tip_box_planar.yaml"
SLOPE = ROOT / "examples" / "push_up_slope.yaml"
SLOPE_SHAPES = ROOT / "examples" / "push_up_slope_shapes.yaml"
SCRIPT = Path(sys.executable).with_name("quasistatic")
MARGIN = 1e-3


def world(body_shape: Any, body_pose: Any, other_shape: Any, other_pose: Any = None, margin: float = MARGIN) -> PlanarWorld:
    """One free body and one fixed mover, with an explicit margin."""
    return PlanarWorld(
        bodies=(PlanarBody("a", 1.0, body_shape, body_pose),),
        movers=(PlanarMover("b", other_shape, other_pose or planar_pose()),),
        detection=ContactDetection(margin=margin),
    )


def found(w: PlanarWorld) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(point, normal into the body, gap) of each contact, sorted by x then y."""
    detection = w.detect()
    rows = [(np.array(c.point), np.array(c.normal), g) for c, g in zip(detection.contacts, detection.gaps, strict=True)]
    return sorted(rows, key=lambda row: (round(row[0][0], 9), round(row[0][1], 9)))


def assert_contacts(w: PlanarWorld, expected: list[tuple[list[float], list[float], float]]) -> None:
    got = found(w)
    assert len(got) == len(expected), got
    for (point, normal, gap), (want_point, want_normal, want_gap) in zip(got, expected, strict=True):
        np.testing.assert_allclose(point, want_point, atol=1e-12)
        np.testing.assert_allclose(normal, want_normal, atol=1e-12)
        assert gap == pytest.approx(want_gap, abs=1e-12)


FLOOR = HalfPlane([0.0, 1.0], 0.0)


# --------------------------------------------------------------------------- detection, by hand


def test_disk_on_a_halfplane_touches_at_one_point_below_its_centre() -> None:
    # radius 0.1 at height 0.1004: gap 4e-4 (inside the margin), the point midway between disk and floor
    assert_contacts(world(Disk(0.1), planar_pose([0.3, 0.1004]), FLOOR), [([0.3, 0.0002], [0.0, 1.0], 4e-4)])
    assert found(world(Disk(0.1), planar_pose([0.3, 0.1015]), FLOOR)) == []  # 1.5e-3 apart: beyond the margin


def test_box_flat_on_a_halfplane_gives_its_two_bottom_corners() -> None:
    assert_contacts(world(Rectangle([0.2, 0.1]), planar_pose([0.0, 0.05]), FLOOR), [([-0.1, 0.0], [0, 1], 0.0), ([0.1, 0.0], [0, 1], 0.0)])


def test_a_tilted_box_on_a_halfplane_touches_at_its_lowest_corner_only() -> None:
    angle = 0.3  # turned counter-clockwise by 0.3 rad, corner (-0.1, -0.05) is the lowest; put it at height 0
    corner = np.array([-0.1 * math.cos(angle) + 0.05 * math.sin(angle), -0.1 * math.sin(angle) - 0.05 * math.cos(angle)])
    centre = np.array([0.0, -corner[1]])
    assert_contacts(world(Rectangle([0.2, 0.1]), planar_pose(centre, angle), FLOOR), [([corner[0], 0.0], [0.0, 1.0], 0.0)])


def test_a_tilted_halfplane_turns_the_normal() -> None:
    # the floor as a mover turned by 30 degrees; a disk resting on it along its normal
    n = np.array([-math.sin(math.pi / 6), math.cos(math.pi / 6)])
    w = world(Disk(0.05), planar_pose(0.05 * n + 0.2 * np.array([n[1], -n[0]])), FLOOR, planar_pose([0, 0], math.pi / 6))
    ((point, normal, gap),) = found(w)
    np.testing.assert_allclose(normal, n, atol=1e-12)
    np.testing.assert_allclose(point, 0.2 * np.array([n[1], -n[0]]), atol=1e-12)
    assert gap == pytest.approx(0.0, abs=1e-12)


def test_box_face_on_box_face_gives_the_ends_of_the_common_edge() -> None:
    # a narrow box on a wide one: the narrow box's bottom corners
    narrow_on_wide = world(Rectangle([0.2, 0.1]), planar_pose([0.05, 0.15]), Rectangle([1.0, 0.2]), planar_pose([0.0, 0.0]))
    assert_contacts(narrow_on_wide, [([-0.05, 0.1], [0, 1], 0.0), ([0.15, 0.1], [0, 1], 0.0)])
    # a wide box on a narrow post: the post's top corners (the incident edge clipped to the reference face)
    wide_on_narrow = world(Rectangle([1.0, 0.1]), planar_pose([0.2, 0.15]), Rectangle([0.1, 0.2]), planar_pose([0.0, 0.0]))
    assert_contacts(wide_on_narrow, [([-0.05, 0.1], [0, 1], 0.0), ([0.05, 0.1], [0, 1], 0.0)])


def test_boxes_overlapping_report_a_negative_gap() -> None:
    overlap = world(Rectangle([0.2, 0.1]), planar_pose([0.0, 0.1498]), Rectangle([1.0, 0.2]), planar_pose([0.0, 0.0]))
    assert_contacts(overlap, [([-0.1, 0.0999], [0, 1], -2e-4), ([0.1, 0.0999], [0, 1], -2e-4)])


def test_disk_against_disk_along_the_line_of_centres() -> None:
    # centres 0.3 apart along (3, 4)/5, radii 0.1 and 0.1995: gap 5e-4
    direction = np.array([0.6, 0.8])
    w = world(Disk(0.1), planar_pose(0.3 * direction), Disk(0.1995), planar_pose([0.0, 0.0]))
    midpoint = (0.1995 + 0.5 * 5e-4) * direction
    assert_contacts(w, [(midpoint.tolist(), direction.tolist(), 5e-4)])


def test_disk_against_a_box_face_and_a_box_corner() -> None:
    beside = world(Disk(0.01), planar_pose([0.06, 0.02]), Rectangle([0.1, 0.1]), planar_pose([0.0, 0.0]))
    assert_contacts(beside, [([0.05, 0.02], [1.0, 0.0], 0.0)])
    d = 0.01 + 2e-4  # centre on the corner's diagonal: the normal along it
    at_corner = world(Disk(0.01), planar_pose([0.05 + d / math.sqrt(2), 0.05 + d / math.sqrt(2)]), Rectangle([0.1, 0.1]))
    u = np.array([1.0, 1.0]) / math.sqrt(2)
    assert_contacts(at_corner, [((np.array([0.05, 0.05]) + 1e-4 * u).tolist(), u.tolist(), 2e-4)])


def test_triangle_vertex_on_a_box_face_is_one_point() -> None:
    # a downward triangle whose tip is 3e-4 above the top face of a box
    triangle = Polygon([[-0.05, 0.1], [0.05, 0.1], [0.0, 0.0]])  # clockwise on purpose: kept counter-clockwise
    w = world(triangle, planar_pose([0.01, 0.1003]), Rectangle([0.4, 0.2]), planar_pose([0.0, 0.0]))
    assert_contacts(w, [([0.01, 0.10015], [0.0, 1.0], 3e-4)])


def test_the_default_margin_is_relative_to_the_bodies_size() -> None:
    # default margin: 1e-4 of the largest body's bounding radius (0.1 here): 1e-5
    near = PlanarWorld((PlanarBody("a", 1.0, Disk(0.1), planar_pose([0.0, 0.100009])),), (PlanarMover("b", FLOOR),))
    far = PlanarWorld((PlanarBody("a", 1.0, Disk(0.1), planar_pose([0.0, 0.100011])),), (PlanarMover("b", FLOOR),))
    assert len(near.detect().contacts) == 1
    detection = far.detect()
    assert detection.contacts == ()
    assert detection.isolated["a"][0] == "b" and detection.isolated["a"][1] == pytest.approx(1.1e-5, rel=1e-6)


def scene_data(length: float = 1.0, mass: float = 1.0, turn: float = 0.0, shift: tuple[float, float] = (0.0, 0.0)) -> dict[str, Any]:
    """The planar push's file, in other units (``length`` per metre, ``mass`` per kg) and rigidly moved as a whole."""
    c, s = math.cos(turn), math.sin(turn)

    def placed(x: float, y: float) -> list[float]:
        return [length * (c * x - s * y + shift[0]), length * (s * x + c * y + shift[1])]

    def finger(height: float) -> dict[str, Any]:
        velocity = [0.01 * c * length, 0.01 * s * length, 0.0]
        return {"shape": {"disk": 0.005 * length}, "pose": {"position": placed(-0.055, height), "angle": turn}, "twist": velocity}

    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [9.81 * length * s, -9.81 * length * c],
        "bodies": {
            "box": {"mass": mass, "shape": {"box": [0.1 * length, 0.1 * length]}, "pose": {"position": placed(0.0, 0.05), "angle": turn}}
        },
        "movers": {
            "table": {"shape": {"halfplane": {"normal": [-s, c], "offset": 0.0}}, "pose": {"position": placed(0.0, 0.0)}},
            "finger_low": finger(0.03),
            "finger_high": finger(0.07),
        },
        "contact_detection": {
            "friction": {
                "default": 0.5,
                "pairs": [{"between": ["box", "finger_low"], "mu": 0.0}, {"between": ["box", "finger_high"], "mu": 0.0}],
            }
        },
    }


def test_detection_and_answer_are_invariant_under_a_rigid_motion_of_the_world() -> None:
    plain = qs.load_world(scene_data())
    turn, shift = 0.7, (0.3, -1.2)
    moved = qs.load_world(scene_data(turn=turn, shift=shift))
    assert isinstance(plain, PlanarWorld) and isinstance(moved, PlanarWorld)
    rotation = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    before, after = plain.detect(), moved.detect()
    assert len(before.contacts) == len(after.contacts) == 4
    for c, d, g, h in zip(before.contacts, after.contacts, before.gaps, after.gaps, strict=True):
        assert (c.body, c.other) == (d.body, d.other)
        np.testing.assert_allclose(d.point, rotation @ c.point + shift, atol=1e-12)
        np.testing.assert_allclose(d.normal, rotation @ c.normal, atol=1e-12)
        assert h == pytest.approx(g, abs=1e-12)
    a, b = qs.solve(plain), qs.solve(moved)
    assert a.status == b.status == "solved" and a.certified and b.certified
    np.testing.assert_allclose(b.motion.twists["box"][:2], rotation @ a.motion.twists["box"][:2], atol=1e-12)


def test_millimetres_and_grams_give_the_same_contacts_and_answer() -> None:
    metres, millimetres = qs.load_world(scene_data()), qs.load_world(scene_data(length=1000.0, mass=1000.0))
    a, b = metres.detect(), millimetres.detect()
    assert len(a.contacts) == len(b.contacts) == 4
    for c, d in zip(a.contacts, b.contacts, strict=True):
        np.testing.assert_allclose(d.point, 1000.0 * c.point, atol=1e-9)
        np.testing.assert_allclose(d.normal, c.normal, atol=1e-12)
    x, y = qs.solve(metres), qs.solve(millimetres)
    assert x.status == y.status == "solved"
    np.testing.assert_allclose(y.motion.twists["box"], x.motion.twists["box"] * [1000.0, 1000.0, 1.0], atol=1e-9)


def test_listed_contacts_add_to_the_found_ones() -> None:
    data = scene_data()
    data["contacts"] = [{"body": "box", "other": "table", "point": [0.0, 0.0], "normal": [0.0, 1.0], "mu": 0.5}]
    w = qs.load_world(data)
    scene = w.scene()
    assert len(scene.contacts) == 5 and scene.dimension == 2
    np.testing.assert_allclose(scene.contacts[-1].point, [0.0, 0.0])  # after the 4 found ones
    assert qs.solve(w).status == "solved"


def test_a_planar_world_built_in_python() -> None:
    w = qs.PlanarWorld(
        bodies=(PlanarBody("box", 1.0, Rectangle([0.1, 0.1]), qs.planar_pose([0.0, 0.05])),),
        movers=(PlanarMover("floor", FLOOR), PlanarMover("wall", HalfPlane([1.0, 0.0], 0.0), qs.planar_pose([0.05, 0.0], math.pi))),
        detection=ContactDetection(mu=0.5),
    )
    found = [(c.other, tuple(np.round(c.normal, 12) + 0.0)) for c in w.detect().contacts]  # the wall turned by pi faces -x
    assert sorted(found) == [("floor", (0.0, 1.0))] * 2 + [("wall", (-1.0, 0.0))] * 2
    solution = qs.solve(w)
    assert solution.status == "solved" and solution.certified  # at rest in the corner
    np.testing.assert_allclose(solution.motion.twists["box"], 0.0, atol=1e-12)


# --------------------------------------------------------------------------- the explicit twin


def test_the_planar_twin_of_push_up_slope_gives_the_same_answer() -> None:
    listed, shaped = qs.solve(qs.load_scene(SLOPE)), qs.solve(qs.load_scene(SLOPE_SHAPES))
    assert listed.status == shaped.status == "solved" and shaped.certified
    np.testing.assert_allclose(shaped.motion.twists["block"], listed.motion.twists["block"], atol=1e-12)
    np.testing.assert_allclose(shaped.motion.twists["block"], [0.009396926207859, 0.003420201433257, 0.0], atol=1e-12)

    def by_point(solution: qs.Solution) -> list[tuple[tuple[float, ...], str, str, np.ndarray]]:
        rows = [
            (tuple(np.round(c.point, 9)), r.other, r.mode, r.force)
            for c, r in zip(solution.scene.contacts, solution.motion.contacts, strict=True)
        ]
        return sorted(rows, key=lambda row: row[0])

    for (p, other, mode, force), (q, other2, mode2, force2) in zip(by_point(listed), by_point(shaped), strict=True):
        assert p == q and other == other2 and mode == mode2
        np.testing.assert_allclose(force2, force, atol=1e-9)
    pusher = next(r for r in shaped.motion.contacts if r.other == "pusher")
    assert pusher.normal_force == pytest.approx(9.81 * (math.sin(math.radians(20)) + 0.5 * math.cos(math.radians(20))), rel=1e-9)


# --------------------------------------------------------------------------- the command line, as a user runs it


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, timeout=300, check=False)


def test_solve_a_planar_scene_of_shapes_from_the_command_line() -> None:
    result = run("solve", str(PUSH), "--json")
    assert result.returncode == 0, result.stderr
    answer = json.loads(result.stdout)
    assert answer["status"] == "solved" and answer["certified"] is True
    np.testing.assert_allclose(answer["bodies"]["box"]["twist"], [0.01, 0.0, 0.0], atol=1e-12)
    modes = {(c["other"], c["mode"]) for c in answer["contacts"]}
    assert modes == {("table", "sliding"), ("finger_low", "rolling"), ("finger_high", "rolling")}
    # by hand: the totals are fixed (N1 + N2 = m g, F1 + F2 = mu m g), their split is not
    assert answer["forces_indeterminate"] is True
    table = [c for c in answer["contacts"] if c["other"] == "table"]
    fingers = [c for c in answer["contacts"] if c["other"] != "table"]
    assert sum(c["normal_force"] for c in table) == pytest.approx(9.81, rel=1e-9)
    assert sum(c["normal_force"] for c in fingers) == pytest.approx(0.5 * 9.81, rel=1e-9)
    assert fingers[0]["normal_force_range"] == pytest.approx([0.0, 0.5 * 9.81], abs=1e-9)
    contacts = run("contacts", str(PUSH))
    assert contacts.returncode == 0 and "4 contacts found" in contacts.stdout


def test_simulate_a_planar_scene_from_the_command_line(tmp_path: Path) -> None:
    out = tmp_path / "push.jsonl"
    result = run("simulate", str(PUSH), "--duration", "0.5", "--dt", "0.05", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "every step certified" in result.stdout
    trajectory = qs.Trajectory.load(out)
    np.testing.assert_allclose(trajectory.positions("box")[-1], [0.005, 0.05, 0.0], atol=1e-12)


def test_plot_draws_a_planar_world(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    result = run("plot", str(PUSH), "--output", str(tmp_path / "push.png"))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "push.png").stat().st_size > 0 and "solved" in result.stdout


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text("quasistatic: 1\ndimension: 2\n" + text)
    return path


FLOOR_FILE = "movers: {floor: {shape: {halfplane: {normal: [0, 1]}}}}\n"
BAD = {
    "non-convex polygon": (
        "bodies: {a: {mass: 1, shape: {polygon: [[0, 0], [1, 0], [0.2, 0.2], [0, 1]]}}}\n" + FLOOR_FILE,
        "bodies.a.shape.polygon",
        "not convex",
    ),
    "zero-size box": (
        "bodies: {a: {mass: 1, shape: {box: [0.1, 0.0]}}}\n" + FLOOR_FILE,
        "bodies.a.shape.box",
        "both > 0",
    ),
    "NaN angle": (
        "bodies: {a: {mass: 1, shape: {disk: 0.1}, pose: {position: [0, 0.1], angle: .nan}}}\n" + FLOOR_FILE,
        "bodies.a.pose.angle",
        "finite",
    ),
    "urdf in 2-D": (
        "bodies: {a: {mass: 1, shape: {disk: 0.1}}}\nrobots: {hand: {urdf: hand.urdf}}\n",
        "robots.hand.urdf",
        "URDF robots are 3-D",
    ),
    "3-D shape in 2-D": ("bodies: {a: {mass: 1, shape: {sphere: 0.1}}}\n", "bodies.a.shape.sphere", "a 3-D shape"),
    "halfplane body": ("bodies: {a: {mass: 1, shape: {halfplane: {normal: [0, 1]}}}}\n", "bodies.a.shape.halfplane", "bounded shape"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_planar_input_is_one_error_line_naming_the_field(tmp_path: Path, case: str) -> None:
    text, field, words = BAD[case]
    result = run("solve", str(write(tmp_path, text)))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and field in lines[0] and words in lines[0], result.stderr
    assert "Traceback" not in result.stderr


def test_a_planar_shape_in_a_3d_scene_names_the_dimension() -> None:
    with pytest.raises(SceneError, match="dimension: 2"):
        qs.load_world({"quasistatic": 1, "bodies": {"a": {"mass": 1, "shape": {"disk": 0.1}}}})


def test_planar_worlds_need_no_coal() -> None:
    # coal made unimportable: a planar scene still loads, solves and simulates (the default install)
    code = (
        "import sys; sys.modules['coal'] = None; sys.modules['pinocchio'] = None\n"
        "import quasistatic as qs\n"
        f"s = qs.solve(qs.load_world({str(PUSH)!r})); t = qs.simulate({str(PUSH)!r}, 0.2, 0.05)\n"
        "print(s.status, t.status)\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["solved", "completed"]


# --------------------------------------------------------------------------- simulation


def test_a_planar_step_is_the_exact_se2_screw() -> None:
    # a quarter turn about the point (1, 0) carries the origin to (1, -1), turned by 90 degrees
    pose = advance_pose(planar_pose([0.0, 0.0]), np.array([0.0, 0.0, math.pi / 2]), np.array([1.0, 0.0]), 1.0)
    np.testing.assert_allclose(pose.position, [1.0, -1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(pose.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    # the same as the 3-D screw of the embedded twist
    twist, point = np.array([0.3, -0.2, 1.7]), np.array([0.4, 0.1])
    planar = advance_pose(planar_pose([0.2, 0.5], 0.3), twist, point, 0.37)
    spatial = advance_pose(planar_pose([0.2, 0.5], 0.3), np.array([0.3, -0.2, 0, 0, 0, 1.7]), np.array([0.4, 0.1, 0.0]), 0.37)
    np.testing.assert_allclose(planar.position, spatial.position, atol=1e-15)
    np.testing.assert_allclose(planar.rotation, spatial.rotation, atol=1e-15)


def test_the_planar_push_keeps_the_box_with_the_fingers_certified_at_every_step() -> None:
    trajectory = simulate(PUSH, duration=2.0, dt=0.05)
    assert trajectory.status == "completed"
    assert all(s.status == "solved" and s.certified for s in trajectory.steps)
    box, finger = trajectory.positions("box"), trajectory.positions("finger_low")
    np.testing.assert_allclose(box[:, 0] - finger[:, 0], 0.055, atol=1e-12)  # the face stays on the fingertip
    np.testing.assert_allclose(box[:, 1], 0.05, atol=1e-12)
    np.testing.assert_allclose(box[-1], [0.02, 0.05, 0.0], atol=1e-12)
    angles = np.arctan2(trajectory.rotations("box")[:, 1, 0], trajectory.rotations("box")[:, 0, 0])
    np.testing.assert_allclose(angles, 0.0, atol=1e-12)


def test_the_planar_tipping_box_falls_at_atan_w_over_h() -> None:
    w, tall, h, r, v = 0.1, 0.2, 0.15, 0.005, 0.01
    trajectory = simulate(TIP, duration=8.0, dt=0.05)
    assert trajectory.status == "unstable"
    assert all(s.certified for s in trajectory.steps)
    rotations = trajectory.rotations("box")
    theta = -np.arctan2(rotations[:, 1, 0], rotations[:, 0, 0])  # it turns clockwise
    assert theta[-1] == pytest.approx(math.atan(w / tall), abs=math.radians(0.01))
    # by hand: t(theta) = (h tan theta - (w + r)(sec theta - 1)) / v, the fingertip centre staying r from the face
    expected = (h * np.tan(theta) - (w + r) * (1 / np.cos(theta) - 1)) / v
    times = np.array([s.time for s in trajectory.steps])
    np.testing.assert_allclose(times, expected, atol=0.01)
