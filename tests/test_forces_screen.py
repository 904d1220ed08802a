"""The exact-cone refinement's force LP is skipped only where a checked Farkas vector proves it infeasible.

Where a refined twist's least-squares forces leave the cones, ``certify/exact_cone.py`` asks an LP for forces at
that twist (``least_normal_forces``, 64-gons); most such LPs are infeasible, and HiGHS confirms each infeasible
answer with a second run. ``farkas_excludes`` first tries a non-negative fit on the LP's generators and answers
None where its residual is a checked Farkas vector. Checked here: wherever it answers, the LP finds no forces
either, and the certified answer is the same, to the last bit, with the screen turned off, on scenes where it
skips LPs (counted, so the check is not vacuous).
"""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.numerics.forces as forces
from quasistatic.laws import ModeMasks, Problem
from random_scenes import random_scene


def _answer(solution: qs.Solution) -> dict[str, object]:
    """Everything the solution reports (status, message, motions, forces, ranges), but the time it took."""
    answer = solution.to_dict()
    del answer["seconds"]
    return answer


@pytest.mark.parametrize("seed", [28, 92])
def test_screen_skips_only_infeasible_lps_and_changes_no_answer(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    real_screen, real_forces = forces.farkas_excludes, forces.least_normal_forces
    excluded = 0

    def checked(problem: Problem, q: np.ndarray, masks: ModeMasks, edge_count: int, screen: bool = False) -> np.ndarray | None:
        nonlocal excluded
        result = real_forces(problem, q, masks, edge_count, screen)
        if screen and result is None:
            edges = forces.aligned_edges(problem, edge_count, forces.slips(problem, q))
            if real_screen(forces.forces_at_twist(problem, edges, q, masks), problem.g):
                excluded += 1
                assert real_forces(problem, q, masks, edge_count) is None  # the LP finds none either
        return result

    monkeypatch.setattr("quasistatic.solvers.certify.exact_cone.least_normal_forces", checked)
    screened = _answer(qs.solve(random_scene(3, seed)))
    assert excluded > 0  # the screen answered here
    monkeypatch.setattr(forces, "farkas_excludes", lambda *args: False)
    assert _answer(qs.solve(random_scene(3, seed))) == screened


def _resting_box(pull: float) -> Problem:
    """A box on one frictional contact (mu 0.5) at its centre of mass, pulled sideways by ``pull`` times its weight."""
    weight = 9.81
    scene = qs.Scene(
        dimension=3,
        bodies=(qs.Body("box", mass=1.0, com=[0.0, 0.0, 0.0], wrench=[pull * weight, 0.0, 0.0, 0.0, 0.0, 0.0]),),
        movers=(qs.Mover("ground"),),
        contacts=(qs.Contact("box", "ground", point=[0.0, 0.0, 0.0], normal=[0.0, 0.0, 1.0], mu=0.5),),
    )
    return qs.assemble(scene)


@pytest.mark.parametrize(("pull", "excluded"), [(0.7, True), (0.3, False)])
def test_screen_decides_only_where_friction_cannot_hold_the_pull(pull: float, excluded: bool) -> None:
    """At rest (the contact rolling, 64-gon inside the circle of radius 0.5): no force balances a pull of 0.7 of
    the weight; one of 0.3 is held, and the screen must not say otherwise."""
    problem = _resting_box(pull)
    q = np.zeros(problem.n_dof)
    masks = ModeMasks(np.array([True]), np.array([True]), np.array([False]))
    edges = forces.aligned_edges(problem, 64, forces.slips(problem, q))
    assert forces.farkas_excludes(forces.forces_at_twist(problem, edges, q, masks), problem.g) is excluded
    assert (forces.least_normal_forces(problem, q, masks, 64) is None) is excluded


@pytest.mark.parametrize(("pull", "excluded"), [(0.3, True), (0.5, False)])
def test_screen_holds_a_sliding_contact_to_its_cone(pull: float, excluded: bool) -> None:
    """Sliding along the pull (+x), friction is exactly 0.5 of the weight against it: a pull of 0.3 cannot be
    balanced (the normal force alone is no generator of a sliding contact), one of 0.5 is."""
    problem = _resting_box(pull)
    q = np.zeros(problem.n_dof)
    q[0] = 1.0  # the box's velocity along x (scene-relative)
    masks = ModeMasks(np.array([True]), np.array([False]), np.array([True]))
    edges = forces.aligned_edges(problem, 64, forces.slips(problem, q))
    assert forces.farkas_excludes(forces.forces_at_twist(problem, edges, q, masks), problem.g) is excluded
    assert (forces.least_normal_forces(problem, q, masks, 64) is None) is excluded
