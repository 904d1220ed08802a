"""A closed set of twists (``solvers/numerics/closed_set.py``): its closed rows factored, and each bank row's best
slack and rates, worked out when read.

The installed kernels (numba, their loops in C, or numpy calls) give LAPACK's singular values, pseudo-inverse and
spaces left, and the whole-bank products' values at the rows asked for, leaving the other rows as they were; the C
loops give the numba kernels' bits.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest

from quasistatic import compiled
from quasistatic.solvers.numerics import closed_set as kernel_module
from quasistatic.solvers.numerics.closed_set import closed_rows, row_bounds
from quasistatic.tolerances import JACOBI_ORTHOGONAL, MOTION_RANK, ZERO

SLACK = 1e-7


def _cases() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """``(bank, rhs, inverse, q0, directions, rows)``: random banks with what 1 to 6 of their rows leave (a point, a
    line, a plane), and a few rows asked for (one, several, none)."""
    rng = np.random.default_rng(3)
    for total in (12, 200):
        for k in (4, 5, 6):
            bank, rhs = rng.standard_normal((total, 6)), rng.standard_normal(total)
            u, sigma, vt = np.linalg.svd(bank[:k], full_matrices=True)
            inverse = np.ascontiguousarray((vt[:k].T / sigma) @ u.T)
            for rows in ([3], [0, 5, 7, 11], []):
                yield bank, rhs, inverse, inverse @ rhs[:k], np.ascontiguousarray(vt[k:]), np.array(rows, dtype=np.int64)


def _filled(kernel: Callable[..., None], case: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    reserve, rates = np.full(case[0].shape[0], 7.0), np.full((case[0].shape[0], 2), 7.0)
    kernel(*case[:6], SLACK, reserve, rates)
    return reserve, rates


def test_the_rows_asked_for_get_the_whole_banks_values_and_no_other_row_changes() -> None:
    for case in _cases():
        bank, rhs, inverse, q0, directions, rows = case
        reserve, rates = _filled(row_bounds, case)
        whole = bank @ q0 + SLACK * np.abs(bank @ inverse).sum(axis=1) - rhs + SLACK
        np.testing.assert_allclose(reserve[rows], whole[rows], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(rates[rows, : directions.shape[0]], (bank @ directions.T)[rows], rtol=1e-12, atol=1e-12)
        untouched = np.ones(bank.shape[0], dtype=bool)
        untouched[rows] = False
        assert np.all(reserve[untouched] == 7.0) and np.all(rates[untouched] == 7.0)
        assert np.all(rates[rows, directions.shape[0] :] == 7.0)


def test_the_kernel_and_its_numpy_twin_agree() -> None:
    for case in _cases():
        for ours, twin in zip(_filled(row_bounds, case), _filled(kernel_module._row_bounds_numpy, case), strict=True):
            np.testing.assert_allclose(ours, twin, rtol=1e-12, atol=1e-12)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_c_loops_give_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(row_bounds, numba.core.registry.CPUDispatcher)
    for case in _cases():
        for ours, c in zip(_filled(row_bounds, case), _filled(compiled.row_bounds, case), strict=True):
            np.testing.assert_array_equal(c, ours)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_c_loops_reject_bad_arguments() -> None:
    bank, rhs, inverse, q0, directions = np.ones((4, 6)), np.ones(4), np.ones((6, 2)), np.ones(6), np.ones((2, 6))
    reserve, rates = np.empty(4), np.empty((4, 2))
    with pytest.raises(ValueError, match="rows must index the bank's rows"):
        compiled.row_bounds(bank, rhs, inverse, q0, directions, np.array([4]), SLACK, reserve, rates)
    with pytest.raises(ValueError, match="directions must be"):
        compiled.row_bounds(bank, rhs, inverse, q0, np.ones((3, 6)), np.array([0]), SLACK, reserve, rates)
    with pytest.raises(ValueError, match="rates must have 2 dimensions"):
        compiled.row_bounds(bank, rhs, inverse, q0, directions, np.array([0]), SLACK, reserve, np.empty((4, 3)))


def _closed_cases() -> Iterator[tuple[np.ndarray, np.ndarray, bool]]:
    """``(E, e, by_rank)``: 1 to 8 random rows of 6 columns (a point, a line, a plane, more), well and badly scaled,
    rows that repeat one another (deficient rank: read by rank, or not), and rows that meet no common twist."""
    rng = np.random.default_rng(4)
    for k in (1, 3, 4, 5, 6, 8):
        for scale in (1.0, 1e-4):
            E = rng.standard_normal((k, 6)) * np.logspace(0.0, np.log10(scale), 6)
            yield E, rng.standard_normal(k), False
    base = rng.standard_normal((3, 6))
    deficient = np.vstack([base, base[0] + base[1]])  # rank 3 of 4 rows
    for by_rank in (True, False):
        yield deficient, deficient @ rng.standard_normal(6), by_rank
    yield np.zeros((2, 6)), np.zeros(2), True  # no rank at all


def _factored(
    kernel: Callable[..., tuple[int, float]], E: np.ndarray, e: np.ndarray, by_rank: bool
) -> tuple[int, float, dict[str, np.ndarray]]:
    k, n = E.shape
    out = {"sigma": np.empty(n), "basis": np.empty((n, n)), "inverse": np.empty((n, k)), "q0": np.empty(n), "spread": np.empty(n)}
    r, square = kernel(E, e, by_rank, MOTION_RANK, JACOBI_ORTHOGONAL, ZERO, *out.values())
    return r, square, out


def test_the_closed_rows_are_factored_as_lapack_factors_them() -> None:
    answers = set()
    for E, e, by_rank in _closed_cases():
        r, square, out = _factored(closed_rows, E, e, by_rank)
        k, n = E.shape
        values = np.linalg.svd(E, compute_uv=False)
        kept = int(np.count_nonzero(values > MOTION_RANK)) if by_rank else min(k, n)
        answers.add(r)
        if kept == 0 or values[kept - 1] <= MOTION_RANK:
            assert r == 0
            continue
        assert r == kept
        np.testing.assert_allclose(out["sigma"][: values.size], values, rtol=1e-12, atol=1e-14 * values[0])
        basis = out["basis"]
        np.testing.assert_allclose(basis @ basis.T, np.eye(n), atol=1e-13)
        np.testing.assert_allclose(np.abs(E @ basis[r:].T), 0.0, atol=1e-12 * values[0])  # the space the rows leave
        u, sigma, vt = np.linalg.svd(E)
        inverse = (vt[:r].T / sigma[:r]) @ u[:, :r].T
        np.testing.assert_allclose(out["inverse"], inverse, rtol=1e-9, atol=1e-12 * np.abs(inverse).max())
        np.testing.assert_allclose(out["q0"], inverse @ e, rtol=1e-9, atol=1e-12 * np.abs(inverse @ e).max())
        np.testing.assert_allclose(out["spread"], ZERO * np.abs(inverse).sum(axis=1), rtol=1e-9)
        residual = E @ (inverse @ e) - e
        assert square == pytest.approx(float(residual @ residual), rel=1e-6, abs=1e-20)
    assert {0, 3, 6} <= answers


def test_the_factoring_kernel_and_its_numpy_twin_agree() -> None:
    for E, e, by_rank in _closed_cases():
        r, square, out = _factored(closed_rows, E, e, by_rank)
        r_twin, square_twin, twin = _factored(kernel_module._closed_rows_numpy, E, e, by_rank)
        assert r == r_twin
        if r:
            assert square == pytest.approx(square_twin, rel=1e-6, abs=1e-20)
            for name in ("sigma", "inverse", "q0", "spread"):
                np.testing.assert_allclose(out[name], twin[name], rtol=1e-9, atol=1e-12 * max(1.0, np.abs(twin[name]).max()))


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_factoring_c_loops_give_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(closed_rows, numba.core.registry.CPUDispatcher)
    for E, e, by_rank in _closed_cases():
        r, square, out = _factored(closed_rows, E, e, by_rank)
        r_c, square_c, out_c = _factored(compiled.closed_rows, E, e, by_rank)
        assert (r_c, square_c) == (r, square)
        names = ("sigma", "basis", "inverse", "q0", "spread") if r else ("sigma", "basis")
        for name in names:
            np.testing.assert_array_equal(out_c[name], out[name])
