"""The exact-cone refinement skips a changed mode pattern only where an LP proves it has no solution.

``certify/exact_cone.py`` refines each pyramid motion on the exact cones, and where that fails tries the
pattern with one or two sliding contacts rolling or separating instead. A changed pattern whose closed
contacts cannot balance the load (polygons around the circles), or whose modes no twist meets, is skipped
without its least-squares solve. Checked here: the answer is the same, to the last bit, with the test
disabled (every one of its LPs reported feasible), on scenes where it skips attempts (counted, so the check
is not vacuous); if it cut a pattern that refines, the motion found or the verdict would differ.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.exact_cone as exact_cone
from quasistatic.laws.assemble import assemble
from quasistatic.tools.bench.families import grasp_3d
from random_scenes import random_scene


def _answer(solution: qs.Solution) -> tuple[object, ...]:
    """Status, message and every motion's twists, modes and forces, exactly (not the force ranges: nothing here
    changes them, and they are worked out only when read)."""
    motions = solution.solutions or ((solution.motion,) if solution.motion is not None else ())
    return (
        solution.status,
        solution.certified,
        solution.message,
        tuple(
            (tuple(np.concatenate([np.ravel(t) for t in m.twists.values()]).tolist()), m.modes, m.forces_and_slips()[0].tolist())
            for m in motions
        ),
    )


def _with_and_without(monkeypatch: pytest.MonkeyPatch, scene: qs.Scene) -> tuple[tuple[object, ...], tuple[object, ...], int]:
    """The certified answer with the refinement's test, then with it disabled; and how many of its LPs were infeasible.
    The first proof is withheld: where it closes, no pyramid motion is refined (seed 70, grasp-3d 8 #1)."""
    monkeypatch.setattr(exact_cone, "_newton_from_lemke", lambda problem: None)
    real = exact_cone.solve_lp
    infeasible = 0

    def counting(*args: object, **kwargs: object) -> object:
        nonlocal infeasible
        result = real(*args, **kwargs)  # type: ignore[arg-type]
        infeasible += result.status == "infeasible"
        return result

    monkeypatch.setattr(exact_cone, "solve_lp", counting)
    tested = _answer(qs.solve(scene))
    monkeypatch.setattr(exact_cone, "solve_lp", lambda *a, **k: dataclasses.replace(real(*a, **k), status="optimal"))
    untested = _answer(qs.solve(scene))
    return tested, untested, infeasible


@pytest.mark.parametrize("seed", [70, 256])
def test_skipped_patterns_change_no_answer_on_random_scenes(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    tested, untested, infeasible = _with_and_without(monkeypatch, random_scene(3, seed))
    assert infeasible > 0  # the test skipped some attempts here
    assert tested == untested


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["random 169", "grasp-3d 6 #1", "grasp-3d 8 #1"])
def test_skipped_patterns_change_no_answer_slow(monkeypatch: pytest.MonkeyPatch, scene: str) -> None:
    """An ambiguous random scene (0.5 s) and the two bench grasps whose refinement tries most patterns (1.7 s each)."""
    made = random_scene(3, 169) if scene.startswith("random") else grasp_3d(int(scene[9]), int(scene[-1]))
    tested, untested, infeasible = _with_and_without(monkeypatch, made)
    assert infeasible > 0
    assert tested == untested


@pytest.mark.parametrize(("contacts", "index"), [(6, 1), (8, 1)])
def test_implied_verdicts_are_each_pattern_s_own(contacts: int, index: int) -> None:
    """One ``_Necessary`` asked of many patterns (verdicts implied between them by the closed and rolling sets)
    answers as a fresh one per pattern (its own LPs), with fewer LPs."""
    problem = assemble(grasp_3d(contacts, index))
    m = problem.n_contacts
    bases = [np.array(["sliding"] * m, dtype=object), np.array(["sliding", "separating"] * (m // 2), dtype=object)]
    patterns = [changed for base in bases for changed in exact_cone._mode_changes(base)]
    shared = exact_cone._Necessary(problem)
    together = [shared.possible(modes) for modes in patterns]
    alone = [exact_cone._Necessary(problem).possible(modes) for modes in patterns]
    assert together == alone
    assert not all(alone) and any(alone)  # both verdicts met
    assert shared.lps < len(patterns)
