"""Whole-array twins (what runs without numba) of the frictionless LP's and the audit's kernels.

Each twin must give its compiled kernel's results: the same masks, ranks and
verdicts, residuals to round-off. Without numba the module names are the twins
themselves, so the comparisons need numba to mean anything. With numba the
twins of the LP's analysis call the compiled rank test; the LAPACK singular
values it uses without numba are held to the Jacobi kernel's ranks apart.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

import quasistatic as qs
from quasistatic.solvers import lp
from quasistatic.solvers.numerics.lcp import PIVOTS_PER_ROW
from quasistatic.tolerances import FORCE_RANK, MODE_SPEED, MOTION_RANK, PIVOT, ZERO
from quasistatic.tools.bench.families import FAMILIES

numba = pytest.importorskip("numba")


def _rank_deficient(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    rank = int(rng.integers(0, min(rows, cols) + 1))
    if rank == 0:
        return np.zeros((rows, cols))
    return rng.normal(size=(rows, rank)) @ rng.normal(size=(rank, cols))


def _matrices(rng: np.random.Generator) -> Iterator[np.ndarray]:
    """Random matrices of every rank (small to JACOBI_MAX wide), repeated rows, a zero column, and empty ones."""
    for trial in range(300):
        rows, cols = (int(x) for x in rng.integers(1, lp.JACOBI_MAX + 1, size=2))
        A = _rank_deficient(rng, rows, cols) * 10.0 ** rng.uniform(-3, 2)
        if trial % 4 == 0 and rows > 1:
            A[1] = A[0]
        if trial % 7 == 0:
            A[:, 0] = 0.0
        yield A
    yield np.zeros((0, 6))
    yield np.zeros((3, 0))


def test_lapack_singular_values_give_the_jacobi_kernels_ranks() -> None:
    """The same singular values to round-off, so the same rank decision wherever none sits within round-off of the tolerance."""
    rng = np.random.default_rng(5)
    for A in _matrices(rng):
        jacobi = np.sort(lp._singular_values(A) if A.size else np.zeros(0))[::-1]
        lapack = lp._singular_values_numpy(A) if A.size else np.zeros(0)
        scale = max(1.0, float(lapack.max(initial=0.0)))
        np.testing.assert_allclose(lapack, jacobi, rtol=0, atol=1e-13 * scale)
        for tol in (MOTION_RANK, FORCE_RANK):
            if np.any(np.abs(lapack - tol) <= 1e-12 * scale):
                continue  # a value at the threshold: either answer is round-off
            assert np.count_nonzero(lapack > tol) == np.count_nonzero(jacobi > tol)  # what _full_rank decides


def test_lapack_singular_values_do_not_depend_on_the_blas_threads() -> None:
    """Up to JACOBI_MAX columns (any number of rows) one thread and several give the same bits."""
    rng = np.random.default_rng(8)
    for _ in range(40):
        rows, cols = int(rng.integers(1, 400)), int(rng.integers(1, lp.JACOBI_MAX + 1))
        A = rng.normal(size=(rows, cols)) if rng.random() < 0.5 else rng.normal(size=(cols, rows))
        with threadpool_limits(1):
            one = lp._singular_values_numpy(A)
        with threadpool_limits(4):
            several = lp._singular_values_numpy(A)
        np.testing.assert_array_equal(one, several)


def _assert_same_analysis(got: tuple, want: tuple) -> None:
    residual, *masks_and_ranks = want
    assert got[0] == pytest.approx(residual, rel=1e-12, abs=1e-14)
    np.testing.assert_allclose(got[1], masks_and_ranks[0], rtol=1e-13, atol=1e-14)  # slacks
    for a, b in zip(got[2:5], masks_and_ranks[1:4], strict=True):
        np.testing.assert_array_equal(a, b)
    assert got[5:] == tuple(masks_and_ranks[4:])


def _pairs(rng: np.random.Generator) -> Iterator[tuple[np.ndarray, ...]]:
    """Primal-dual pairs: exactly complementary ones on rank-deficient normals (ties at zero slack and zero force),
    perturbed ones, and ones with more closed contacts than twist entries."""
    for trial in range(200):
        m, n = int(rng.integers(1, 14)), int(rng.integers(1, 8))
        Jn = _rank_deficient(rng, m, n) if trial % 2 else rng.normal(size=(m, n))
        q = rng.normal(size=n)
        state = rng.integers(0, 3, size=m)  # 0: open, 1: closed and loaded, 2: closed, unloaded
        slack = np.where(state == 0, rng.uniform(0.1, 1.0, m), 0.0)
        forces = np.where(state == 1, rng.uniform(0.1, 1.0, m), 0.0)
        bn = Jn @ q - slack
        g = -Jn.T @ forces
        if trial % 3 == 0:
            forces = forces + rng.normal(scale=1e-3, size=m)
        yield Jn, bn, g, q, forces


def test_analysis_twin_equals_the_kernel() -> None:
    rng = np.random.default_rng(13)
    for Jn, bn, g, q, forces in _pairs(rng):
        args = (Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        _assert_same_analysis(lp._analyse_numpy(*args), lp._analyse(*args))


def test_analysis_twin_of_a_non_finite_pair_or_no_contacts() -> None:
    """Not finite: infinite residual and no rank claimed; no contacts: nothing closed, forces unique."""
    Jn, bn, g = np.eye(3), np.zeros(3), np.zeros(3)
    for q, forces in ((np.array([np.nan, 0.0, 0.0]), np.zeros(3)), (np.zeros(3), np.array([0.0, np.inf, 0.0]))):
        got = lp._analyse_numpy(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        assert got[0] == np.inf and got[5:] == (0, 0)
        _assert_same_analysis(got, lp._analyse(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK))
    empty = (np.zeros((0, 3)), np.zeros(0), np.array([0.0, 0.0, -1.0]), np.zeros(3), np.zeros(0), ZERO, MOTION_RANK, FORCE_RANK)
    got = lp._analyse_numpy(*empty)
    assert got[0] == 1.0 and got[6] == 1
    _assert_same_analysis(got, lp._analyse(*empty))


@pytest.mark.parametrize("family", ["grasp-2d-nf", "grasp-3d-nf", "box-push-nf", "pile-nf"])
def test_lemke_pair_twin_equals_the_kernel_on_bench_scenes(family: str) -> None:
    """Lemke's pair and its analysis on the frictionless bench families, as the frictionless default runs them."""
    make = FAMILIES[family].make
    for size in FAMILIES[family].quick_sizes[:2]:
        for instance in range(2):
            data = lp._Frictionless(qs.assemble(make(size, instance)))
            args = (data.J, data.b, data.mu, data.g, data.frictional, data.base, data.Jn, data.bn)
            tolerances = (MODE_SPEED, PIVOT, PIVOTS_PER_ROW, ZERO, MOTION_RANK, FORCE_RANK)
            status, q, c, analysis = lp._lemke_pair_numpy(*args, *tolerances)
            want = lp._lemke_pair(*args, *tolerances)
            assert status == want[0]
            np.testing.assert_allclose(q, want[1], rtol=1e-12, atol=1e-14)
            np.testing.assert_allclose(c, want[2], rtol=1e-12, atol=1e-14)
            assert c.min(initial=0.0) >= 0.0
            _assert_same_analysis(analysis, want[3])
