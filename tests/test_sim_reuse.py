"""A step whose laws equal the previous solve's bit for bit takes its certified answer again: the run is the same.

``solve(..., reuse=Reuse())`` keeps the last certified, complete answer with the exact laws it answered; a
simulation keeps one per run (``StepOptions.reuse``, on by default). These tests check that a run with it
on is the run with it off, saved byte for byte; that it reuses only for laws equal to the last bit (and the
same options and method); and that a kept answer is still audited on the new scene.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws import Problem, assemble
from quasistatic.sim import Inputs, SimModel, State, StepOptions, advance, evaluate
from quasistatic.solve import Reuse
from quasistatic.tools.bench.simulation import planar_tipping_box, planar_two_finger_push

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "sim"


@pytest.mark.parametrize(
    ("scene", "duration", "dt"),
    [
        (EXAMPLES / "push_planar.yaml", 5.0, 0.05),
        (EXAMPLES / "tip_box_planar.yaml", 10.0, 0.25),
        pytest.param(EXAMPLES / "push_box.yaml", 0.5, 0.5, marks=pytest.mark.slow),
    ],
)
def test_a_run_with_reuse_is_the_run_without_it_saved_byte_for_byte(scene: Path, duration: float, dt: float, tmp_path: Path) -> None:
    """The planar push translates (most steps reuse); the tipping box turns, so its laws change every step (none do);
    the 3-D push is ambiguous at every step, so the least-power motion is taken from a reused list of motions."""
    if scene.name == "push_box.yaml":
        pytest.importorskip("coal")
    runs = [qs.simulate(scene, duration=duration, dt=dt, ambiguous="min_power", reuse=reuse) for reuse in (False, True)]
    files = [run.save(tmp_path / f"run_{i}.jsonl").read_text(encoding="utf-8") for i, run in enumerate(runs)]
    assert files[0] == files[1]
    assert runs[1].status == runs[0].status and runs[1].certified and len(runs[1].steps) >= 2


def test_the_planar_push_reuses_most_steps_and_each_is_the_fresh_answer() -> None:
    world = planar_two_finger_push()
    models = [SimModel(world, StepOptions(0.05, reuse=reuse)) for reuse in (True, False)]
    states = [State.of(world), State.of(world)]
    for _ in range(40):
        reused, fresh = (evaluate(model, state, Inputs()) for model, state in zip(models, states, strict=True))
        assert reused.solution.status == fresh.solution.status == "solved" and reused.solution.certified
        assert np.array_equal(reused.twist("box"), fresh.twist("box"))
        assert reused.solution.motion is not None and reused.solution.motion.audit.passed
        states = [advance(reused, 0.05), advance(fresh, 0.05)]
    assert models[0].reuse is not None and models[0].reuse.hits >= 30  # the box only translates: its laws repeat
    assert models[1].reuse is None


def _push_problem() -> Problem:
    world = planar_two_finger_push()
    return assemble(world.scene(world.detect()))


def test_reuse_takes_an_answer_again_only_for_the_same_laws_options_and_method() -> None:
    problem = _push_problem()
    memory = Reuse()
    first = qs.solve(problem, reuse=memory)
    assert first.status == "solved" and first.certified and memory.hits == 0
    again = qs.solve(assemble(problem.scene), reuse=memory)  # assembled anew: equal arrays, another Problem
    assert memory.hits == 1 and dict(again.notes)["reused"]
    assert np.array_equal(again.motion.twists["box"], first.motion.twists["box"])  # type: ignore[union-attr]
    assert again.message == first.message and again.certified
    nudged = dataclasses.replace(problem, b=np.nextafter(problem.b, np.inf))  # one ulp on every mover velocity
    qs.solve(nudged, reuse=memory)
    qs.solve(problem, max_solutions=3, reuse=memory)
    qs.solve(problem, method="scip", reuse=memory)
    assert memory.hits == 1  # none of the three is the kept answer's question
    assert "reused" not in dict(qs.solve(problem).notes)  # without a memory, every solve is proven anew


def test_only_certified_complete_answers_are_kept() -> None:
    problem = _push_problem()
    memory = Reuse()
    qs.solve(problem, certify=False, reuse=memory)  # the fast path: not certified
    assert memory.result is None
    qs.solve(problem, reuse=memory)
    assert memory.result is not None
    stuck = dataclasses.replace(problem, b=np.zeros_like(problem.b), g=-problem.g)  # load pushes it into the table
    jammed_or_unstable = qs.solve(stuck, reuse=memory)
    assert jammed_or_unstable.status in ("jammed", "unstable") and memory.result is None


def test_a_kept_answer_that_fails_the_audit_on_the_new_scene_is_not_reported() -> None:
    problem = _push_problem()
    memory = Reuse()
    truth = qs.solve(problem, reuse=memory)
    assert memory.result is not None
    wrong = dataclasses.replace(memory.result.motions[0], q=2.0 * memory.result.motions[0].q)  # twice the true twist
    memory.result = dataclasses.replace(memory.result, motions=(wrong,))
    answer = qs.solve(problem, reuse=memory)
    assert memory.hits == 1  # taken again, and judged by the audit
    assert answer.status == "solved" and answer.method == "scip" and answer.fallback[0].method == "certified"
    assert np.allclose(answer.motion.twists["box"], truth.motion.twists["box"])  # type: ignore[union-attr]


@pytest.mark.parametrize(
    ("build", "example", "reuses"),
    [(planar_two_finger_push, "push_planar.yaml", True), (planar_tipping_box, "tip_box_planar.yaml", False)],
)
def test_the_bench_rows_run_their_examples_and_only_the_translating_push_reuses(build, example: str, reuses: bool, tmp_path: Path) -> None:
    """The bench's two planar rows are the examples they name (the same run, saved byte for byte), and the turning
    box is the row that cannot reuse: a bench figure for it measures proofs, not the memory."""
    built, loaded = qs.simulate(build(), duration=2.0, dt=0.05), qs.simulate(EXAMPLES / example, duration=2.0, dt=0.05)
    files = [run.save(tmp_path / f"run_{i}.jsonl").read_text(encoding="utf-8") for i, run in enumerate((built, loaded))]
    _headers, steps = zip(*(text.split("\n", 1) for text in files), strict=True)
    assert steps[0] == steps[1] and len(built.steps) >= 20  # the header names the source file, which differs
    world = build()
    model, state = SimModel(world, StepOptions(0.05)), State.of(world)
    for _ in range(20):
        evaluation = evaluate(model, state, Inputs())
        state = advance(evaluation, 0.05)
    assert model.reuse is not None and (model.reuse.hits >= 15 if reuses else model.reuse.hits <= 2)
