"""The exact-cone refinement of a pyramid motion (``certify/exact_cone.py``): where the pyramid's modes lead to a
zero that breaks them, the modes at that zero are tried last, so the 8-edge search decides where it once needed a
second, 32-edge search."""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.exact_cone as exact_cone
from quasistatic.laws import Problem, RawMotion
from quasistatic.solvers.certify.exact_cone import SEARCH_EDGES
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
