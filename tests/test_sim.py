"""Motion over time: the screw integration, the step, events, files and the command, against hand-derived answers."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

pytest.importorskip("coal")

import quasistatic as qs
from quasistatic.sim import Inputs, InputTable, SimModel, State, StepOptions, Trajectory, advance_pose, step
from quasistatic.tolerances import SIM_PENETRATION

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "sim"
TIP = EXAMPLES / "tip_box.yaml"
PUSH = EXAMPLES / "push_box.yaml"

# The tipping example's numbers (see its header): box depth w, height H, push height h, fingertip radius r, speed v.
W, H, PUSH_HEIGHT, RADIUS, SPEED = 0.1, 0.2, 0.15, 0.005, 0.01


def tilt(trajectory: Trajectory) -> np.ndarray:
    """The box's rotation about +y at every state [rad]."""
    rotations = trajectory.rotations("box")
    return np.arctan2(rotations[:, 0, 2], rotations[:, 2, 2])


def time_to_tilt(theta: np.ndarray) -> np.ndarray:
    """By hand: the fingertip centre stays r from the back face, x = (h sin t - w - r) / cos t, so
    dt/dtheta = (h - (w + r) sin t) / (v cos^2 t), whose integral is (h tan t - (w + r)(sec t - 1)) / v."""
    return (PUSH_HEIGHT * np.tan(theta) - (W + RADIUS) * (1 / np.cos(theta) - 1)) / SPEED


@pytest.fixture(scope="module")
def tipping() -> Trajectory:
    return qs.simulate(TIP, duration=10.0, dt=0.25)


# --------------------------------------------------------------------------- the exponential map


