"""The sector relaxation of exact cones (``certify/wedge.py``) decided by the mode branch and bound
(``patterns.relaxation_excluded``) against SCIP's MILP of the same relaxation (``wedge._relaxation``).

Soundness (random scenes, one set with every other contact frictionless): the branch and bound excludes the
relaxation only where SCIP proves it infeasible, and never where the exact laws have a motion (the certified
solve found one). It decides: on the random scenes SCIP calls infeasible it excludes most, and the jammed
benchmark grasps get their wedge proof from it with SCIP's relaxation never built. On a box rolling on a table
(gap rows of rank 3): the closed rows still bound the twists, the leaves that pin the motion's twist are passed
over, and Farkas vectors handed to a search exclude nothing they do not prove. A round resumed from the last
(its excluded regions passed over) excludes only what SCIP proves infeasible, and only where its sectors refine
those the regions were found with.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.patterns as patterns
import quasistatic.solvers.certify.wedge as wedge
from quasistatic.solvers.certified import solve_cheap_certified
from quasistatic.solvers.certify.patterns import relaxation_excluded
from quasistatic.solvers.result import Options
from quasistatic.tools.bench.families import grasp_3d
from random_scenes import random_scene


def _scene(seed: int, frictionless_every: int = 0) -> qs.Scene:
    """Odd seeds: a box on a table and fingers; even: an ellipsoid grasp; with ``frictionless_every``, every such
    contact (the first, ...) frictionless."""
    scene = random_scene(3, 3000 + seed, friction="exact") if seed % 2 else grasp_3d(2 + seed % 3, 3000 + seed)
    if not frictionless_every:
        return scene
    contacts = tuple(dataclasses.replace(c, mu=0.0) if i % frictionless_every == 0 else c for i, c in enumerate(scene.contacts))
    return dataclasses.replace(scene, contacts=contacts)


def _uniform(problem: qs.Problem, count: int) -> list[np.ndarray]:
    return [2.0 * np.pi * np.arange(count + 1) / count for _ in range(problem.n_contacts)]


@pytest.mark.parametrize(("count", "frictionless_every"), [(8, 0), pytest.param(16, 0, marks=pytest.mark.slow), (8, 2)])  # 16: 5.5 s
def test_the_branch_and_bound_excludes_the_relaxation_only_where_scip_proves_it_infeasible(count: int, frictionless_every: int) -> None:
    infeasible = excluded = 0
    for seed in range(30):
        problem = qs.assemble(_scene(seed, frictionless_every))
        proof = relaxation_excluded(problem, _uniform(problem, count))
        status = wedge._relaxation(problem, Options(time_limit=30.0).start_clock(), _uniform(problem, count), None)[0]
        assert status in ("feasible", "infeasible")
        if proof.excluded:
            assert status == "infeasible", f"seed {seed}: excluded by the branch and bound, feasible for SCIP"
        else:
            assert proof.sectors is None or proof.q is not None
        infeasible += status == "infeasible"
        excluded += proof.excluded
    assert infeasible >= 3 and excluded >= 0.8 * infeasible, f"{excluded} excluded of {infeasible} infeasible"


def test_the_branch_and_bound_never_excludes_a_scene_with_an_exact_motion() -> None:
    moving = 0
    for seed in range(40):
        scene = _scene(seed)
        solution = qs.solve(scene)
        if solution.status not in ("solved", "ambiguous"):
            continue
        moving += 1
        problem = qs.assemble(scene)
        for count in (8, 16, 32):
            assert not relaxation_excluded(problem, _uniform(problem, count)).excluded, f"seed {seed}, {count} sectors"
    assert moving >= 10


@pytest.mark.parametrize("instance", [1, 2])
def test_jammed_grasps_are_proven_by_the_branch_and_bound_without_scip(instance: int, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_scip(*args: object) -> None:
        raise AssertionError("SCIP's sector relaxation was built")

    monkeypatch.setattr(wedge, "_relaxation", no_scip)
    solution = qs.solve(grasp_3d(4, instance))
    assert solution.status == "jammed" and solution.certified
    assert solution.certificate is not None and solution.certificate.kind is qs.CertificateKind.SECTOR_RELAXATION
    assert wedge.BY_BRANCH_AND_BOUND in solution.certificate.text


@pytest.fixture(scope="module")
def rolling_box() -> tuple[qs.Problem, np.ndarray]:
    """A box rolling on a table with four coplanar supports (gap rows of rank 3), and its motion's twist."""
    problem = qs.assemble(random_scene(3, 186))
    motion = solve_cheap_certified(problem, Options(time_limit=30.0)).motions[0]
    assert set(qs.laws.contact_modes(problem, motion.q)) == {"rolling"}
    return problem, motion.q


