"""A closed set of twists and its bank rows, compiled: what the mode branch and bound's closed rows leave.

Where a node's closed rows ``E q = e`` (a few by ``n``) leave a point, a line or a plane of twists
(:func:`..certify.patterns._closed_set`), :func:`closed_rows` factors them (singular values, the right singular
vectors, the pseudo-inverse, the point ``q0``) by one-sided Jacobi rotations (~3 us, where numpy's SVD and the
products around it cost ~40 us a set). Each inequality row of the bank is then read as its best slack at ``q0``
(every closed row loosened) and its rates along the set's free directions (:func:`row_bounds`). A node reads a few
to tens of the bank's 100-1000 rows: only the rows asked for are worked out (~1 us a call), where whole-bank
products cost ~50-150 us a set. With numba the loops below are compiled; without it, the same loops in C
(``quasistatic._kernels``, where the default install built it), else numpy (LAPACK's SVD, and BLAS's sums: the same
to round-off; a line's or a plane's directions may be another orthonormal basis of the same space).
"""

from __future__ import annotations

import math

import numpy as np

from ...compiled import HAVE_KERNELS
from ...compiled import closed_rows as compiled_closed_rows
from ...compiled import row_bounds as compiled_row_bounds
from ...jit import njit

__all__ = ["closed_rows", "row_bounds"]


def _closed_rows_numpy(
    E: np.ndarray,
    e: np.ndarray,
    by_rank: bool,
    rank: float,
    orthogonal: float,
    zero: float,
    sigma: np.ndarray,
    basis: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    spread: np.ndarray,
) -> tuple[int, float]:
    """:func:`closed_rows` by LAPACK's SVD and numpy's products (without numba or the C extension)."""
    k, n = E.shape
    u, values, vt = np.linalg.svd(E, full_matrices=True)
    sigma[:] = 0.0
    sigma[: values.size] = values
    basis[:] = vt
    r = int(np.count_nonzero(values > rank)) if by_rank else values.size
    if r == 0 or values[r - 1] <= rank:
        return 0, 0.0
    inverse[:] = (vt[:r].T / values[:r]) @ u[:, :r].T
    q0[:] = inverse @ e
    spread[:] = zero * np.abs(inverse).sum(axis=1)
    residual = E @ q0 - e
    return r, float(residual @ residual)


@njit(python=compiled_closed_rows if HAVE_KERNELS else _closed_rows_numpy)
def closed_rows(
    E: np.ndarray,
    e: np.ndarray,
    by_rank: bool,
    rank: float,
    orthogonal: float,
    zero: float,
    sigma: np.ndarray,
    basis: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    spread: np.ndarray,
) -> tuple[int, float]:
    """The closed rows ``E q = e`` factored: ``E = U diag(sigma) basis`` with ``sigma`` (n,) largest first (zeros past
    ``k``) and ``basis`` (n, n) orthonormal rows, the right singular vectors, by one-sided Jacobi rotations of E's
    columns (Hestenes; pairs left once their cosine is below ``orthogonal``, as ``solvers/lp.py``'s, or once one of
    them is below ``orthogonal`` times E's Frobenius norm: a null direction's column, in round-off, which would keep
    turning where E has fewer rows than columns, measured: all 60 sweeps instead of 5-7); the ranks kept,
    ``r``: with ``by_rank`` the singular values above ``rank``, else ``min(k, n)``; the pseudo-inverse truncated to
    them, ``inverse`` (n, k); ``q0 = inverse e``; ``spread = zero |inverse|`` summed along each row. Returns ``r`` and
    the squared residual ``|E q0 - e|^2``; ``(0, 0.0)`` when no rank is kept or the last kept is ``rank`` or less (then
    only ``sigma`` and ``basis`` are filled). ``E`` (k, n) and ``e`` (k,) float64; the rest filled, all C-contiguous.
    """
    k, n = E.shape
    W = E.copy()  # its columns rotated until orthogonal: W = E V
    V = np.eye(n)
    negligible = 0.0  # a column's square norm below this is a null direction's, in round-off: no pair with it turns
    for i in range(k):
        for j in range(n):
            negligible += E[i, j] * E[i, j]
    negligible *= orthogonal * orthogonal
    for _ in range(60):
        rotated = False
        for p in range(n - 1):
            for q in range(p + 1, n):
                alpha = beta = gamma = 0.0
                for i in range(k):
                    alpha += W[i, p] * W[i, p]
                    beta += W[i, q] * W[i, q]
                    gamma += W[i, p] * W[i, q]
                if gamma == 0.0 or abs(gamma) <= orthogonal * math.sqrt(alpha * beta) or min(alpha, beta) <= negligible:
                    continue
                rotated = True
                diff = beta - alpha  # tan of the rotation in solvers/lp.py's overflow-free form
                sign = 1.0 if diff == 0.0 or (diff > 0.0) == (gamma > 0.0) else -1.0
                t = sign * 2.0 * abs(gamma) / (abs(diff) + math.hypot(2.0 * gamma, diff))
                cos = 1.0 / math.sqrt(1.0 + t * t)
                sin = cos * t
                for i in range(k):
                    wp, wq = W[i, p], W[i, q]
                    W[i, p] = cos * wp - sin * wq
                    W[i, q] = sin * wp + cos * wq
                for i in range(n):
                    vp, vq = V[i, p], V[i, q]
                    V[i, p] = cos * vp - sin * vq
                    V[i, q] = sin * vp + cos * vq
        if not rotated:
            break
    norms = np.empty(n)
    for j in range(n):
        total = 0.0
        for i in range(k):
            total += W[i, j] * W[i, j]
        norms[j] = math.sqrt(total)
    order = np.empty(n, dtype=np.int64)  # the columns by their norms, largest first (a stable selection)
    taken = np.zeros(n, dtype=np.bool_)
    for slot in range(n):
        best = -1
        for j in range(n):
            if not taken[j] and (best < 0 or norms[j] > norms[best]):
                best = j
        taken[best] = True
        order[slot] = best
    full = min(k, n)
    r = 0
    for slot in range(n):
        j = order[slot]
        sigma[slot] = norms[j] if slot < full else 0.0
        for i in range(n):
            basis[slot, i] = V[i, j]
        if slot < full and (norms[j] > rank if by_rank else True):
            r = slot + 1
    if r == 0 or sigma[r - 1] <= rank:
        return 0, 0.0  # no rank kept, or the last one too small: nothing more is read
    for i in range(n):
        for c in range(k):
            value = 0.0
            for slot in range(r):
                j = order[slot]
                value += V[i, j] * (W[c, j] / (norms[j] * norms[j]))
            inverse[i, c] = value
    for i in range(n):
        value = 0.0
        size = 0.0
        for c in range(k):
            value += inverse[i, c] * e[c]
            size += abs(inverse[i, c])
        q0[i] = value
        spread[i] = zero * size
    square = 0.0
    for c in range(k):
        value = 0.0
        for i in range(n):
            value += E[c, i] * q0[i]
        square += (value - e[c]) * (value - e[c])
    return r, square


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


@njit(python=compiled_row_bounds if HAVE_KERNELS else _row_bounds_numpy)
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
