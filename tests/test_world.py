"""Scenes described by shapes and URDF robots: contacts found, solved like their hand-written twins.

Every scene here has a twin with its contacts written by hand (or derived by hand), and the two must
give the same Solution; the command line is run as a user runs it, in a subprocess.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("coal")
pytest.importorskip("pinocchio")

import quasistatic as qs  # noqa: E402
from quasistatic.model.io import scene_to_dict  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BOX_PUSH = EXAMPLES / "box_push_shapes.yaml"
HAND = EXAMPLES / "robots" / "planar_hand.yaml"
PANDA = EXAMPLES / "robots" / "panda_gripper.yaml"
SCRIPT = Path(sys.executable).with_name("quasistatic")


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    environment = {**os.environ, "COLUMNS": "200"}
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, timeout=120, env=environment, check=False)


def _same_answer(first: qs.Solution, second: qs.Solution, length: float = 1.0) -> None:
    """Same status, twists, forces and modes (twists' linear parts and forces in the units of each scene)."""
    assert first.status == second.status
    assert first.motion is not None and second.motion is not None
    for name, twist in first.motion.twists.items():
        other = second.motion.twists[name]
        assert np.allclose(twist[:3] * length, other[:3], atol=1e-9 * length), name
        assert np.allclose(twist[3:], other[3:], atol=1e-9), name

    # The same contacts, found in another order: compare them as sorted (other, mode, force) rows.
    # Forces scale with lengths when masses stay (kg mm/s^2 against kg m/s^2).
    def rows(solution: qs.Solution, scale: float) -> list[tuple[str, str, tuple[float, ...]]]:
        assert solution.motion is not None
        return sorted((c.other, c.mode, tuple(np.round(c.force * scale, 6) + 0.0)) for c in solution.motion.contacts)

    assert rows(first, 1.0) == rows(second, 1.0 / length)


def _box_push_by_hand() -> qs.Scene:
    """The twin with its five contacts written by hand."""
    return qs.load_scene(EXAMPLES / "box_push_3d.yaml")


def _by_pair(scene: qs.Scene) -> list[tuple[str, str, tuple[float, ...]]]:
    return sorted((c.body, c.other, tuple(np.round(c.point, 12))) for c in scene.contacts)


def test_box_push_finds_the_contacts_written_by_hand() -> None:
    found = qs.load_scene(BOX_PUSH)
    by_hand = _box_push_by_hand()
    assert _by_pair(found) == _by_pair(by_hand)
    for contact in found.contacts:
        twin = next(c for c in by_hand.contacts if c.other == contact.other and np.allclose(c.point, contact.point))
        assert np.allclose(contact.normal, twin.normal, atol=1e-12) and contact.mu == twin.mu


def test_box_push_solves_like_its_hand_written_twin() -> None:
    """box_push_shapes.yaml finds the contacts box_push_3d.yaml lists, and gives its answer."""
    found = qs.solve(qs.load_scene(BOX_PUSH))
    twin = qs.solve(qs.load_scene(EXAMPLES / "box_push_3d.yaml"))
    assert found.status == twin.status == "ambiguous" and found.certified and twin.certified
    _same_answer(found, twin)
    assert len(found.solutions) == len(twin.solutions)
    for ours, theirs in zip(found.solutions, twin.solutions, strict=True):
        assert sorted(map(tuple, (t["box"] for t in ours.extreme_twists))) == sorted(map(tuple, (t["box"] for t in theirs.extreme_twists)))


def _scaled(data: dict[str, Any], factor: float) -> dict[str, Any]:
    """The box push with every length multiplied by ``factor`` (metres to millimetres: 1000)."""
    data = json.loads(json.dumps(data))
    data["bodies"]["box"]["shape"]["box"] = [x * factor for x in data["bodies"]["box"]["shape"]["box"]]
    data["bodies"]["box"]["pose"]["position"] = [x * factor for x in data["bodies"]["box"]["pose"]["position"]]
    finger = data["movers"]["finger"]
    finger["shape"]["sphere"] *= factor
    finger["pose"]["position"] = [x * factor for x in finger["pose"]["position"]]
    finger["twist"] = [x * factor for x in finger["twist"][:3]] + finger["twist"][3:]
    data["gravity"] = [0.0, 0.0, -9.81 * factor]
    return data


def _box_push_data() -> dict[str, Any]:
    import yaml

    data: dict[str, Any] = yaml.safe_load(BOX_PUSH.read_text(encoding="utf-8"))
    return data


def test_millimetres_give_the_same_answer_as_metres() -> None:
    metres = qs.solve(qs.load_scene(_box_push_data()))
    millimetres = qs.solve(qs.load_scene(_scaled(_box_push_data(), 1000.0)))
    _same_answer(metres, millimetres, length=1000.0)


def test_detection_turns_with_the_world_frame() -> None:
    """The same scene seen from a turned and shifted world frame: contacts move with it, the answer turns with it."""
    turn = qs.Pose.from_rpy([0.3, -0.2, 0.1], [0.4, -0.3, 1.1])
    data = _box_push_data()

    def moved(entry: dict[str, Any]) -> dict[str, Any]:
        pose = turn.compose(qs.Pose(entry["pose"]["position"]))
        entry["pose"] = {"position": pose.position.tolist(), "rotation": {"matrix": pose.rotation.tolist()}}
        return entry

    moved(data["bodies"]["box"])
    moved(data["movers"]["finger"])
    data["movers"]["finger"]["twist"] = (turn.rotation @ [0.01, 0, 0]).tolist() + [0.0, 0.0, 0.0]
    up = turn.rotation[:, 2]
    data["movers"]["table"]["shape"]["halfspace"] = {"normal": up.tolist(), "offset": float(up @ turn.position)}
    data["gravity"] = (turn.rotation @ [0, 0, -9.81]).tolist()
    turned = qs.load_scene(data)
    plain = qs.load_scene(_box_push_data())
    expected = sorted(tuple(np.round(turn.apply(c.point), 9)) for c in plain.contacts)
    assert sorted(tuple(np.round(c.point, 9)) for c in turned.contacts) == expected
    solution, before = qs.solve(turned), qs.solve(plain)
    assert solution.status == before.status == "ambiguous" and len(solution.solutions) == len(before.solutions)
    # The continuum's listed extremes are LP vertices along the frame's axes, so only the verdict is compared.
    assert all(m.audit.passed for m in solution.solutions)


def test_a_body_touching_nothing_is_unstable_and_the_message_names_the_gap() -> None:
    data = _box_push_data()
    data["bodies"]["box"]["pose"]["position"] = [0.0, 0.0, 0.07]  # 2 cm above the table
    data["movers"]["finger"]["pose"]["position"] = [-0.1, 0.0, 0.07]
    solution = qs.solve(qs.load_world(data))  # type: ignore[arg-type]
    assert solution.status == "unstable"
    assert "nearest surface" in solution.message and "0.02" in solution.message


def test_contacts_json_is_a_plain_scene_that_solves_the_same(tmp_path: Path) -> None:
    listed = _run("contacts", str(BOX_PUSH), "--json")
    assert listed.returncode == 0, listed.stderr
    plain = tmp_path / "plain.json"
    plain.write_text(listed.stdout, encoding="utf-8")
    data = json.loads(listed.stdout)
    assert len(data["contacts"]) == 5 and "shape" not in data["bodies"]["box"]
    ours = json.loads(_run("solve", str(BOX_PUSH), "--json").stdout)
    theirs = json.loads(_run("solve", str(plain), "--json").stdout)
    assert ours["status"] == theirs["status"] == "ambiguous"
    assert np.allclose(ours["bodies"]["box"]["twist"], theirs["bodies"]["box"]["twist"])
    assert len(ours["solutions"]) == len(theirs["solutions"])


def test_contacts_table_lists_every_contact() -> None:
    result = _run("contacts", str(BOX_PUSH))
    assert result.returncode == 0, result.stderr
    assert "5 contacts found" in result.stdout and result.stdout.count("table") >= 4


def test_planar_hand_grasp_has_the_analytic_jacobians() -> None:
    world = qs.load_world(HAND)
    assert isinstance(world, qs.World)
    scene = world.scene()
    hand = world.robots[0]
    fingertips = [c for c in scene.contacts if c.other.startswith("hand/")]
    assert {c.other for c in fingertips} == {"hand/left_tip", "hand/right_tip"}
    for contact in fingertips:
        link = contact.other.removeprefix("hand/")
        assert contact.jacobian is not None
        assert np.allclose(contact.jacobian, hand.point_jacobian(link, contact.point))


def test_explicit_contacts_are_added_to_the_found_ones() -> None:
    data = _box_push_data()
    data["contacts"] = [{"body": "box", "other": "table", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "mu": 0.5}]
    assert len(qs.load_scene(data).contacts) == 6


def test_the_explicit_twin_round_trips_through_the_file_format() -> None:
    scene = qs.load_scene(BOX_PUSH)
    again = qs.load_scene(json.loads(json.dumps(scene_to_dict(scene))))
    _same_answer(qs.solve(scene), qs.solve(again))


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda d: d["bodies"]["box"]["shape"].update(box=[0.1, -0.1, 0.1]), "bodies.box.shape.box"),
        (lambda d: d["bodies"]["box"]["shape"].update(sphere=0.1), "bodies.box.shape"),
        (lambda d: d["bodies"]["box"]["pose"].update(rotation={"quaternion": [1.0, 1.0, 0.0, 0.0]}), "bodies.box.pose.rotation.quaternion"),
        (lambda d: d["movers"]["finger"]["shape"].update(sphere=0.0, **{}), "movers.finger.shape.sphere"),
        (lambda d: d["bodies"]["box"]["shape"].update(box=None, mesh="no/such/part.obj"), "bodies.box.shape.mesh"),
        (lambda d: d["bodies"]["box"]["shape"].update(boxx=[1, 1, 1]), "bodies.box.shape.boxx"),
        (lambda d: d["bodies"]["box"]["shape"].update(box=None, mesh="/dev/zero"), "bodies.box.shape.mesh"),
        (lambda d: d["bodies"]["box"]["pose"].update(rotation={"rpy": [0.0, "a", 0.0]}), "bodies.box.pose.rotation.rpy[1]"),
        (lambda d: d.update(robots={"arm": {"urdf": "no/such/arm.urdf"}}), "robots.arm.urdf"),
        (lambda d: d.update(contact_detection={"margin": -1.0}), "contact_detection.margin"),
        (
            lambda d: d["contact_detection"]["friction"]["pairs"][0].update(between=["box", "fingr"]),
            "contact_detection.friction.pairs[0].between",
        ),
        (
            lambda d: d.update(robots={"arm": {"urdf": str(EXAMPLES / "robots" / "models" / "planar_hand.urdf"), "q": {"elbow": 0.1}}}),
            "robots.arm.q.elbow",
        ),
    ],
)
def test_bad_geometry_is_one_error_line_naming_the_field(tmp_path: Path, change: Any, field: str) -> None:
    data = _box_push_data()
    change(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    result = _run("solve", str(path))
    assert result.returncode == 2, result.stdout + result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {field}: "), lines  # the field exactly as the file spells it


def test_a_missing_robots_extra_says_how_to_install_it(tmp_path: Path) -> None:
    """With Pinocchio and coal hidden, a scene with shapes is one line naming the extra; a plain scene still solves."""
    code = "import sys; sys.modules['coal'] = None; sys.modules['pinocchio'] = None; sys.argv = ['quasistatic', *sys.argv[1:]]; "
    code += "from quasistatic.cli import main; main()"
    hidden = subprocess.run([sys.executable, "-c", code, "solve", str(BOX_PUSH)], capture_output=True, text=True, timeout=60, check=False)
    assert hidden.returncode == 2 and hidden.stderr.count("\n") == 1
    assert "pip install 'quasistatic[robots]'" in hidden.stderr
    plain = subprocess.run(
        [sys.executable, "-c", code, "solve", str(EXAMPLES / "squeeze.yaml")], capture_output=True, text=True, timeout=60, check=False
    )
    assert plain.returncode == 0, plain.stderr
    robot = subprocess.run([sys.executable, "-c", code, "solve", str(PANDA)], capture_output=True, text=True, timeout=60, check=False)
    assert robot.returncode == 2 and robot.stderr.count("\n") == 1
    assert "Pinocchio, needed for URDF robots" in robot.stderr and "quasistatic[robots]" in robot.stderr


def _solved_json(path: Path) -> dict[str, Any]:
    """``quasistatic solve PATH --json`` as a user runs it: exit 0, stdout only JSON, stderr empty."""
    result = _run("solve", str(path), "--json")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # no solver banner, SCIP error line or URDF parser message
    data: dict[str, Any] = json.loads(result.stdout)
    return data


def test_planar_hand_example_gives_the_answer_its_comment_derives() -> None:
    data = _solved_json(HAND)
    assert data["status"] == "ambiguous" and data["certified"] is True
    lift = data["solutions"][0]
    assert np.allclose(lift["bodies"]["box"]["twist"], [0.0, 0.0, 0.00958148, 0.0, 0.0, 0.0], atol=1e-7)
    assert [c["mode"] for c in lift["contacts"]] == ["rolling", "rolling"]
    assert np.allclose([c["normal_force"] for c in lift["contacts"]], [3.67875, 3.67875], atol=1e-4)


def test_panda_gripper_holds_the_box_with_indeterminate_forces() -> None:
    """The Panda example: certified at rest on the exact cones, every contact rolling, forces indeterminate."""
    data = _solved_json(PANDA)
    assert data["status"] == "solved" and data["certified"] is True and data["forces_indeterminate"] is True
    assert np.allclose(data["bodies"]["box"]["twist"], np.zeros(6), atol=1e-12)
    assert {c["mode"] for c in data["contacts"]} == {"rolling"}
    assert len(data["contacts"]) == 12
    weight = sum(c["normal_force"] for c in data["contacts"] if c["other"] == "table")
    assert weight == pytest.approx(0.1 * 9.81, rel=1e-9)


def test_allegro_example_turns_the_ball_and_holds_it_when_still(tmp_path: Path) -> None:
    """The Allegro example: its index finger opening turns the ball (thumb and middle rolling, index sliding),
    proven the only motion on the exact cones; with every joint still, rest is certified on them too."""
    pytest.importorskip("pinocchio")
    allegro = EXAMPLES / "robots" / "allegro_ball.yaml"
    data = _solved_json(allegro)
    assert data["status"] == "solved" and data["certified"] is True
    assert "unique for the exact cones" in data["message"]
    assert [c["mode"] for c in data["contacts"]] == ["rolling", "sliding", "rolling"]
    assert np.allclose(data["bodies"]["ball"]["twist"][3:], [-0.438498, -0.131465, -0.0237766], atol=1e-5)
    import yaml

    still = yaml.safe_load(allegro.read_text(encoding="utf-8"))
    still["robots"]["hand"]["joint_velocities"] = {}
    path = tmp_path / "still.yaml"
    path.write_text(yaml.safe_dump(still), encoding="utf-8")
    held = _solved_json(path)
    assert held["status"] == "solved" and held["certified"] is True
    assert np.allclose(held["bodies"]["ball"]["twist"], np.zeros(6), atol=1e-12)


def test_friction_pairs_may_name_a_robot_or_one_of_its_links() -> None:
    import yaml

    data = yaml.safe_load(HAND.read_text(encoding="utf-8"))
    data["robots"]["hand"]["urdf"] = str(HAND.parent / data["robots"]["hand"]["urdf"])
    data["contact_detection"]["friction"]["pairs"] = [
        {"between": ["hand/left_tip", "box"], "mu": 0.2},
        {"between": ["box", "hand"], "mu": 0.3},
    ]
    mu = {c.other: c.mu for c in qs.load_scene(data).contacts}
    assert mu == {"hand/left_tip": 0.2, "hand/right_tip": 0.3}  # the first pair that names the contact wins
