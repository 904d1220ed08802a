"""The inverse problem (issue 15, section 4): qs.plan on worked examples with answers derived by hand."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.tolerances import PLAN_SPEED

G = 9.81


def _pushed_box(mu_finger: float = 0.5) -> qs.Scene:
    """A 0.1 m box of 0.5 kg on a floor (mu 0.3), a fingertip at the middle of its left face."""
    return qs.Scene(
        bodies=[qs.Body("box", 0.5, [0.0, 0.05])],
        movers=[qs.Mover("floor"), qs.Mover("finger", origin=[-0.05, 0.05])],
        contacts=[
            qs.Contact("box", "floor", [-0.05, 0.0], [0.0, 1.0], mu=0.3),
            qs.Contact("box", "floor", [0.05, 0.0], [0.0, 1.0], mu=0.3),
            qs.Contact("box", "finger", [-0.05, 0.05], [1.0, 0.0], mu=mu_finger),
        ],
        dimension=2,
    )


def test_pushing_a_box_so_it_translates_without_rotating() -> None:
    """The finger rolls on the box, so its contact point moves with it: (0.01, 0); least norm leaves it unturned.
    The floor's friction 0.3 m g is the finger's push; the forward certified solve proves the motion the only one."""
    result = qs.plan(_pushed_box(), [0.01, 0.0, 0.0], ["sliding", "sliding", "rolling"], free=["finger"], certify=True)
    assert result.status == "planned", result.message
    assert result.input_names == ("finger.v_x", "finger.v_y", "finger.omega_z")
    np.testing.assert_allclose(result.inputs, [0.01, 0.0, 0.0], atol=1e-12)
    assert result.motion is not None and result.motion.audit.passed
    assert result.motion.modes == ("sliding", "sliding", "rolling")
    np.testing.assert_allclose(result.motion.contacts[2].force, [0.3 * 0.5 * G, 0.0], atol=1e-9)
    assert result.unique is True and result.forward is not None and result.forward.status == "solved"
    np.testing.assert_allclose(result.forward.twists["box"], [0.01, 0.0, 0.0], atol=1e-12)


def test_a_quadratic_cost_chooses_among_the_inputs() -> None:
    """The finger's spin about its contact point moves nothing; a linear reward on it, with the unit Hessian,
    makes the cheapest spin 1 rad/s (minimum of w^2/2 - w)."""
    cost = qs.QuadraticCost(np.eye(3), [0.0, 0.0, -1.0])
    result = qs.plan(_pushed_box(), [0.01, 0.0, 0.0], ["sliding", "sliding", "rolling"], free=["finger"], cost=cost)
    assert result.status == "planned"
    np.testing.assert_allclose(result.inputs, [0.01, 0.0, 1.0], atol=1e-9)
    assert result.cost == pytest.approx(0.5 * (0.01**2 + 1.0) - 1.0)


def _meter_stick() -> qs.Scene:
    """A 1 m stick of 0.2 kg (com at x = 0.1) on two fingertips at x = -0.3 and x = 0.4, both mu = 0.4.

    Moments about the com: N1 0.4 = N2 0.3, so N1 = 3/7 m g and N2 = 4/7 m g: the far finger carries less.
    """
    return qs.Scene(
        bodies=[qs.Body("stick", 0.2, [0.1, 0.0])],
        movers=[qs.Mover("left", origin=[-0.3, 0.0]), qs.Mover("right", origin=[0.4, 0.0])],
        contacts=[
            qs.Contact("stick", "left", [-0.3, 0.0], [0.0, 1.0], mu=0.4),
            qs.Contact("stick", "right", [0.4, 0.0], [0.0, 1.0], mu=0.4),
        ],
        dimension=2,
    )


def test_the_meter_stick_trick_slides_on_the_less_loaded_finger() -> None:
    """The stick moves with one finger while the other slides under it. The sliding finger's friction mu N_s must be
    met by the rolling one's, at most mu N_r: only the less loaded (left) finger can slide."""
    wanted = [0.01, 0.0, 0.0]
    result = qs.plan(_meter_stick(), wanted, ["sliding", "rolling"], free=["left", "right"], certify=True)
    assert result.status == "planned", result.message
    inputs = dict(zip(result.input_names, result.inputs, strict=True))
    assert inputs["right.v_x"] == pytest.approx(0.01, abs=1e-12)  # rolls: moves with the stick
    # Least norm: the left finger stays still and the stick slides over it at 0.01, past the smallest planned slip.
    assert inputs["left.v_x"] == pytest.approx(0.0, abs=1e-12)
    assert PLAN_SPEED * 0.01 < 0.01
    assert inputs["left.v_y"] == pytest.approx(0.0, abs=1e-12) and inputs["right.v_y"] == pytest.approx(0.0, abs=1e-12)
    assert result.motion is not None
    normal = [c.normal_force for c in result.motion.contacts]
    np.testing.assert_allclose(normal, [3 / 7 * 0.2 * G, 4 / 7 * 0.2 * G], rtol=1e-9)
    assert result.motion.contacts[0].force[0] == pytest.approx(-0.4 * normal[0], rel=1e-9)  # friction holds the stick back
    assert result.unique is True

    swapped = qs.plan(_meter_stick(), wanted, ["rolling", "sliding"], free=["left", "right"])
    assert swapped.status == "infeasible"
    assert swapped.motion is None and not swapped.ok