@pytest.mark.parametrize("seed", range(5))
def test_screw_step_is_the_matrix_exponential_of_the_twist(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pose = qs.Pose.from_rpy(rng.normal(size=3), rng.normal(size=3))
    point, v, w = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    dt = 0.7
    moved = advance_pose(pose, np.r_[v, w], point, dt)
    # The same constant twist as a 4x4 matrix about the world origin: v_origin = v_point - w x point.
    xi = np.zeros((4, 4))
    xi[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    xi[:3, 3] = v - np.cross(w, point)
    before = np.eye(4)
    before[:3, :3], before[:3, 3] = pose.rotation, pose.position
    expected = scipy.linalg.expm(xi * dt) @ before
    np.testing.assert_allclose(moved.rotation, expected[:3, :3], atol=1e-12)
    np.testing.assert_allclose(moved.position, expected[:3, 3], atol=1e-12)


def test_a_point_on_the_screw_axis_stays_put() -> None:
    """A box tipping about its edge: the edge does not drift, however long the step."""
    edge = np.array([0.05, 0.0, 0.0])
    moved = advance_pose(qs.Pose([0, 0, 0.1]), np.r_[np.zeros(3), 0.0, 2.0, 0.0], edge, 0.3)
    local_edge = edge - np.array([0, 0, 0.1])
    np.testing.assert_allclose(moved.rotation @ local_edge + moved.position, edge, atol=1e-15)


# --------------------------------------------------------------------------- tipping, by hand


def test_tipping_box_ends_unstable_when_its_centre_of_mass_passes_the_edge(tipping: Trajectory) -> None:
    assert tipping.status == "unstable"
    assert tipping.certified
    critical = math.atan(W / H)  # the centre of mass above the front edge: 26.57 degrees
    # The event is located within dt/64 = 3.9 ms, over which the box turns < 0.02 degrees.
    assert abs(tilt(tipping)[-1] - critical) < math.radians(0.05)
    unstable = [e for e in tipping.events if e.kind == "unstable"]
    assert len(unstable) == 1 and "'box'" in unstable[0].detail
    # It falls forward (+x), turning about +y: the way it was tipping.
    assert "moving along [1.000" in unstable[0].detail and "turning about [0.000, 1.000, 0.000]" in unstable[0].detail
    assert unstable[0].window[1] - unstable[0].window[0] <= 0.25 / 64 + 1e-12


def test_tipping_box_turns_at_the_hand_derived_rate(tipping: Trajectory) -> None:
    theta = tilt(tipping)
    assert np.all(np.diff(theta) >= 0) and theta[-1] > 0.4
    # A first-order step lags the exact tilt by at most the step times the change of the rate (~0.08 s here).
    lag = tipping.times - time_to_tilt(theta)
    assert np.max(np.abs(lag)) < 0.1 * 0.25
    for result, angle in zip(tipping.steps[1:-1], theta[1:-1], strict=True):  # the exact rate at each step's start
        rate = SPEED * math.cos(angle) ** 2 / (PUSH_HEIGHT - (W + RADIUS) * math.sin(angle))
        assert result.twists["box"][4] == pytest.approx(rate, rel=1e-4)  # the contact within its margin (1e-4 of the size)
    first = tipping.steps[1]
    modes = {(c.other, c.mode) for c in first.contacts}
    assert modes == {("finger", "sliding"), ("table", "rolling")}  # it pivots on its front edge; the tip slides up the face
    for contact in first.contacts:  # the fingertip slides up the face (tangent to it); the edge does not slip
        speed = float(np.linalg.norm(contact.slip))
        assert (speed > 1e-3) if contact.other == "finger" else (speed == 0.0)
        assert abs(float(contact.slip @ contact.normal)) < 1e-9


def test_penetration_is_corrected_and_does_not_accumulate(tipping: Trajectory) -> None:
    margin = 1e-4 * H  # the default contact margin of this scene
    assert tipping.max_penetration < 2 * margin
    for result in tipping.steps:
        assert all(c.gap >= -SIM_PENETRATION * margin - 1e-12 for c in result.contacts)


def test_the_first_event_is_the_back_corners_lifting(tipping: Trajectory) -> None:
    first = tipping.events[0]
    assert first.kind == "mode change" and first.pair == ("box", "table")
    assert "separating" in first.detail.split("->")[0]


# --------------------------------------------------------------------------- contacts made, tunnelling


def test_contact_made_at_the_time_the_gap_closes() -> None:
    trajectory = qs.simulate(PUSH, duration=2.6, dt=0.5, ambiguous="min_power")
    assert trajectory.status == "completed" and trajectory.certified
    made = [e for e in trajectory.events if e.kind == "contact made"]
    assert [e.pair for e in made] == [("box", "finger")]
    # The fingertip's surface starts 2 cm from the box at 1 cm/s; it stops half a margin short of touching.
    assert made[0].time == pytest.approx(2.0, abs=1e-3)
    # Then the box goes with the fingertip: the least-power motion of the ambiguous answers.
    assert any(s.choice.startswith("ambiguous: took motion") for s in trajectory.steps)
    np.testing.assert_allclose(trajectory.positions("box")[-1], [0.01 * (2.6 - made[0].time), 0, 0.05], atol=2e-5)


def test_a_solver_crash_mid_run_ends_it_failed_with_the_steps_before_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    """A HiGHS or SCIP crash at one step is that step's `failed` answer: the run stops there, not with an exception."""
    step_module = sys.modules["quasistatic.sim.step"]  # the package exports the function `step` under the same name
    real_solve, calls = step_module.solve, []

    def crashing_after_three(*args: object, **kwargs: object) -> qs.Solution:
        calls.append(None)
        if len(calls) > 3:
            raise qs.SolverError("highs", "LP error")
        return real_solve(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(step_module, "solve", crashing_after_three)
    trajectory = qs.simulate(EXAMPLES / "push_planar.yaml", duration=0.5, dt=0.05)
    assert trajectory.status == "failed" and not trajectory.certified
    assert "the solver failed" in trajectory.message and "LP error" in trajectory.message
    assert len(trajectory.times) >= 3 and trajectory.steps[-1].status == "failed"


def test_a_thin_plate_is_not_passed_through_with_a_long_step() -> None:
    world = qs.load_world(PUSH)
    plate = replace(world.bodies[0], shape=qs.Box([0.002, 0.1, 0.1]))
    finger = replace(world.movers[1], pose=qs.Pose([-0.03, 0.0, 0.02]))
    world = replace(world, bodies=(plate,), movers=(world.movers[0], finger))
    trajectory = qs.simulate(world, duration=3.5, dt=10.0, ambiguous="min_power")
    made = [e for e in trajectory.events if e.kind == "contact made"]
    assert made and made[0].time == pytest.approx((0.03 - 0.001 - 0.005) / 0.01, abs=1e-3)
    finger_x = trajectory.positions("finger")[:, 0]
    plate_x = trajectory.positions("box")[:, 0]
    assert np.all(finger_x + 0.005 <= plate_x - 0.001 + 1e-5)  # the fingertip never enters the plate


# --------------------------------------------------------------------------- the pure step, inputs


def test_a_run_that_reaches_the_step_limit_says_so_and_keeps_its_steps() -> None:
    trajectory = qs.simulate(TIP, duration=1.0, dt=0.25, max_steps=4)  # exactly enough steps of dt, but events bisect them
    assert trajectory.status == "max_steps", trajectory.message
    assert "largest number of steps" in trajectory.message
    assert 0.0 < trajectory.final.time < 1.0 and len(trajectory.steps) == 5  # 4 steps and the final state


def test_step_is_pure_and_repeatable() -> None:
    world = qs.load_world(TIP)
    model = SimModel(world, StepOptions(dt=0.1))
    state = State.of(world)
    first_state, first = step(model, state, Inputs())
    second_state, second = step(model, state, Inputs())
    assert state.time == 0.0 and np.array_equal(state.bodies["box"].position, [0, 0, 0.1])
    assert first_state.time == pytest.approx(0.1) and first.dt == pytest.approx(0.1)
    np.testing.assert_array_equal(first_state.bodies["box"].rotation, second_state.bodies["box"].rotation)
    assert first.status == second.status == "solved"


def test_stopped_finger_leaves_the_box_leaning_at_rest() -> None:
    table = InputTable((0.0, 1.0), (Inputs(), Inputs(mover_twists={"finger": np.zeros(6)})))
    trajectory = qs.simulate(TIP, duration=2.0, dt=0.5, inputs=table)
    assert trajectory.status == "completed"
    times, theta = trajectory.times, tilt(trajectory)
    assert 1.0 in set(np.round(times, 12))  # a step ends where the inputs change
    leaning = theta[times >= 1.0]
    assert leaning[0] > 0.05 and np.ptp(leaning) < 1e-9
    assert np.all(trajectory.steps[-1].twists["box"] == 0)


def test_inputs_function_of_time_and_state() -> None:
    def backwards(time: float, state: State) -> Inputs:
        return Inputs(mover_twists={"finger": [-0.01, 0, 0, 0, 0, 0]})

    trajectory = qs.simulate(PUSH, duration=1.0, dt=0.5, inputs=backwards)
    assert trajectory.status == "completed" and not trajectory.events
    np.testing.assert_allclose(trajectory.positions("finger")[-1], [-0.085, 0, 0.05], atol=1e-12)


@pytest.mark.parametrize(
    ("inputs", "field"),
    [
        (Inputs(mover_twists={"nobody": np.zeros(6)}), "inputs.mover_twists"),
        (Inputs(joint_velocities={"hand": [0.1]}), "inputs.joint_velocities"),
    ],
)
def test_inputs_naming_nothing_are_refused(inputs: Inputs, field: str) -> None:
    with pytest.raises(qs.SceneError, match=field.replace(".", r"\.")):
        qs.simulate(TIP, duration=1.0, dt=0.5, inputs=inputs)


def test_bad_inputs_and_runs_are_refused() -> None:
    with pytest.raises(qs.SceneError, match="twist has 6 entries"):
        Inputs(mover_twists={"finger": [1, 2]})
    with pytest.raises(qs.SceneError, match="3-D world has 6 entries"):  # a planar twist, in a 3-D world
        qs.simulate(TIP, duration=1.0, dt=0.5, inputs=Inputs(mover_twists={"finger": [1, 2, 3]}))
    with pytest.raises(qs.SceneError, match=r"inputs\.times"):
        InputTable((0.5, 1.0), (Inputs(), Inputs()))
    with pytest.raises(qs.SceneError, match="duration"):
        qs.simulate(TIP, duration=math.nan)
    with pytest.raises(qs.SceneError, match="max_steps = 3 steps of dt = 0.25 s"):
        qs.simulate(TIP, duration=1.0, dt=0.25, max_steps=3)
    with pytest.raises(qs.SceneError, match="listed contacts"):
        qs.simulate(qs.load_scene(Path(__file__).resolve().parents[1] / "examples" / "squeeze.yaml"), duration=1.0)


# --------------------------------------------------------------------------- files


@pytest.mark.parametrize("suffix", [".npz", ".jsonl"])
def test_trajectory_files_read_back_the_same(tipping: Trajectory, tmp_path: Path, suffix: str) -> None:
    path = tipping.save(tmp_path / f"run{suffix}")
    again = Trajectory.load(path)
    assert (again.status, again.message, again.certified) == (tipping.status, tipping.message, tipping.certified)
    np.testing.assert_array_equal(again.times, tipping.times)
    np.testing.assert_array_equal(again.rotations("box"), tipping.rotations("box"))
    np.testing.assert_array_equal(again.positions("finger"), tipping.positions("finger"))
    assert again.events == tipping.events
    for a, b in zip(again.steps, tipping.steps, strict=True):
        assert (a.status, a.dt, [c.mode for c in a.contacts]) == (b.status, b.dt, [c.mode for c in b.contacts])
        np.testing.assert_array_equal(a.twists["box"], b.twists["box"])
        np.testing.assert_array_equal([c.slip for c in a.contacts], [c.slip for c in b.contacts])


def test_a_file_that_is_not_a_trajectory_is_refused(tmp_path: Path) -> None:
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps({"format": "something else"}) + "\n")
    with pytest.raises(qs.SceneError, match="not a trajectory"):
        Trajectory.load(bad)


# --------------------------------------------------------------------------- the command


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-c", "from quasistatic.cli import main; main()", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


def test_simulate_command_writes_the_trajectory_and_prints_the_events(tmp_path: Path) -> None:
    out = tmp_path / "tip.jsonl"
    result = run_cli("simulate", str(TIP), "--duration", "0.5", "--dt", "0.25", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "completed" in result.stdout and "every step certified" in result.stdout
    assert "mode change" in result.stdout and "box / table" in result.stdout
    assert Trajectory.load(out).final.time == pytest.approx(0.5)


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--duration", "-1"], "duration"),
        (["--duration", "1", "--ambiguous", "maybe"], "--ambiguous"),
        (["--duration", "1", "--out", "x.csv"], "--out"),
        (["--duration", "1", "--dt", "0"], "dt"),
        (["--duration", "1e308"], "max_steps = 100000"),  # would run for minutes to the step limit
    ],
)
def test_simulate_command_bad_input_is_one_error_line(args: list[str], words: str) -> None:
    result = run_cli("simulate", str(TIP), *args)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0]


