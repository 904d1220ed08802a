"""solve_many: the hand-derived answers, in order, the same as solving one by one, and clear errors on bad input.

Each comparison of ``solve_many`` with ``solve`` (or of one way of running
workers with another) also checks catalogue cases (``catalogue.py``) placed
among the items against their hand-derived answers, so that a batch that
dropped an option, reordered its items or lost a motion cannot pass by
agreeing with itself.
"""

from __future__ import annotations

import gc
import subprocess
import sys
import weakref

import numpy as np
import pytest

import quasistatic as qs
from catalogue import BY_NAME, Case, describe, matches
from quasistatic.tools.bench.families import grasp_2d, grasp_3d

# Frictionless catalogue cases, one of each status, each with a distinct hand-derived answer.
FRICTIONLESS = [
    BY_NAME[n] for n in ("held-slope-pushed", "push-into-wall", "lift-between-pins", "topple-on-fingertip", "box-alone-on-table")
]
FRICTIONAL = [BY_NAME[n] for n in ("box-push-low", "box-push-high", "slope-slides-30")]


def _same(a: qs.Solution, b: qs.Solution) -> None:
    assert a.status == b.status
    assert a.method == b.method
    assert a.modes == b.modes
    assert a.twists.keys() == b.twists.keys()
    for name in a.twists:
        np.testing.assert_allclose(a.twists[name], b.twists[name], rtol=0, atol=1e-12)
    assert [c.normal_force for c in a.contacts] == pytest.approx([c.normal_force for c in b.contacts], abs=1e-9)


def _as_derived(case: Case, sol: qs.Solution) -> None:
    """The case's hand-derived answer: its status, then its motion, every kind of motion it lists, or its diagnosis."""
    assert sol.status == case.status, (case.name, sol.message)
    if case.status == "solved":
        assert sol.motion is not None and matches(sol.motion, case.motions[0], exact=True), describe(sol.motion, *case.motions)
    elif case.status == "ambiguous":
        for kind in case.motions:
            assert any(matches(m, kind, exact=True) for m in sol.solutions), (case.name, kind)
    else:
        assert sol.diagnosis is case.diagnosis, (case.name, sol.diagnosis)


@pytest.fixture(scope="module")
def problems() -> list[qs.Problem]:
    # Frictionless 2-D and 3-D grasps: a mix of solved and unstable answers.
    return [qs.assemble(grasp_2d(3, i, friction="none")) for i in range(6)] + [
        qs.assemble(grasp_3d(8, i, friction="none")) for i in range(3)
    ]


def test_serial_matches_one_by_one(problems: list[qs.Problem]) -> None:
    items = [*problems, *(c.scene for c in FRICTIONLESS)]
    batch = qs.solve_many(items, method="lp")
    assert len(batch) == len(items)
    for problem, solution in zip(problems, batch, strict=False):
        _same(solution, qs.solve(problem, method="lp"))
    assert {s.status for s in batch[: len(problems)]} >= {"solved", "unstable"}
    for case, solution in zip(FRICTIONLESS, batch[len(problems) :], strict=True):
        _as_derived(case, solution)


def test_parallel_matches_one_by_one_in_order(problems: list[qs.Problem]) -> None:
    """The catalogue cases are interleaved with the grasps: each answer must be its own case's, in input order."""
    cases = [*FRICTIONLESS, *FRICTIONAL]
    items: list[qs.Problem | qs.Scene] = []
    for i, problem in enumerate(problems):
        items += [problem, cases[i % len(cases)].scene]
    batch = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=2)
    for i, problem in enumerate(problems):
        _same(batch[2 * i], qs.solve(problem))
        _as_derived(cases[i % len(cases)], batch[2 * i + 1])


def test_scenes_and_problems_mix() -> None:
    case = BY_NAME["box-push-high"]
    solutions = qs.solve_many([case.scene, qs.assemble(case.scene)], method="scip")
    for solution in solutions:
        _as_derived(case, solution)
        assert solution.certified