def _controlled_slip(a: float = 0.05) -> qs.Scene:
    """Brock's controlled slip: a 0.2 kg box (half-size a, com at y = 0.02) pinched by two fingertips on the x faces,
    a third under it at y = 0.03 (mu 0.5); every fingertip a mover whose twist the planner chooses."""
    return qs.Scene(
        bodies=[qs.Body("box", 0.2, [0.0, 0.02, 0.0])],
        movers=[qs.Mover("f1", origin=[-a, 0, 0]), qs.Mover("f2", origin=[a, 0, 0]), qs.Mover("f3", origin=[0, 0.03, -a])],
        contacts=[
            qs.Contact("box", "f1", [-a, 0, 0], [1, 0, 0], mu=0.8),
            qs.Contact("box", "f2", [a, 0, 0], [-1, 0, 0], mu=0.8),
            qs.Contact("box", "f3", [0, 0.03, -a], [0, 0, 1], mu=0.5),
        ],
        dimension=3,
    )


def test_brocks_controlled_slip_turns_the_object_about_the_axis_through_the_rolling_fingers() -> None:
    """Turning at w about the x axis (through both pinching contacts) leaves the pinching fingertips still (their
    contact points lie on the axis); the third must rise with the box's point, w x (0, 0.03, -0.05) = (0, 0.05 w,
    0.03 w), and slip under it. On exact cones the NLP's friction is -mu c_n along the slip."""
    w = 0.2
    com = np.array([0.0, 0.02, 0.0])
    twist = np.r_[np.cross([w, 0.0, 0.0], com), [w, 0.0, 0.0]]
    result = qs.plan(_controlled_slip(), twist, ["rolling", "rolling", "sliding"], free=["f1", "f2", "f3"])
    assert result.status == "planned", result.message
    assert result.unique is None  # not asked to certify: unproven as the only motion
    inputs = dict(zip(result.input_names, result.inputs, strict=True))
    for finger in ("f1", "f2"):
        np.testing.assert_allclose([inputs[f"{finger}.v_{axis}"] for axis in "xyz"], 0.0, atol=1e-9)
    assert inputs["f3.v_z"] == pytest.approx(0.03 * w, rel=1e-6)
    assert result.motion is not None and result.motion.audit.passed
    assert result.motion.modes == ("rolling", "rolling", "sliding")
    slip = result.motion.contacts[2].slip
    friction = result.motion.contacts[2].force[:2]
    # Maximum dissipation on the exact cone: friction opposes the slip with magnitude mu c_n.
    np.testing.assert_allclose(friction, -0.5 * result.motion.contacts[2].normal_force * slip[:2] / np.linalg.norm(slip), atol=1e-8)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"modes": ["sliding", "rolling"]}, "modes: expected 3 entries"),
        ({"modes": ["sliding", "sliding", "stuck"]}, "modes\\[2\\]: 'stuck'"),
        ({"twist": {"crate": [0, 0, 0]}}, "twist: 'crate' is not a free body"),
        ({"twist": [0.01, 0.0]}, "twist.box"),
        ({"free": ["hand"]}, "free: 'hand'"),
        ({"free": None}, "free: the scene has no robot"),
        ({"min_speed": -1.0}, "min_speed: -1.0"),
        ({"cost": qs.QuadraticCost(np.eye(2))}, "cost.hessian"),
    ],
)
def test_bad_requests_name_the_field(kwargs: dict, message: str) -> None:
    arguments = {"twist": [0.01, 0.0, 0.0], "modes": ["sliding", "sliding", "rolling"], "free": ["finger"], **kwargs}
    with pytest.raises(ValueError, match=message):
        qs.plan(_pushed_box(), **arguments)


