"""solve_many: the same answers as solving one by one, in order, and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.tools.bench.families import grasp_2d, grasp_3d


def _same(a: qs.Solution, b: qs.Solution) -> None:
    assert a.status == b.status
    assert a.method == b.method
    assert a.modes == b.modes
    assert a.twists.keys() == b.twists.keys()
    for name in a.twists:
        np.testing.assert_allclose(a.twists[name], b.twists[name], rtol=0, atol=1e-12)
    assert [c.normal_force for c in a.contacts] == pytest.approx([c.normal_force for c in b.contacts], abs=1e-9)


@pytest.fixture(scope="module")
def problems() -> list[qs.Problem]:
    # Frictionless 2-D and 3-D grasps: a mix of solved and unstable answers.
    return [qs.assemble(grasp_2d(3, i, friction="none")) for i in range(6)] + [
        qs.assemble(grasp_3d(8, i, friction="none")) for i in range(3)
    ]


def test_serial_matches_one_by_one(problems: list[qs.Problem]) -> None:
    batch = qs.solve_many(problems, method="lp")
    assert len(batch) == len(problems)
    for problem, solution in zip(problems, batch, strict=True):
        _same(solution, qs.solve(problem, method="lp"))
    assert {s.status for s in batch} >= {"solved", "unstable"}


def test_parallel_matches_one_by_one_in_order(problems: list[qs.Problem]) -> None:
    batch = qs.solve_many(problems, method="auto", n_jobs=2, chunks_per_job=2)
    for problem, solution in zip(problems, batch, strict=True):
        _same(solution, qs.solve(problem))


def test_scenes_and_problems_mix() -> None:
    scene = grasp_2d(2, 0)
    solutions = qs.solve_many([scene, qs.assemble(scene)], method="scip")
    _same(solutions[0], solutions[1])
    _same(solutions[0], qs.solve(scene, method="scip"))


def test_options_are_passed_on() -> None:
    scene = grasp_2d(3, 0)
    (solution,) = qs.solve_many([scene], all_solutions=True, max_solutions=4)
    _same(solution, qs.solve(scene, all_solutions=True, max_solutions=4))


def test_empty_and_generator_input() -> None:
    assert qs.solve_many([]) == []
    assert len(qs.solve_many(grasp_2d(3, i, friction="none") for i in range(2))) == 2


def test_item_that_is_not_a_scene_is_named() -> None:
    with pytest.raises(TypeError, match=r"problems\[1\]: expected a Scene or a Problem, got dict"):
        qs.solve_many([grasp_2d(2, 0), {"bodies": []}])


def test_unknown_method() -> None:
    with pytest.raises(ValueError, match="unknown method 'simplex'"):
        qs.solve_many([grasp_2d(2, 0)], method="simplex")


@pytest.mark.parametrize("n_jobs", [0, -2, 1.5, True, "2"])
def test_bad_n_jobs(n_jobs: object) -> None:
    with pytest.raises(ValueError, match="n_jobs must be"):
        qs.solve_many([grasp_2d(2, 0)], n_jobs=n_jobs)  # type: ignore[arg-type]


def test_bad_chunks_per_job() -> None:
    with pytest.raises(ValueError, match="chunks_per_job"):
        qs.solve_many([grasp_2d(2, 0)], chunks_per_job=0)


def test_failing_item_is_named() -> None:
    scenes = [grasp_2d(2, 0, friction="none"), grasp_2d(2, 1)]  # the second has friction: lp refuses it
    with pytest.raises(qs.QuasistaticError, match="frictionless") as info:
        qs.solve_many(scenes, method="lp")
    assert "while solving problems[1]" in info.value.__notes__


def test_forked_and_joblib_workers_give_the_same_answers(problems: list[qs.Problem], monkeypatch: pytest.MonkeyPatch) -> None:
    """Both ways of running workers (forked, inheriting the items; joblib, pickling them) answer alike."""
    from quasistatic import batch

    items = problems + [qs.assemble(grasp_2d(3, i)) for i in range(5)]
    serial = qs.solve_many(items, method="auto")
    forked = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=3)
    monkeypatch.setattr(batch, "_can_fork", lambda: False)
    shipped = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=3)
    for a, b, c in zip(serial, forked, shipped, strict=True):
        _same(b, a)
        _same(c, a)


def test_failing_item_is_named_by_a_worker() -> None:
    scenes = [grasp_2d(2, 0, friction="none")] * 3 + [grasp_2d(2, 1)]  # the last has friction: lp refuses it
    with pytest.raises(qs.QuasistaticError, match="frictionless") as info:
        qs.solve_many(scenes, method="lp", n_jobs=2, chunks_per_job=1)
    assert "while solving problems[3]" in info.value.__notes__
