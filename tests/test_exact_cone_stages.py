"""The stages of the certified exact-cone solve (``certify/exact_cone.py``) that decide which searches run: the
fast path's exact motion (Newton's method from Lemke's end) is proven the only one first, and where that short
attempt closes no pyramid is searched; where it pauses, the pyramid's search runs and the proof resumes where the
pyramid leaves the same motion; where a pyramid motion's modes lead to a zero that breaks them, the modes at that
zero are tried last (the 8-edge search decides where it once needed a second, 32-edge search); where the 8-edge
pyramid jams but Newton's method finds an exact motion, the sector relaxation's proof that none exists is not
tried, and the uniqueness proof certifies that motion without the 32-edge search."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.exact_cone as exact_cone
from quasistatic.laws import Problem, RawMotion
from quasistatic.solvers.certify.exact_cone import SEARCH_EDGES
from quasistatic.solvers.certify.exact_unique import PausedProof, Uniqueness
from quasistatic.solvers.result import Options
from quasistatic.tools.bench.families import grasp_3d


def _withhold_the_first_proof(monkeypatch: pytest.MonkeyPatch) -> None:
    """No fast-path motion: the solve runs the pyramid's search from the start, as before the first proof."""
    monkeypatch.setattr(exact_cone, "_newton_from_lemke", lambda problem: None)