def test_closed_rows_of_deficient_rank_leave_a_line_that_holds_the_motion(rolling_box: tuple[qs.Problem, np.ndarray]) -> None:
    problem, q = rolling_box
    layout, _, _ = patterns._sector_layout(problem, _uniform(problem, 4), patterns.TreeShape(range(problem.n_contacts)))
    m = problem.n_contacts
    equal = [*range(m), m, 2 * m]  # every gap shut, contact 0 still: six rows of rank 5
    width = layout.loads.shape[1] // m
    for by_rank in (False, True):
        rows = patterns._Rows.of(layout, problem.g, width, 100, seed=q, form=None, by_rank=by_rank)
        closed = patterns._closed_set(rows, equal, len(equal))
        if not by_rank:
            assert closed is patterns._UNKNOWN  # what the pyramid search still says of such rows
            continue
        assert isinstance(closed, patterns._ClosedSet) and closed.free == 1
        offset = q - closed.q0
        assert np.linalg.norm(offset - (offset @ closed.direction) * closed.direction) <= closed.radius + 1e-12


def test_the_far_part_passes_over_the_leaves_that_pin_the_motions_twist(rolling_box: tuple[qs.Problem, np.ndarray]) -> None:
    problem, q = rolling_box
    sectors = _uniform(problem, 4)
    assert not relaxation_excluded(problem, sectors).excluded  # the motion is a point of the relaxation
    proof = relaxation_excluded(problem, sectors, twist=q)
    assert proof.excluded  # every leaf holding it holds it alone


def test_farkas_vectors_passed_to_a_search_are_checked_on_its_own_columns(rolling_box: tuple[qs.Problem, np.ndarray]) -> None:
    problem, _ = rolling_box
    sectors = _uniform(problem, 4)
    rng = np.random.default_rng(0)
    false = [rng.normal(size=problem.n_dof) for _ in range(40)] + [-problem.g, problem.g]
    proof = relaxation_excluded(problem, sectors, farkas=false)
    assert not proof.excluded  # the box has a motion: no vector may exclude it
    refined = relaxation_excluded(problem, [np.sort(np.append(s, s[0] + 0.1)) for s in sectors], farkas=proof.farkas)
    assert not refined.excluded and all(v.shape == (problem.n_dof,) for v in proof.farkas)


def test_a_search_resumed_from_the_last_excludes_only_what_scip_proves_infeasible() -> None:
    """Each round refines the surviving leaf's sectors and passes over what the last excluded (its regions are
    products of sets of modes whose polygons hold the refined ones'): a resumed exclusion is SCIP's too."""
    resumed = 0
    for scene in [grasp_3d(4, 1), grasp_3d(4, 2), *(_scene(seed) for seed in range(30))]:  # the grasps jam
        problem = qs.assemble(scene)
        sectors, passed = _uniform(problem, 4), None
        for _ in range(6):
            proof = relaxation_excluded(problem, sectors, passed=passed)
            if proof.excluded and passed is not None and passed.regions:
                resumed += 1
                status = wedge._relaxation(problem, Options(time_limit=30.0).start_clock(), sectors, None)[0]
                assert status == "infeasible", "excluded when resumed, feasible for SCIP"
            if proof.sectors is None or not wedge.split_sectors(sectors, proof.sectors):
                break
            passed = proof.passed
    assert resumed >= 3


def test_regions_passed_over_only_where_the_sectors_refine_those_they_were_found_with() -> None:
    problem = qs.assemble(grasp_3d(4, 1))  # jammed
    sectors = _uniform(problem, 4)
    proof = relaxation_excluded(problem, sectors)
    assert proof.passed is not None and proof.passed.regions  # a leaf survived after others were excluded
    layout, _, sets = patterns._sector_layout(problem, sectors, patterns.TreeShape(range(problem.n_contacts)))
    assert patterns._PassedOver.of(sets, sectors, None, proof.passed).regions  # the same sectors: kept
    merged = [np.delete(s, 1) for s in sectors]  # a boundary gone: a wider polygon than those excluded
    _, _, merged_sets = patterns._sector_layout(problem, merged, patterns.TreeShape(range(problem.n_contacts)))
    assert not patterns._PassedOver.of(merged_sets, merged, None, proof.passed).regions
    assert not patterns._PassedOver.of(sets, sectors, np.zeros(problem.n_dof), proof.passed).regions  # another twist


def test_rounds_resumed_reach_the_same_verdict_in_fewer_nodes() -> None:
    problem = qs.assemble(grasp_3d(4, 1))  # jammed: its relaxation survives four refinements, then is excluded
    totals = []
    for resume in (False, True):
        sectors, passed, nodes = _uniform(problem, 4), None, 0
        for _ in range(8):
            proof = relaxation_excluded(problem, sectors, passed=passed if resume else None)
            nodes += proof.nodes
            if proof.excluded or proof.sectors is None or not wedge.split_sectors(sectors, proof.sectors):
                break
            passed = proof.passed
        assert proof.excluded
        totals.append(nodes)
    assert totals[1] < totals[0]
