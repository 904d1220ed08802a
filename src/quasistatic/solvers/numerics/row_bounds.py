"""Bank rows over a closed set of twists, compiled: the slacks and rates the mode branch and bound reads.

Where a node's closed rows ``E q = e`` leave a point, a line or a plane of twists
(:func:`..certify.patterns._closed_set`), each inequality row of the bank is read as its best slack at the set's point
``q0`` (every closed row loosened) and its rates along the set's free directions. A node reads a few to tens of the
bank's 100-1000 rows: these loops work out only the rows asked for (~1 us a call), where whole-bank products cost
~50-150 us per closed set. With numba the loops below are compiled; without it, the same loops in C
(``quasistatic._kernels``, where the default install built it), else the same arithmetic in numpy calls on the
rows asked for (sums in BLAS's order: the same to round-off).
"""

from __future__ import annotations

import numpy as np

from ...compiled import HAVE_KERNELS
from ...compiled import row_bounds as compiled_row_bounds
from ...jit import njit

__all__ = ["row_bounds"]


def _row_bounds_numpy(
    bank: np.ndarray,
    rhs: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    directions: np.ndarray,
    rows: np.ndarray,
    slack: float,
    reserve: np.ndarray,
    rates: np.ndarray,
) -> None:
    """:func:`row_bounds` in numpy calls on the rows asked for (without numba or the C extension)."""
    chosen = bank[rows]
    reach = np.abs(chosen @ inverse) @ np.ones(inverse.shape[1])
    reserve[rows] = chosen @ q0 + slack * reach - rhs[rows] + slack
    rates[rows, : directions.shape[0]] = chosen @ directions.T


def _row_bounds_compiled(
    bank: np.ndarray,
    rhs: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    directions: np.ndarray,
    rows: np.ndarray,
    slack: float,
    reserve: np.ndarray,
    rates: np.ndarray,
) -> None:
    """:func:`row_bounds`' loops in C (without numba, where the extension was built)."""
    compiled_row_bounds(bank, rhs, inverse, q0, directions, rows, slack, reserve, rates)


@njit(python=_row_bounds_compiled if HAVE_KERNELS else _row_bounds_numpy)
def row_bounds(
    bank: np.ndarray,
    rhs: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    directions: np.ndarray,
    rows: np.ndarray,
    slack: float,
    reserve: np.ndarray,
    rates: np.ndarray,
) -> None:
    """For each bank row ``j`` in ``rows``: ``reserve[j] = bank[j] . q0 + slack |bank[j] inverse|_1 - rhs[j] + slack``,
    its best slack over the twists that meet the closed rows to ``slack`` each (``inverse``: their pseudo-inverse,
    ``q0``: their point), and ``rates[j, c] = bank[j] . directions[c]``, its rate along each free direction.

    ``bank`` (R, n), ``rhs`` (R,), ``inverse`` (n, k), ``q0`` (n,), ``directions`` (f, n) with ``f <= 2``, all float64;
    ``rows`` (I,) int64; ``reserve`` (R,) and ``rates`` (R, 2) are filled at ``rows`` only; all C-contiguous.
    """
    n, k, free = bank.shape[1], inverse.shape[1], directions.shape[0]
    for j in rows:
        value = 0.0
        for column in range(n):
            value += bank[j, column] * q0[column]
        reach = 0.0
        for i in range(k):
            product = 0.0
            for column in range(n):
                product += bank[j, column] * inverse[column, i]
            reach += abs(product)
        reserve[j] = value + slack * reach - rhs[j] + slack
        for c in range(free):
            rate = 0.0
            for column in range(n):
                rate += bank[j, column] * directions[c, column]
            rates[j, c] = rate
