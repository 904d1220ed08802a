"""The stages of the certified exact-cone solve (``certify/exact_cone.py``) that decide which searches run: where a
pyramid motion's modes lead to a zero that breaks them, the modes at that zero are tried last (the 8-edge search
decides where it once needed a second, 32-edge search); where the 8-edge pyramid jams but Newton's method from
Lemke's end finds an exact motion, the sector relaxation's proof that none exists is not tried, and the
uniqueness proof certifies that motion without the 32-edge search."""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.exact_cone as exact_cone
from quasistatic.laws import Problem, RawMotion
from quasistatic.solvers.certify.exact_cone import SEARCH_EDGES
from quasistatic.solvers.result import Options
from quasistatic.tools.bench.families import grasp_3d


def test_a_contact_the_pyramid_opens_and_the_circle_closes_refines_on_8_edges() -> None:
    """grasp-3d 8 #1: the 8-edge pyramid opens a contact that the exact zero with its modes penetrates; closing it
    refines the motion, which the uniqueness proof then certifies (before: only the 32-edge search's did)."""
    solution = qs.solve(grasp_3d(8, 1))
    assert solution.status == "solved" and solution.certified
    assert f"from a {SEARCH_EDGES}-edge pyramid" in dict(solution.notes)["pyramid"]


def test_repaired_modes_close_the_penetrating_contact(monkeypatch: pytest.MonkeyPatch) -> None:
    """The repaired pattern differs from the pyramid's in the contacts the zero breaks: here one opened contact closes."""
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
    """grasp-3d 6 #3: the 8-edge pyramid jams, Newton's method from Lemke's end finds the exact motion, and the
    uniqueness proof certifies it without the relaxation's proof that none exists (which fails there) or the
    32-edge search; with Newton's motion withheld, both run and give the same answer."""
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
