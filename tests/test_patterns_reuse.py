"""The mode branch and bound's reuse of earlier work (``prove_by_patterns(..., reuse=True)``, the default) against
the same search with every node worked out from its own rows (``reuse=False``).

With reuse, a child that keeps its parent's closed rows narrows the parent's line or polygon of twists by its new
rows, and a balancing fit found at an earlier node serves any node whose columns hold its support. Neither may
change what is proven: on random planar and 3-D scenes (the generators of ``test_patterns.py`` and
``test_patterns_3d.py``) and the benchmark grasps, both give the same verdict, the same motions and the same
number of nodes; and reuse does make fewer fits on the grasps (it is not switched off by accident).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
from quasistatic.solvers.certify.cheap import seed_point
from quasistatic.solvers.certify.patterns import PatternProof, prove_by_patterns
from quasistatic.tools.bench.families import grasp_2d, grasp_3d
from random_scenes import random_scene

FRICTIONS_3D = ("pyramid:4", "pyramid:8", "exact")
SEARCH_EDGES_3D = 8  # the pyramid the exact cones' search runs on


def _scene(dimension: int, seed: int) -> qs.Scene:
    if dimension == 2:
        return random_scene(2, 1000 + seed) if seed % 2 else grasp_2d(2 + seed % 7, 1000 + seed)
    friction = FRICTIONS_3D[seed % 3]
    return random_scene(3, 2000 + seed, friction=friction) if seed % 2 else grasp_3d(2 + seed % 3, 1000 + seed, friction=friction)


def _both(scene: qs.Scene) -> tuple[PatternProof, PatternProof]:
    problem = qs.assemble(scene)
    polyhedral = problem.friction.is_polyhedral(problem.dimension)
    edges = problem.friction.edges if polyhedral else (2 if problem.dimension == 2 else SEARCH_EDGES_3D)
    form = polyhedral_form(problem, aligned_edges(problem, edges))
    seed = seed_point(form)
    return prove_by_patterns(form, seed), prove_by_patterns(form, seed, reuse=False)


def _assert_same(reused: PatternProof, fresh: PatternProof) -> None:
    assert reused.verdict is fresh.verdict
    assert reused.nodes == fresh.nodes
    assert len(reused.motions) == len(fresh.motions)
    for a, b in zip(reused.motions, fresh.motions, strict=True):
        assert a.continuum == b.continuum
        np.testing.assert_allclose(a.q, b.q, rtol=0.0, atol=1e-12)
        assert len(a.extremes) == len(b.extremes)
        for e, f in zip(a.extremes, b.extremes, strict=True):
            np.testing.assert_allclose(e, f, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("dimension", [2, 3])
def test_reuse_proves_the_same_on_random_scenes(dimension: int) -> None:
    for seed in range(60):
        _assert_same(*_both(_scene(dimension, seed)))


@pytest.mark.parametrize(("make", "contacts"), [(grasp_3d, 4), (grasp_3d, 6), (grasp_2d, 6), (grasp_2d, 8)])
def test_reuse_proves_the_same_on_the_benchmark_grasps_with_fewer_fits(make: Callable[[int, int], qs.Scene], contacts: int) -> None:
    fewer = False
    for instance in range(3):
        reused, fresh = _both(make(contacts, instance))
        _assert_same(reused, fresh)
        assert reused.fits <= fresh.fits
        fewer |= reused.fits < fresh.fits
    assert fewer, "the kept fits served no node"
