"""Robot loads: joint torques tau = J^T f, mover wrenches, their ranges and torque limits, each derived by hand."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import quasistatic as qs

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
W = 0.5 * 9.81  # weight of the examples' 0.5 kg boxes [N]
# robot_tip.yaml: the finger pushes 0.625 W = 3.065625 N along the normal [-0.6, 0.8] at [0.05, 0].
FINGER_FORCE = 3.065625 * np.array([-0.6, 0.8])
TIP_JACOBIAN = np.array([[0.0, 0.2], [-0.3, -0.15]])
# tau = J^T f: [0 * -1.839375 - 0.3 * 2.4525, 0.2 * -1.839375 - 0.15 * 2.4525] = [-0.73575, -0.73575].
TIP_TORQUES = np.array([-0.73575, -0.73575])


def _tip_scene(**robot: object) -> qs.Scene:
    """robot_tip.yaml with more keys for its arm (joint names, torque limits)."""
    data = yaml.safe_load((EXAMPLES / "robot_tip.yaml").read_text())
    data["robots"]["arm"].update(robot)
    return qs.load_scene(data)


def test_robot_tip_torques_by_hand() -> None:
    solution = qs.solve(qs.load_scene(EXAMPLES / "robot_tip.yaml"))
    assert solution.status == "solved"
    (load,) = solution.robot_loads
    assert load.robot == "arm" and load.joints == ("joint[0]", "joint[1]")
    np.testing.assert_allclose(TIP_JACOBIAN.T @ FINGER_FORCE, TIP_TORQUES)
    np.testing.assert_allclose(load.torques, TIP_TORQUES, atol=1e-9)
    assert load.torque_ranges is None and load.torque_limits is None and load.within_limits
    # Sign: tau . qdot is the power the arm puts in, 0.014715 W (the example's comment), all of the input.
    power = float(load.torques @ np.array([-0.04, 0.02]))
    assert power == pytest.approx(0.014715) and power == pytest.approx(solution.power.input)


def test_robot_tip_mover_wrenches_by_hand() -> None:
    wrenches = {w.mover: w for w in qs.solve(qs.load_scene(EXAMPLES / "robot_tip.yaml")).mover_wrenches}
    assert set(wrenches) == {"notch", "fingertip"}
    notch = wrenches["notch"]  # floor 0.5 W up, stop 0.375 W to the right, both at [-0.05, 0]
    np.testing.assert_allclose(notch.origin, [0.0, 0.0])
    np.testing.assert_allclose(notch.force, [0.375 * W, 0.5 * W], atol=1e-9)
    np.testing.assert_allclose(notch.moment, [-0.05 * 0.5 * W], atol=1e-9)  # r x f = r_x f_y - r_y f_x
    tip = wrenches["fingertip"]
    np.testing.assert_allclose(tip.force, FINGER_FORCE, atol=1e-9)
    np.testing.assert_allclose(tip.moment, [0.05 * FINGER_FORCE[1]], atol=1e-9)


def test_squeeze_wrench_ranges() -> None:
    """squeeze.yaml: fingers squeeze with any f in [0, 4.0875] N; corners 2.4525 +- 0.6 f (see its comment)."""
    solution = qs.solve(qs.load_scene(EXAMPLES / "squeeze.yaml"))
    assert solution.forces_indeterminate
    wrenches = {w.mover: w for w in solution.mover_wrenches}
    f_max = 4.0875
    table = wrenches["table"]  # always carries the weight; its moment about [0, 0] is 0.05 (N_R - N_L) = -0.06 f
    np.testing.assert_allclose(table.force, [0.0, W], atol=1e-9)
    expected = {
        "table": [(0.0, 0.0), (W, W), (-0.06 * f_max, 0.0)],
        "left_finger": [(0.0, f_max), (0.0, 0.0), (-0.02 * f_max, 0.0)],  # [f, 0] at [-0.05, 0.02]
        "right_finger": [(-f_max, 0.0), (0.0, 0.0), (0.0, 0.08 * f_max)],  # [-f, 0] at [0.05, 0.08]
    }
    for name, ranges in expected.items():
        wrench = wrenches[name]
        assert wrench.ranges is not None
        np.testing.assert_allclose(np.array(wrench.ranges, dtype=float), ranges, atol=1e-9)
        for value, (lo, hi) in zip(np.r_[wrench.force, wrench.moment], wrench.ranges, strict=True):
            assert lo - 1e-9 <= value <= hi + 1e-9  # the reported distribution is one of them


def test_table_carries_the_weight_3d_about_its_origin() -> None:
    """A box resting on four table points: the split is indeterminate, the table's net wrench is not.

    Net force [0, 0, m g]; about the table's origin o its moment is (com - o) x [0, 0, m g].
    """
    com, origin, weight = np.array([0.2, 0.1, 0.05]), np.array([1.0, -0.5, 0.0]), 2.0 * 9.81
    corners = [com + [sx * 0.05, sy * 0.05, -0.05] for sx in (-1, 1) for sy in (-1, 1)]
    scene = qs.Scene(
        bodies=(qs.Body("box", mass=2.0, com=com),),
        movers=(qs.Mover("table", origin=origin),),
        contacts=tuple(qs.Contact("box", "table", point=p, normal=[0.0, 0.0, 1.0], mu=0.5) for p in corners),
        friction="pyramid:4",
    )
    solution = qs.solve(scene)
    assert solution.status == "solved" and solution.forces_indeterminate
    (table,) = solution.mover_wrenches
    moment = np.cross(com - origin, [0.0, 0.0, weight])
    np.testing.assert_allclose(table.force, [0.0, 0.0, weight], atol=1e-9)
    np.testing.assert_allclose(table.moment, moment, atol=1e-9)
    assert table.ranges is not None
    np.testing.assert_allclose(np.array(table.ranges, dtype=float), np.repeat(np.r_[0.0, 0.0, weight, moment], 2).reshape(6, 2), atol=1e-8)
    assert solution.robot_loads == ()


def test_torque_limits_met_and_exceeded_determinate() -> None:
    within = qs.solve(_tip_scene(torque_limits=[0.74, 0.74]))
    assert within.robot_loads[0].within_limits and within.motion is not None and within.motion.torque_limits_exceeded == {}
    exceeded = qs.solve(_tip_scene(joint_names=["shoulder", "elbow"], torque_limits=[0.7, 10.0]))
    assert exceeded.status == "solved"  # the rigid model's motion is still the motion
    (load,) = exceeded.robot_loads
    assert load.joints == ("shoulder", "elbow") and load.limits_exceeded == ("shoulder",)
    assert exceeded.motion is not None and exceeded.motion.torque_limits_exceeded == {"arm": ("shoulder",)}
    assert exceeded.to_dict()["robot_loads"][0]["limits_exceeded"] == ["shoulder"]


def _hand_squeeze(limits: list[float] | None) -> qs.Solution:
    """A box on a frictionless table, pushed left by 1 N at its com, held by two robot fingers at com height.

    The left finger pushes f_L = f_R + 1 (f_R >= 0 free: an unbounded squeeze). Jacobians (prismatic
    joints a, b): left finger moves at [qa + qb, 0], right at [3 qb, 0], so tau = J_L^T [f_L, 0] +
    J_R^T [-f_R, 0] = [f_L, f_L - 3 f_R] = [1 + f_R, 1 - 2 f_R]: ranges [1, inf) and (-inf, 1].
    """
    scene = qs.Scene(
        dimension=2,
        bodies=(qs.Body("box", mass=0.5, com=[0.0, 0.05], wrench=[-1.0, 0.0, 0.0]),),
        robots=(qs.Robot("hand", [0.0, 0.0], joint_names=["a", "b"], torque_limits=limits),),
        movers=(qs.Mover("table"), qs.Mover("left", robot="hand"), qs.Mover("right", robot="hand")),
        contacts=(
            qs.Contact("box", "table", point=[-0.05, 0.0], normal=[0.0, 1.0]),
            qs.Contact("box", "table", point=[0.05, 0.0], normal=[0.0, 1.0]),
            qs.Contact("box", "left", point=[-0.05, 0.05], normal=[1.0, 0.0], jacobian=[[1.0, 1.0], [0.0, 0.0]]),
            qs.Contact("box", "right", point=[0.05, 0.05], normal=[-1.0, 0.0], jacobian=[[0.0, 3.0], [0.0, 0.0]]),
        ),
    )
    return qs.solve(scene)


def test_torque_ranges_unbounded_squeeze() -> None:
    solution = _hand_squeeze(None)
    assert solution.status == "solved" and solution.forces_indeterminate
    (load,) = solution.robot_loads
    assert load.torque_ranges is not None
    (lo_a, hi_a), (lo_b, hi_b) = load.torque_ranges
    assert lo_a == pytest.approx(1.0) and hi_a is None and lo_b is None and hi_b == pytest.approx(1.0)
    f_right = load.torques[0] - 1.0
    np.testing.assert_allclose(load.torques, [1.0 + f_right, 1.0 - 2.0 * f_right], atol=1e-9)


@pytest.mark.parametrize(
    ("limits", "exceeded"),
    [
        # |1 + f_R| <= 1.5 and |1 - 2 f_R| <= 0.5: f_R in [0.25, 0.5]; met, though the reported f_R = 0 gives tau_b = 1.
        ([1.5, 0.5], ()),
        ([0.8, 10.0], ("a",)),  # tau_a >= 1 at every distribution: a fails alone
        ([1.2, 0.5], ("a", "b")),  # f_R <= 0.2 and f_R >= 0.25: each can be met, not both
    ],
)
def test_torque_limits_with_indeterminate_forces(limits: list[float], exceeded: tuple[str, ...]) -> None:
    solution = _hand_squeeze(limits)
    assert solution.status == "solved"
    assert solution.robot_loads[0].limits_exceeded == exceeded


def test_loads_survive_pickling() -> None:
    solution = _hand_squeeze([1.2, 0.5])
    copy = pickle.loads(pickle.dumps(solution))
    assert copy.robot_loads[0].limits_exceeded == ("a", "b")
    assert copy.mover_wrenches[0].ranges == solution.mover_wrenches[0].ranges


@pytest.mark.parametrize(
    ("entry", "reason"),
    [
        ({"torque_limits": [1.0]}, "expected 2 numbers"),
        ({"torque_limits": [1.0, -1.0]}, ">= 0"),
        ({"torque_limits": {"a": 1.0, "b": 1.0}}, "urdf"),
        ({"joint_names": ["a", "a"]}, "unique"),
    ],
)
def test_torque_limits_are_validated(entry: dict[str, object], reason: str) -> None:
    data = yaml.safe_load((EXAMPLES / "robot_tip.yaml").read_text())
    data["robots"]["arm"].update(entry)
    with pytest.raises(qs.SceneError, match=reason) as error:
        qs.load_scene(data)
    assert error.value.field.startswith("robots.arm.")


def test_console_json_has_loads(tmp_path: Path) -> None:
    data = yaml.safe_load((EXAMPLES / "robot_tip.yaml").read_text())
    data["robots"]["arm"].update(joint_names=["shoulder", "elbow"], torque_limits=[0.5, 1.0])
    path = tmp_path / "tip.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    command = [str(Path(sys.executable).with_name("quasistatic")), "solve", str(path), "--json"]
    result = subprocess.run(command, capture_output=True, text=True, check=True)
    out = json.loads(result.stdout)
    assert out["status"] == "solved"
    (load,) = out["robot_loads"]
    assert load["joints"] == ["shoulder", "elbow"] and load["torque_limits"] == [0.5, 1.0]
    np.testing.assert_allclose(load["torques"], TIP_TORQUES, atol=1e-9)
    assert load["within_limits"] is False and load["limits_exceeded"] == ["shoulder"] and load["torque_ranges"] is None
    assert [w["mover"] for w in out["mover_wrenches"]] == ["notch", "fingertip"]
    assert qs.load_scene(path).robot("arm").torque_limits.tolist() == [0.5, 1.0]
    table = subprocess.run(command[:-1], capture_output=True, text=True, check=True).stdout
    assert "robot joint torques" in table and "infeasible for robot arm" in table and "shoulder" in table


def test_scene_file_round_trip_keeps_limits() -> None:
    scene = _tip_scene(joint_names=["shoulder", "elbow"], torque_limits=[0.5, 1.0])
    entry = qs.load_scene(qs.model.io.scene_to_dict(scene)).robot("arm")
    assert entry.joint_names == ("shoulder", "elbow") and entry.torque_limits is not None
    assert entry.torque_limits.tolist() == [0.5, 1.0]


def test_planar_hand_urdf_torques() -> None:
    """URDF joints are named by the model; each torque is the sum of J^T f over the hand's contacts."""
    pytest.importorskip("pinocchio")
    pytest.importorskip("coal")
    world = qs.load_world(EXAMPLES / "robots" / "planar_hand.yaml")
    scene = world.scene()
    solution = qs.solve(scene)
    (load,) = solution.robot_loads
    hand = scene.robots[0]
    assert load.joints == hand.joint_names and len(load.joints) == hand.joint_velocities.size
    expected = sum(
        (c.jacobian.T @ r.force for c, r in zip(scene.contacts, solution.contacts, strict=True) if c.jacobian is not None),
        start=np.zeros(len(load.joints)),
    )
    np.testing.assert_allclose(load.torques, expected, atol=1e-9)