PUSH_FILE = """\
quasistatic: 1
dimension: 2
bodies:
  box: {mass: 0.5, com: [0.0, 0.05]}
movers:
  floor:
  finger: {origin: [-0.05, 0.05]}
contacts:
  - {body: box, other: floor, point: [-0.05, 0.0], normal: [0.0, 1.0], mu: 0.3}
  - {body: box, other: floor, point: [0.05, 0.0], normal: [0.0, 1.0], mu: 0.3}
  - {body: box, other: finger, point: [-0.05, 0.05], normal: [1.0, 0.0], mu: 0.5}
"""


def _run(*arguments: str) -> subprocess.CompletedProcess[str]:
    command = [str(Path(sys.executable).with_name("quasistatic")), *arguments]  # the venv's script, found without PATH
    return subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)


def test_the_plan_command_prints_the_plan_as_json(tmp_path: Path) -> None:
    scene = tmp_path / "push.yaml"
    scene.write_text(PUSH_FILE, encoding="utf-8")
    done = _run(
        "plan", str(scene), "--twist", "box=0.01,0,0", "--modes", "sliding,sliding,rolling", "--free", "finger", "--certify", "--json"
    )
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout)
    assert answer["status"] == "planned" and answer["unique"] is True
    assert answer["inputs"] == {"finger.v_x": 0.01, "finger.v_y": 0.0, "finger.omega_z": 0.0}
    assert answer["motion"]["modes"] == ["sliding", "sliding", "rolling"] and answer["motion"]["audit"]["passed"]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--twist", "0.01,x,0", "--modes", "sliding,sliding,rolling"], "error: --twist '0.01,x,0'"),
        (["--twist", "0.01,0,0", "--modes", "sliding,stuck,rolling"], "error: --modes entry 1 is 'stuck'"),
        (["--twist", "0.01,0,0", "--modes", "sliding,rolling"], "error: modes: expected 3 entries"),
    ],
)
def test_the_plan_command_names_bad_input(tmp_path: Path, arguments: list[str], message: str) -> None:
    scene = tmp_path / "push.yaml"
    scene.write_text(PUSH_FILE, encoding="utf-8")
    done = _run("plan", str(scene), *arguments, "--free", "finger")
    assert done.returncode == 2
    assert done.stderr.startswith(message) and done.stderr.count("\n") == 1 and "Traceback" not in done.stderr


def test_a_robot_plan_is_the_least_norm_joint_velocity() -> None:
    """examples/robot_tip.yaml, wanted: its own answer's twist (turning at 0.06 rad/s about the notch corner). Only the
    fingertip's normal speed is constrained, n . (J qdot) = 0.08 w = 0.0048 with n^T J = [-0.24, -0.24]: the least-norm
    joint velocities are [-0.01, -0.01] (the scene's own [-0.04, 0.02] costs more), and the fingertip still slips."""
    scene = qs.load_scene(Path(__file__).resolve().parents[1] / "examples" / "robot_tip.yaml")
    result = qs.plan(scene, {"box": [-0.003, 0.003, 0.06]}, ["rolling", "rolling", "sliding"], certify=True)
    assert result.status == "planned", result.message
    assert result.input_names == ("arm.joint[0]", "arm.joint[1]")
    np.testing.assert_allclose(result.inputs, [-0.01, -0.01], atol=1e-12)
    assert result.unique is True


