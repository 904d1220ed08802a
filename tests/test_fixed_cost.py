"""What a simulation step, a sweep point and a small solve reuse or leave for later gives exactly what a fresh, eager
answer gives.

A recorded step's message (its claim about the forces) is worked out when read; it must equal the message of the
same state solved again, and a whole run restating its scenes must equal one building every scene anew. A sweep
point's scene, made from the scene validated once with only the swept parts rebuilt, must equal the scene read
from the file with the values set, at every point, and reject what it rejects with the same error. An unstable
answer's certificate (the fall direction, an LP) is worked out when read and equals the eager one.
"""

from __future__ import annotations

import copy
import importlib
import itertools
import math
import pickle
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import quasistatic as qs
from quasistatic.adapters import planar_pose
from quasistatic.errors import SceneError
from quasistatic.laws.polyhedral import aligned_edges
from quasistatic.model import Contact, Scene
from quasistatic.model.io import scene_to_dict
from quasistatic.sim import Inputs, SimModel, StepOptions, evaluate
from quasistatic.sim.step import StepResult
from quasistatic.solution import CertificateKind
from quasistatic.solvers.certify.diagnose import fall_certificate
from quasistatic.sweeps.params import sweep_params
from quasistatic.sweeps.result import SweepPoint, point_from_solution
from quasistatic.sweeps.scenes import PointScenes, scene_at
from quasistatic.tools.bench.families import grasp_2d
from quasistatic.tools.bench.simulation import planar_two_finger_push
from quasistatic.tools.bench.sweep_bench import SWEEP_SCENE

MESSAGE = StepResult.__dict__["message"]
simulate_module = importlib.import_module("quasistatic.sim.simulate")  # the package re-exports the function by that name
sweep_run = importlib.import_module("quasistatic.sweeps.run")


def test_a_recorded_message_is_worked_out_when_read_and_equals_a_fresh_solve() -> None:
    world = planar_two_finger_push()
    trajectory = qs.simulate(world, duration=0.3, dt=0.05)
    assert len(trajectory.steps) >= 5
    assert not any(MESSAGE.decided(step) for step in trajectory.steps)  # nothing read them yet
    model = SimModel(world, StepOptions(0.05))
    for state, step in zip(trajectory.states, trajectory.steps, strict=True):
        fresh = evaluate(model, state, Inputs()).solution.message
        assert step.message == fresh
        assert MESSAGE.decided(step)
    assert "indeterminate" in trajectory.steps[0].message  # the claim itself is in it, not only the status


def test_saving_a_run_writes_the_worked_out_messages(tmp_path) -> None:
    trajectory = qs.simulate(planar_two_finger_push(), duration=0.2, dt=0.05)
    path = tmp_path / "run.jsonl"
    trajectory.save(path)
    back = qs.Trajectory.load(path)
    assert [s.message for s in back.steps] == [s.message for s in trajectory.steps]


def _flat(trajectory: qs.Trajectory) -> list[Any]:
    """Every number and word of a run, step by step (poses, statuses, messages, twists, contacts, events)."""
    rows: list[Any] = []
    for state, step in zip(trajectory.states, trajectory.steps, strict=True):
        poses = {**state.bodies, **state.movers}
        rows.append([(name, p.position.tolist(), p.rotation.tolist()) for name, p in sorted(poses.items())])
        rows.append([step.time, step.dt, step.status, step.certified, step.message, step.choice, step.penetration])
        rows.append([(name, t.tolist()) for name, t in sorted(step.twists.items())])
        contacts = [(c.body, c.other, c.point.tolist(), c.normal.tolist(), c.gap, c.force.tolist(), c.mode) for c in step.contacts]
        rows.append(contacts + [c.slip.tolist() for c in step.contacts])
        rows.append([(e.time, e.kind, e.pair, e.detail) for e in step.events])
    return rows


TIPPING = Path(__file__).resolve().parents[1] / "examples" / "sim" / "tip_box_planar.yaml"


