"""What a simulation step and a sweep point reuse or leave for later gives exactly what a fresh, eager answer gives.

A recorded step's message (its claim about the forces) is worked out when read; it must equal the message of the
same state solved again. A sweep point's scene, made from the scene validated once with only the swept parts
rebuilt, must equal the scene read from the file with the values set, at every point.
"""

from __future__ import annotations

import importlib

import pytest

import quasistatic as qs
from quasistatic.sim import Inputs, SimModel, StepOptions, evaluate
from quasistatic.sim.step import StepResult
from quasistatic.tools.bench.simulation import planar_two_finger_push

MESSAGE = StepResult.__dict__["message"]
simulate_module = importlib.import_module("quasistatic.sim.simulate")  # the package re-exports the function by that name


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


def test_a_long_run_holds_at_most_the_window_of_undecided_messages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(simulate_module, "UNDECIDED_MESSAGES", 2)
    trajectory = qs.simulate(planar_two_finger_push(), duration=0.3, dt=0.05)
    decided = [MESSAGE.decided(step) for step in trajectory.steps]
    assert all(decided[: len(decided) - 3]) and not any(decided[-2:])