def test_simulate_command_refuses_listed_contacts() -> None:
    result = run_cli("simulate", str(Path(__file__).resolve().parents[1] / "examples" / "squeeze.yaml"), "--duration", "1")
    assert result.returncode == 2 and result.stderr.startswith("error:") and "shapes" in result.stderr


def test_uncertified_steps_are_marked_in_the_trajectory_and_the_output(tmp_path: Path) -> None:
    out = tmp_path / "push.npz"
    result = run_cli("simulate", str(PUSH), "--duration", "0.5", "--dt", "0.25", "--first-solution", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "NOT certified" in result.stdout
    trajectory = Trajectory.load(out)
    assert not trajectory.certified and not any(s.certified for s in trajectory.steps)


def test_a_push_into_a_wall_jams_when_the_fingertip_arrives_and_names_the_blocking_contacts() -> None:
    world = qs.load_world(PUSH)
    wall = qs.ShapedMover("wall", qs.Box([0.02, 0.3, 0.3]), qs.Pose([0.06, 0.0, 0.15]))  # touching the box's +x face
    trajectory = qs.simulate(replace(world, movers=(*world.movers, wall)), duration=3.0, dt=0.5, ambiguous="min_power")
    assert trajectory.status == "jammed" and trajectory.certified
    assert trajectory.final.time == pytest.approx(2.0, abs=1e-3)  # when the 2 cm gap has closed
    jam = [e for e in trajectory.events if e.kind == "jammed"]
    assert len(jam) == 1 and jam[0].detail.endswith("blocking contacts: box/finger, box/wall")
    np.testing.assert_array_equal(trajectory.positions("box")[-1], [0.0, 0.0, 0.05])  # the box never moved