@pytest.mark.parametrize("scene, duration", [(planar_two_finger_push, 1.0), (lambda: TIPPING, 3.0)])
def test_a_run_restating_its_scenes_equals_one_building_each_scene_anew(
    scene: Callable[[], Any], duration: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Step for step, with the reuse on and off: the push (4 contacts throughout) and the tipping box (a corner lifts)."""
    reused = qs.simulate(scene(), duration=duration, dt=0.05)
    restated: list[bool] = []
    real = Scene.moved

    def counted(self: Scene, *args: Any) -> Scene | None:
        scene = real(self, *args)
        restated.append(scene is not None)
        return scene

    monkeypatch.setattr(Scene, "moved", counted)
    assert _flat(qs.simulate(scene(), duration=duration, dt=0.05)) == _flat(reused)
    assert sum(restated) >= len(reused.steps) - 2  # the reuse was on: nearly every scene restated
    monkeypatch.setattr(Scene, "moved", lambda self, *args: None)  # every scene built anew
    assert _flat(qs.simulate(scene(), duration=duration, dt=0.05)) == _flat(reused)


def test_a_restated_scene_equals_a_new_one_and_checks_the_new_numbers() -> None:
    world = planar_two_finger_push()
    first = world.scene()
    moved = world.moved({"box": planar_pose([0.004, 0.05], 0.01)}, mover_poses={"finger_low": planar_pose([-0.05, 0.03])})
    detection = moved.detect()
    restated = moved.scene(detection)
    fresh = Scene(
        bodies=[b.body() for b in moved.bodies],
        movers=[m.mover() for m in moved.movers],
        contacts=detection.contacts,
        dimension=2,
        friction=moved.friction,
    )
    assert scene_to_dict(restated) == scene_to_dict(fresh) and scene_to_dict(restated) != scene_to_dict(first)
    with pytest.raises(SceneError) as info:
        first.moved([[math.nan, 0.0]], [(None, None)] * 3, first.contacts)
    assert info.value.field == "bodies.box.com"
    bent = [Contact.from_trusted_arrays(c.body, c.other, c.point, 2.0 * c.normal, c.mu) for c in first.contacts]
    with pytest.raises(SceneError, match="must be a unit vector") as info:
        first.moved([b.com for b in first.bodies], [(m.twist, m.origin) for m in first.movers], bent)
    assert info.value.field == "contacts[0].normal"
    assert first.moved([b.com for b in first.bodies], [(m.twist, m.origin) for m in first.movers], first.contacts[1:]) is None


def test_a_long_run_holds_at_most_the_window_of_undecided_messages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(simulate_module, "UNDECIDED_MESSAGES", 2)
    trajectory = qs.simulate(planar_two_finger_push(), duration=0.3, dt=0.05)
    decided = [MESSAGE.decided(step) for step in trajectory.steps]
    assert all(decided[: len(decided) - 3]) and not any(decided[-2:])


# --------------------------------------------------------------------------- sweeps

SWEPT = {
    "contacts[2].point[1]": [0.02, 0.2, 0.38],
    "contacts[0].mu,contacts[1].mu": [0.0, 0.5],
    "contacts[2].normal[1]": [0.0, 0.01],  # normalised by the Scene, from the file's own numbers
    "bodies.box.mass": [1.0, 3.0],
    "bodies.box.com[0]": [0.0, 0.02],
    "movers.pusher.twist[0]": [0.01, 0.02],
    "movers.pusher.origin[1]": [0.0, 0.1],
    "gravity[0]": [0.0, 1.0],
}


def _box_data() -> dict[str, Any]:
    data = copy.deepcopy(SWEEP_SCENE)
    data["gravity"] = [0.0, -9.81]
    data["movers"]["pusher"]["origin"] = [0.0, 0.0]
    return data


@pytest.mark.parametrize("first, second", list(itertools.combinations(SWEPT, 2)))
def test_a_point_scene_equals_the_file_read_again_at_every_point(first: str, second: str) -> None:
    data = _box_data()
    axes = sweep_params(data, {first: SWEPT[first], second: SWEPT[second]})
    scenes = PointScenes(data, ".", axes)
    assert scenes.base is not None  # the reuse is on: these paths lead into parts it rebuilds alone
    for values in itertools.product(SWEPT[first], SWEPT[second]):
        assert scene_to_dict(scenes.at(values)) == scene_to_dict(scene_at(data, ".", axes, values))
    assert data == _box_data()  # the file's data is never changed


@pytest.mark.parametrize(
    "params, values",
    [
        ({"contacts[2].normal[0]": [1.0, 0.0], "contacts[2].normal[1]": [0.0, 1.0]}, (0.0, 0.0)),  # no normal at all
        ({"contacts[0].mu": [0.5, 0.6], "contacts[1].mu": [0.5, 0.6]}, (-0.1, 0.5)),
        ({"bodies.box.mass": [1.0, 2.0], "movers.pusher.twist[0]": [0.01, 0.02]}, (1.0, math.inf)),
        ({"gravity[1]": [-9.81, -1.0], "bodies.box.com[1]": [0.2, 0.3]}, (1e300, 0.2)),
    ],
)
def test_a_rejected_point_gives_the_error_of_the_file_read_again(params: dict[str, list[float]], values: tuple[float, ...]) -> None:
    data = _box_data()
    axes = sweep_params(data, params)
    with pytest.raises(SceneError) as fresh:
        scene_at(data, ".", axes, values)
    with pytest.raises(SceneError) as reused:
        PointScenes(data, ".", axes).at(values)
    assert (reused.value.field, reused.value.value, reused.value.reason) == (fresh.value.field, fresh.value.value, fresh.value.reason)
    assert str(reused.value) == str(fresh.value)


def test_a_sweep_equals_each_point_solved_from_the_file_and_leaves_messages_for_reading() -> None:
    grid = {"contacts[2].point[1]": [0.05, 0.15, 0.3], "contacts[0].mu,contacts[1].mu": [0.2, 0.8]}
    result = qs.sweep(SWEEP_SCENE, grid, chunk_size=1)  # a point a chunk: solved alone (a batch decides its claims as it proves)
    point_message = SweepPoint.__dict__["message"]
    assert not any(point_message.decided(p) for p in result.points)
    batched = qs.sweep(SWEEP_SCENE, grid)
    assert all(point_message.decided(p) for p in batched.points) and batched.points == result.points
    axes = sweep_params(SWEEP_SCENE, grid)
    for point in result.points:
        fresh = qs.solve(scene_at(SWEEP_SCENE, ".", axes, point.values))
        assert point == point_from_solution(point.index, point.values, point.refinement, fresh)  # == reads the messages
        assert point.message == fresh.message and "contact forces" in point.message


def test_a_sweep_holds_at_most_the_window_of_undecided_messages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sweep_run, "UNDECIDED_MESSAGES", 3)
    result = qs.sweep(SWEEP_SCENE, {"contacts[2].point[1]": [0.05, 0.1, 0.15, 0.3, 0.35]}, chunk_size=1)
    assert all(p.status == "solved" for p in result.points)  # a claim about the forces in every message
    decided = [SweepPoint.__dict__["message"].decided(p) for p in result.points]
    assert decided == [True, True, False, False, False]


# --------------------------------------------------------------------------- unstable certificates


def _pulled_box(pull: float) -> qs.Scene:
    """A 2-D box on two table corners (mu 0.5), nothing pushing, pulled sideways by ``pull`` N/kg."""
    box = qs.Body("box", mass=1.0, com=[0.0, 0.05])
    contacts = [qs.Contact("box", "table", point=[x, 0.0], normal=[0.0, 1.0], mu=0.5) for x in (-0.05, 0.05)]
    return qs.Scene(bodies=[box], movers=[qs.Mover("table")], contacts=contacts, dimension=2, gravity=[pull, -9.81])


UNSTABLE = [grasp_2d(m, i) for m in (2, 3, 4) for i in range(6)] + [_pulled_box(6.0), _pulled_box(20.0)]


@pytest.mark.parametrize("scene", UNSTABLE)
def test_an_unstable_certificate_is_worked_out_when_read_and_equals_the_eager_one(scene: qs.Scene) -> None:
    problem = qs.assemble(scene)
    solution = qs.solve(problem)
    if solution.status != "unstable":
        return
    certificate = solution.certificate
    assert certificate is not None and certificate.kind is CertificateKind.INFEASIBLE_EQUILIBRIUM
    fields = type(certificate).__dict__
    assert not fields["text"].decided(certificate) and not fields["data"].decided(certificate)
    eager = fall_certificate(problem, aligned_edges(problem, problem.friction.edges))
    assert eager.data  # a fall direction: the LP found one
    assert solution.to_dict()["certificate"] == eager.to_dict()
    assert certificate == eager
    again = qs.solve(problem).certificate
    assert pickle.loads(pickle.dumps(again)) == eager  # pickling works it out first


def test_unstable_scenes_are_among_the_checked_ones() -> None:
    assert sum(qs.solve(scene).status == "unstable" for scene in UNSTABLE) >= 3


# --------------------------------------------------------------------------- the console script

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = Path(sys.executable).parent / "quasistatic"
BOX = ROOT / "validation" / "scenes" / "box_push_high.yaml"


def _cli(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=600, cwd=ROOT)


def test_cli_a_value_rejected_with_another_gives_the_line_a_fresh_read_gives() -> None:
    """Both normal entries swept: (0, 0) is no normal at all. The one line names the path as reading the file says."""
    params = {"contacts[2].normal[0]": [1.0, 0.0], "contacts[2].normal[1]": [0.0, 1.0]}
    data = qs.model.io.read_scene_data(BOX)
    axes = sweep_params(data, params)
    with pytest.raises(SceneError) as fresh:
        scene_at(data, BOX.parent, axes, (0.0, 0.0))
    inner = fresh.value
    expected = SceneError("contacts[2].normal[0]", 0.0, f"the scene rejects this value ({inner.field}: {inner.reason})")
    done = _cli("sweep", BOX, "--param", "contacts[2].normal[0]=1,0", "--param", "contacts[2].normal[1]=0,1")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [f"error: {' '.join(str(expected).split())}"]
    assert "must be a unit vector" in done.stderr


def test_cli_table_messages_equal_fresh_solves(tmp_path: Path) -> None:
    import pyarrow.csv as pcsv

    done = _cli("sweep", BOX, "--param", "contacts[2].point[1]=0.05,0.3", "--out", tmp_path / "r.csv")
    assert done.returncode == 0, done.stderr
    table = pcsv.read_csv(tmp_path / "r.csv")
    data = qs.model.io.read_scene_data(BOX)
    axes = sweep_params(data, {"contacts[2].point[1]": [0.05, 0.3]})
    fresh = [qs.solve(scene_at(data, BOX.parent, axes, (h,))).message for h in (0.05, 0.3)]
    assert table.column("message").to_pylist() == fresh
    assert all("contact forces" in m for m in fresh)  # the claim the table waited for is in it