def test_options_are_passed_on() -> None:
    """``max_solutions`` limits the list: the grasp has exactly four kinds of motion (catalogue
    ``grasp-lift-mu05``: both fingers rolling, both sliding, one of each either way), so 2 lists two of
    them and says the list is incomplete; ``certify=False`` gives the fast path's unproven motion."""
    case = BY_NAME["grasp-lift-mu05"]
    limited, complete = qs.solve_many([case.scene], max_solutions=2) + qs.solve_many([case.scene], max_solutions=16)
    assert limited.status == "ambiguous" and len(limited.solutions) == 2 and limited.search_complete is False
    kinds = (*case.motions, *case.also)
    assert all(any(matches(m, kind, exact=False) for kind in kinds) for m in limited.solutions)
    assert complete.status == "ambiguous" and len(complete.solutions) == 4 and complete.search_complete is True
    _as_derived(case, complete)
    pushed = BY_NAME["box-push-low"]
    first, proven = qs.solve_many([pushed.scene], certify=False) + qs.solve_many([pushed.scene])
    _as_derived(pushed, first)
    _as_derived(pushed, proven)
    assert (first.certified, proven.certified) == (False, True)


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
    """Both ways of running workers (forked, inheriting the items; joblib, pickling them) give the hand-derived
    answers of the catalogue cases among the items, and answer alike on the others."""
    from quasistatic import batch

    cases = [*FRICTIONLESS, *FRICTIONAL]
    items = [*problems, *(qs.assemble(c.scene) for c in cases), *(qs.assemble(grasp_2d(3, i)) for i in range(5))]
    serial = qs.solve_many(items, method="auto")
    forked = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=3)
    monkeypatch.setattr(batch, "_can_fork", lambda: False)  # no public switch between the two ways
    shipped = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=3)
    for a, b, c in zip(serial, forked, shipped, strict=True):
        _same(b, a)
        _same(c, a)
    for route in (serial, forked, shipped):
        for case, solution in zip(cases, route[len(problems) :], strict=False):
            _as_derived(case, solution)


def test_forked_workers_leave_no_reference_to_the_items() -> None:
    """After a forked batch the items are freed as soon as the caller drops them (the workers inherit them as
    arguments; nothing in this process keeps them)."""
    items = [qs.assemble(c.scene) for c in FRICTIONLESS * 2]
    refs = [weakref.ref(item) for item in items]
    solutions = qs.solve_many(items, method="auto", n_jobs=2, chunks_per_job=2)
    for case, solution in zip(FRICTIONLESS * 2, solutions, strict=True):
        _as_derived(case, solution)
    del items, solutions
    gc.collect()
    assert [ref() for ref in refs] == [None] * len(refs)


def test_failing_item_is_named_by_a_worker() -> None:
    scenes = [grasp_2d(2, 0, friction="none")] * 3 + [grasp_2d(2, 1)]  # the last has friction: lp refuses it
    with pytest.raises(qs.QuasistaticError, match="frictionless") as info:
        qs.solve_many(scenes, method="lp", n_jobs=2, chunks_per_job=1)
    assert "while solving problems[3]" in info.value.__notes__


FORKED_THREADS = """
import threading
import quasistatic as qs
from quasistatic.tools.bench.families import grasp_2d

items = [qs.assemble(grasp_2d(3, i)) for i in range(12)]
before = threading.active_count()
qs.solve_many(items, method="fast", n_jobs=2, chunks_per_job=2)
print(before, threading.active_count())
"""


def test_forked_workers_leave_no_thread_behind() -> None:
    """A thread left running (a queue's feeder) would keep the next call from forking: it would fall back to
    joblib, which pickles every item (measured 6x slower on the benchmark's batch). Run in a fresh process: the
    test runner's own threads (pytest-xdist's) would keep it from forking at all."""
    run = subprocess.run([sys.executable, "-c", FORKED_THREADS], capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["1", "1"]  # one thread before (so the workers were forked), and after