def test_a_fast_motion_proven_first_runs_no_pyramid_search(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 4 #0: the first proof closes in its first round, so no pyramid is searched or refined; the motion
    is the one the pyramid's path certifies."""

    def no_pyramid(*args: object, **kwargs: object) -> None:
        raise AssertionError("the pyramid search ran")

    with monkeypatch.context() as patch:
        patch.setattr(exact_cone, "_pyramid_motions", no_pyramid)
        patch.setattr(exact_cone, "enumerate_motions", no_pyramid)
        solution = qs.solve(grasp_3d(4, 0))
    assert solution.status == "solved" and solution.certified, solution.message
    assert dict(solution.notes)["pyramid"].startswith("not searched") and "pyramid_search" not in dict(solution.notes)
    _withhold_the_first_proof(monkeypatch)
    searched = qs.solve(grasp_3d(4, 0))
    assert searched.certified and f"from a {SEARCH_EDGES}-edge pyramid" in dict(searched.notes)["pyramid"]
    assert solution.motion is not None and searched.motion is not None
    np.testing.assert_allclose(solution.motion.twists["object"], searched.motion.twists["object"], rtol=0, atol=1e-9)


def test_a_paused_first_proof_resumes_where_the_pyramid_leaves_its_motion(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 6 #0: its proof needs three rounds, so the first attempt pauses after one; the pyramid's only motion
    is the same, and the proof goes on from where it paused (one proof started, resumed once), not from scratch."""
    started: list[Uniqueness] = []
    resumed: list[Uniqueness] = []
    prove, resume = exact_cone.prove_unique_exact, exact_cone.resume_unique_exact

    def counting_prove(*args: Any, **kwargs: Any) -> Uniqueness:
        started.append(prove(*args, **kwargs))
        return started[-1]

    def counting_resume(paused: PausedProof, *args: Any, **kwargs: Any) -> Uniqueness:
        resumed.append(resume(paused, *args, **kwargs))
        return resumed[-1]

    monkeypatch.setattr(exact_cone, "prove_unique_exact", counting_prove)
    monkeypatch.setattr(exact_cone, "resume_unique_exact", counting_resume)
    solution = qs.solve(grasp_3d(6, 0))
    assert solution.status == "solved" and solution.certified, solution.message
    assert f"from a {SEARCH_EDGES}-edge pyramid" in dict(solution.notes)["pyramid"]
    assert len(started) == 1 and started[0].paused is not None and started[0].rounds == exact_cone.FIRST_PROOF_ROUNDS
    assert len(resumed) == 1 and resumed[0].proven and resumed[0].rounds > exact_cone.FIRST_PROOF_ROUNDS


def test_an_ambiguous_grasp_lists_the_same_motions_after_a_paused_first_proof(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 6 #1: the first proof of its fast-path motion pauses, the pyramid lists several motions and the
    paused proof is dropped: the answer (its motions, and the list's completeness) is the one without it."""
    solution = qs.solve(grasp_3d(6, 1))
    _withhold_the_first_proof(monkeypatch)
    searched = qs.solve(grasp_3d(6, 1))
    assert solution.status == searched.status == "ambiguous" and solution.certified == searched.certified
    assert solution.message == searched.message and dict(solution.notes) == dict(searched.notes)
    assert len(solution.solutions) == len(searched.solutions) >= 2
    for motion, again in zip(solution.solutions, searched.solutions, strict=True):
        np.testing.assert_allclose(motion.twists["object"], again.twists["object"], rtol=0, atol=1e-12)


def test_a_contact_the_pyramid_opens_and_the_circle_closes_refines_on_8_edges(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #1 (the first proof withheld: it certifies the fast path's motion before any pyramid): the
    8-edge pyramid opens a contact that the exact zero with its modes penetrates; closing it refines the motion,
    which the uniqueness proof then certifies (before: only the 32-edge search's did)."""
    _withhold_the_first_proof(monkeypatch)
    solution = qs.solve(grasp_3d(8, 1))
    assert solution.status == "solved" and solution.certified
    assert f"from a {SEARCH_EDGES}-edge pyramid" in dict(solution.notes)["pyramid"]


def test_repaired_modes_close_the_penetrating_contact(monkeypatch: pytest.MonkeyPatch) -> None:
    """The repaired pattern differs from the pyramid's in the contacts the zero breaks: here one opened contact closes
    (grasp-3d 8 #1, the first proof withheld)."""
    _withhold_the_first_proof(monkeypatch)
    seen: list[tuple[np.ndarray, np.ndarray | None]] = []
    real = exact_cone._repaired_modes

    def spy(problem: Problem, motion: RawMotion, modes: np.ndarray) -> np.ndarray | None:
        repaired = real(problem, motion, modes)
        seen.append((modes, repaired))
        return repaired

    monkeypatch.setattr(exact_cone, "_repaired_modes", spy)
    qs.solve(grasp_3d(8, 1))
    ((modes, repaired),) = seen
    assert repaired is not None
    changed = np.flatnonzero(modes != repaired)
    assert changed.size == 1 and modes[changed[0]] == "separating" and repaired[changed[0]] != "separating"


def _wedge_proofs(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The wedge proofs the next solves try, and their answers."""
    tried: list[str] = []
    real = exact_cone._wedge_proof

    def counting(problem: Problem, options: Options) -> str:
        tried.append(real(problem, options))
        return tried[-1]

    monkeypatch.setattr(exact_cone, "_wedge_proof", counting)
    return tried


def test_a_pyramid_that_jams_where_newton_finds_an_exact_motion_skips_the_wedge_proof_and_the_wider_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """grasp-3d 6 #3: the first proof pauses, the 8-edge pyramid jams, and the uniqueness proof of Newton's motion,
    resumed, certifies it without the relaxation's proof that none exists (which fails there) or the 32-edge
    search; with Newton's motion withheld, both run and give the same answer."""
    tried = _wedge_proofs(monkeypatch)
    solution = qs.solve(grasp_3d(6, 3))
    assert solution.status == "solved" and solution.certified and not tried
    assert "jams" in dict(solution.notes)["pyramid"]
    monkeypatch.setattr(exact_cone, "_newton_from_lemke", lambda problem: None)
    again = qs.solve(grasp_3d(6, 3))
    assert tried == [""] and again.status == "solved" and again.certified
    assert "32-edge" in dict(again.notes)["pyramid"]
    assert solution.motion is not None and again.motion is not None
    np.testing.assert_allclose(solution.motion.twists["object"], again.motion.twists["object"], rtol=0, atol=1e-12)


def test_a_jammed_grasp_still_gets_its_wedge_proof(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #3: no exact motion found, so the relaxation's proof runs and certifies the jam."""
    tried = _wedge_proofs(monkeypatch)
    solution = qs.solve(grasp_3d(8, 3))
    assert solution.status == "jammed" and solution.certified
    assert len(tried) == 1 and tried[0]
