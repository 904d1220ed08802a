"""A closed set's bank rows (``solvers/numerics/row_bounds.py``): each row's best slack and rates, worked out when read.

The installed kernel (numba, its loops in C, or numpy calls) gives the whole-bank products' values at the rows asked
for, and leaves the other rows as they were; the C loops give the numba kernel's bits.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest

from quasistatic import compiled
from quasistatic.solvers.numerics import row_bounds as kernel_module
from quasistatic.solvers.numerics.row_bounds import row_bounds

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