def _pushed_box_3d(friction: str) -> qs.Scene:
    """A 0.1 m cube of 0.5 kg on a floor (four corners, mu 0.3), a frictionless fingertip at the middle of its -x face."""
    corners = [[x, y, 0.0] for x in (-0.05, 0.05) for y in (-0.05, 0.05)]
    return qs.Scene(
        bodies=[qs.Body("box", 0.5, [0.0, 0.0, 0.05])],
        movers=[qs.Mover("floor"), qs.Mover("finger", origin=[-0.05, 0.0, 0.05])],
        contacts=[qs.Contact("box", "floor", p, [0.0, 0.0, 1.0], mu=0.3) for p in corners]
        + [qs.Contact("box", "finger", [-0.05, 0.0, 0.05], [1.0, 0.0, 0.0])],
        dimension=3,
        friction=friction,
    )


def test_pushing_a_box_on_pyramid_friction() -> None:
    """3-D, pyramid:4 (edges along the contact frame's tangents): the floor's friction opposes the slip along +x from
    one edge (a vertex of the friction square), 0.3 m g in all; the frictionless finger pushes with exactly that
    and moves with the box. The forward certified solve of the planned scene gives the same motion."""
    scene = _pushed_box_3d("pyramid:4")
    twist = [0.01, 0.0, 0.0, 0.0, 0.0, 0.0]
    result = qs.plan(scene, twist, ["sliding"] * 4 + ["rolling"], free=["finger"], certify=True)
    assert result.status == "planned", result.message
    np.testing.assert_allclose(result.inputs, twist, atol=1e-12)
    assert result.motion is not None and result.motion.modes == ("sliding",) * 4 + ("rolling",)
    np.testing.assert_allclose(result.motion.contacts[4].force, [0.3 * 0.5 * G, 0.0, 0.0], atol=1e-9)
    friction = sum(np.array(c.force) for c in result.motion.contacts[:4])
    np.testing.assert_allclose(friction, [-0.3 * 0.5 * G, 0.0, 0.5 * G], atol=1e-9)
    assert result.forward is not None and any(
        np.allclose(m.twists["box"], twist, atol=1e-9) for m in (result.forward.solutions or (result.forward.motion,)) if m is not None
    )


def _pyramid_motions() -> list[tuple[qs.Scene, qs.Solution]]:
    from random_scenes import random_scene

    found = []
    for seed in range(40):
        scene = random_scene(3, seed, "pyramid:8")
        solution = qs.solve(scene)
        if solution.status == "solved" and "sliding" in solution.modes:
            found.append((scene, solution))
    return found


def test_a_plan_on_pyramids_recovers_inputs_as_cheap_as_the_forward_ones() -> None:
    """Random 3-D scenes on pyramid:8 with sliding contacts: planning each solved motion (its twist and modes, every
    finger free) gives audited inputs that cost no more than the scene's own (which realise it), whose slips load
    the pyramid's edges or faces as maximum dissipation wants, and which the forward solve says give that motion."""
    cases = _pyramid_motions()
    assert len(cases) >= 5
    for scene, solution in cases:
        fingers = [m.name for m in scene.movers if m.name != "table"]
        speeds = [np.linalg.norm(c.slip) if c.mode == "sliding" else c.normal_velocity for c in solution.contacts if c.mode != "rolling"]
        twist = solution.twists["box"]
        result = qs.plan(scene, twist, solution.modes, free=fingers, min_speed=0.5 * min(speeds), certify=True)
        assert result.status == "planned", (result.message, solution.modes)
        own = np.concatenate([scene.mover(f).twist for f in fingers])
        assert result.cost is not None and result.cost <= 0.5 * own @ own * (1 + 1e-9) + 1e-15
        assert result.forward is not None
        motions = result.forward.solutions or ((result.forward.motion,) if result.forward.motion is not None else ())
        assert any(np.allclose(m.twists["box"], twist, atol=1e-9 * max(1.0, np.abs(twist).max())) for m in motions)
