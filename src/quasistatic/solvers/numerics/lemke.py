"""Lemke's complementary pivoting method with lexicographic anti-cycling (Cottle, Pang & Stone 1992, ch. 4).

Solves the linear complementarity problem LCP(q, M)::

    w = M z + q,   z >= 0,   w >= 0,   z . w = 0

from the artificial start ``w = q + d z0`` with a positive covering vector ``d``. The
basis inverse is kept dense and updated by one elimination per pivot; ties in
the ratio test are broken by the lexicographic rule on the rows of
``[x_B, B^-1]``, which is equivalent to perturbing ``q`` by ``(eps, eps^2, ...)``
and so cannot cycle on degenerate problems. The kernel is compiled with numba
when it is installed and runs as plain Python otherwise.

Variable numbering in ``basis``: ``0..n-1`` are ``w``, ``n..2n-1`` are ``z``,
``2n`` is the artificial ``z0``.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit

__all__ = ["lemke", "SOLUTION", "RAY", "PIVOT_LIMIT", "STATUS_NAMES"]

SOLUTION = 0  # z0 left the basis: a complementary solution
RAY = 1  # the entering column has no positive entry: Lemke ended on a secondary ray
PIVOT_LIMIT = 2  # stopped after max_pivots pivots
STATUS_NAMES = {SOLUTION: "solution", RAY: "secondary ray", PIVOT_LIMIT: "pivot limit"}


@njit
def lemke(M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Solve ``w = M z + q, z >= 0, w >= 0, z . w = 0`` by Lemke's method.

    Parameters
    ----------
    M : (n, n) float array
    q : (n,) float array
    d : (n,) float array
        Covering vector, every entry > 0 (``np.ones(n)`` is the textbook choice).
    max_pivots : int
        Pivots allowed (the first, bringing in ``z0``, counts).
    tol : float
        Pivot tolerance relative to the largest entry of the entering column,
        and the width within which two ratios tie [-]; the data are
        scene-relative (entries of order one), so e.g. 1e-11.

    Returns
    -------
    status : int
        :data:`SOLUTION`, :data:`RAY` or :data:`PIVOT_LIMIT`.
    z : (n,) float array
        The solution (for other statuses: the last basic point, not a solution).
    pivots : int
        Pivots made.
    basis : (n,) int array
        Basic variable of each row at the end (numbering in the module docstring).
    """
    n = q.shape[0]
    basis = np.arange(n)
    if n == 0 or np.min(q) >= 0.0:
        return SOLUTION, np.zeros(n), 0, basis
    artificial = 2 * n
    Binv = np.eye(n)
    xB = q.copy()
    col = np.empty(n)
    nonzero = np.empty(n, dtype=np.int64)
    candidates = np.empty(n, dtype=np.int64)

    # First pivot: z0 enters (column -d) and the row of the most negative q_i / d_i leaves.
    # Ties go to the lexicographically smallest row of [q, I] / d, i.e. the largest index.
    ratio_min = np.inf
    for i in range(n):
        col[i] = -d[i]
        ratio_min = min(ratio_min, q[i] / d[i])
    row = 0
    for i in range(n):
        if q[i] / d[i] <= ratio_min + tol * (1.0 + abs(ratio_min)):
            row = i
    entering = artificial
    pivots = 0
    while True:
        leaving = basis[row]
        _pivot(Binv, xB, col, row, nonzero)
        basis[row] = entering
        pivots += 1
        if leaving == artificial:
            return SOLUTION, _basic_z(basis, xB), pivots, basis
        if pivots >= max_pivots:
            return PIVOT_LIMIT, _basic_z(basis, xB), pivots, basis
        entering = leaving + n if leaving < n else leaving - n
        _column(Binv, M, d, entering, col)
        row = _ratio_test(Binv, xB, col, basis, artificial, tol, candidates)
        if row < 0:
            return RAY, _basic_z(basis, xB), pivots, basis


@njit
def _basic_z(basis: np.ndarray, xB: np.ndarray) -> np.ndarray:
    """``z`` of the basic point: each basic ``z`` variable's value, zero elsewhere."""
    n = xB.shape[0]
    z = np.zeros(n)
    for i in range(n):
        if n <= basis[i] < 2 * n:
            z[basis[i] - n] = xB[i]
    return z


@njit
def _column(Binv: np.ndarray, M: np.ndarray, d: np.ndarray, entering: int, col: np.ndarray) -> None:
    """``B^-1 A_e`` for the entering variable's column ``A_e`` of ``[I, -M, -d]``."""
    n = col.shape[0]
    if entering < n:
        for i in range(n):
            col[i] = Binv[i, entering]
        return
    col[:] = 0.0
    if entering < 2 * n:
        j = entering - n
        for k in range(n):
            m_kj = M[k, j]
            if m_kj != 0.0:
                for i in range(n):
                    col[i] -= Binv[i, k] * m_kj
        return
    for i in range(n):
        total = 0.0
        for k in range(n):
            total += Binv[i, k] * d[k]
        col[i] = -total


@njit
def _ratio_test(
    Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, basis: np.ndarray, artificial: int, tol: float, candidates: np.ndarray
) -> int:
    """Leaving row by the lexicographic minimum ratio; -1 when the column has no positive entry."""
    n = col.shape[0]
    largest = 1.0
    for i in range(n):
        largest = max(largest, abs(col[i]))
    pivot_tol = tol * largest
    theta = np.inf
    for i in range(n):
        if col[i] > pivot_tol:
            theta = min(theta, xB[i] / col[i])
    if theta == np.inf:
        return -1
    width = tol * (1.0 + abs(theta))
    count = 0
    for i in range(n):
        if col[i] > pivot_tol and xB[i] / col[i] <= theta + width:
            if basis[i] == artificial:
                return i  # z0 can leave: that ends the path at a solution
            candidates[count] = i
            count += 1
    # Break the tie on the rows of B^-1, column by column (never a tie in exact arithmetic).
    for j in range(n):
        if count == 1:
            break
        best = np.inf
        for c in range(count):
            i = candidates[c]
            best = min(best, Binv[i, j] / col[i])
        kept = 0
        for c in range(count):
            i = candidates[c]
            if Binv[i, j] / col[i] <= best + tol:
                candidates[kept] = i
                kept += 1
        count = kept
    return int(candidates[0])


@njit
def _pivot(Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, row: int, nonzero: np.ndarray) -> None:
    """Eliminate the entering column on ``row``: update ``B^-1`` and the basic values in place."""
    n = col.shape[0]
    scale = 1.0 / col[row]
    count = 0
    for j in range(n):
        if Binv[row, j] != 0.0:
            Binv[row, j] *= scale
            nonzero[count] = j
            count += 1
    xB[row] *= scale
    for i in range(n):
        factor = col[i]
        if i == row or factor == 0.0:
            continue
        for c in range(count):
            j = nonzero[c]
            Binv[i, j] -= factor * Binv[row, j]
        xB[i] -= factor * xB[row]
