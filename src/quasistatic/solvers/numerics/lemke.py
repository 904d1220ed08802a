"""Lemke's complementary pivoting method with lexicographic anti-cycling (Cottle, Pang & Stone 1992, ch. 4).

Solves the linear complementarity problem LCP(q, M)::

    w = M z + q,   z >= 0,   w >= 0,   z . w = 0

from the artificial start ``w = q + d z0`` with a positive covering vector ``d``. The
basis inverse is kept dense and updated by one elimination per pivot; ties in
the ratio test are broken by the lexicographic rule on the rows of
``[x_B, B^-1]``, which is equivalent to perturbing ``q`` by ``(eps, eps^2, ...)``
and so cannot cycle on degenerate problems. The method is written twice more: in C
in the extension ``quasistatic._lemke`` (:mod:`quasistatic.compiled`, built by
``pip install .``, making this kernel's choices pivot for pivot) and as a whole-array
numpy twin. Which runs:

- numba installed: :func:`lemke` is compiled and calls the C code by the name of its
  entry point (1.2-3.6x faster a pivot than numba's own compiled :func:`numba_lemke` on
  dense LCPs, 4-6x a solve on the fast path's, whose columns are mostly zeros); where the
  extension was not built, it calls :func:`numba_lemke` the same way (a numba ``cfunc``),
  so that every compiled caller, cached on disk, finds the same C entry point either way;
- no numba: :func:`lemke` is the extension's wrapper, or where it was not built (no
  C compiler) :func:`_lemke_numpy`: the same pivots in fewer, BLAS-backed numpy calls
  (12 us a pivot against the kernel's 33 us as plain Python; 0.4-5 us in C).

Lemke's path from its primary ray ends at a solution of index +1 (``sgn det M_SS``
of its support) or on a secondary ray, for every covering vector ``d > 0``: an LCP
whose solutions all have index -1 always ends on a ray (docs/performance.md).

Variable numbering in ``basis``: ``0..n-1`` are ``w``, ``n..2n-1`` are ``z``,
``2n`` is the artificial ``z0``.

Free variables (a mixed LCP's, written as the first ``free`` entries of ``z``): once one
enters the basis it never leaves (its row drops out of the ratio test, so its value may turn
negative), the usual treatment of a mixed LCP's free variables; its complement then stays
nonbasic at zero. ``free = 0`` is the textbook method.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.linalg.blas import dger

from ...compiled import HAVE_EXTENSION, LEMKE_ADDRESS
from ...compiled import lemke as compiled_lemke
from ...jit import HAVE_NUMBA, c_function, cfunc_address, njit

__all__ = ["lemke", "numba_lemke", "SOLUTION", "RAY", "PIVOT_LIMIT", "STATUS_NAMES"]

SOLUTION = 0  # z0 left the basis: a complementary solution
RAY = 1  # the entering column has no positive entry: Lemke ended on a secondary ray
PIVOT_LIMIT = 2  # stopped after max_pivots pivots
STATUS_NAMES = {SOLUTION: "solution", RAY: "secondary ray", PIVOT_LIMIT: "pivot limit"}


def _lemke_numpy(
    M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float, free: int
) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Whole-array twin of :func:`lemke` for plain Python: the same pivots, in fewer numpy calls.

    Without numba each numpy call costs about a microsecond of interpreter time
    whatever its size, so this version keeps ``B^-1`` and the basic values as
    one table ``[B^-1, x_B]`` (Fortran order) updated in place by one BLAS
    rank-one update per pivot (``dger``), keeps the columns of ``-M`` as rows
    (one matrix-vector product per pivot), and settles the ratio test in a few
    whole-array steps; where two ratios tie, :func:`_tied_ratio_test_numpy`
    applies the kernel's rule, its lexicographic tie-break in whole-array steps too.
    """
    n = q.shape[0]
    basis = np.arange(n)
    if n == 0 or q.min() >= 0.0:
        return SOLUTION, np.zeros(n), 0, basis
    artificial = 2 * n
    minus_columns = -M.T  # row e: the column of z_e in [I, -M]
    table = np.zeros((n, n + 1), order="F")
    table[:, :n] = np.eye(n)
    table[:, n] = q
    Binv, xB = table[:, :n], table[:, n]
    ratios = q / d
    smallest = ratios.min()
    row = int(np.flatnonzero(ratios <= smallest + tol * (1.0 + abs(smallest)))[-1])
    col = -d
    entering = artificial
    pivots = 0
    while True:
        leaving = int(basis[row])
        pivot_row = table[row] * (1.0 / col[row])
        col[row] = 0.0  # col is a fresh array each pivot: it becomes the elimination factors
        dger(-1.0, col, pivot_row, a=table, overwrite_a=True)
        table[row] = pivot_row
        basis[row] = entering
        pivots += 1
        if leaving == artificial:
            return SOLUTION, _basic_z_numpy(basis, xB), pivots, basis
        if pivots >= max_pivots:
            return PIVOT_LIMIT, _basic_z_numpy(basis, xB), pivots, basis
        entering = leaving + n if leaving < n else leaving - n
        col = Binv[:, entering].copy() if entering < n else Binv.dot(minus_columns[entering - n])
        row = _quick_ratio_test(Binv, xB, col, basis, artificial, tol, ratios, free)
        if row < 0:
            return RAY, _basic_z_numpy(basis, xB), pivots, basis


def _quick_ratio_test(
    Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, basis: np.ndarray, artificial: int, tol: float, ratios: np.ndarray, free: int
) -> int:
    """:func:`_ratio_test` in whole-array steps when one row attains the minimum ratio (``ratios``: scratch space)."""
    largest = col[col.argmax()]  # argmax and indexing: a third of max()'s interpreter time
    pivot_tol = tol * max(1.0, largest, -col[col.argmin()])
    candidates = col > pivot_tol
    if free:
        candidates &= ~_free_rows_numpy(basis, artificial // 2, free)
    if not candidates.any():
        return -1
    ratios.fill(np.inf)
    np.divide(xB, col, out=ratios, where=candidates)
    row = int(ratios.argmin())
    theta = ratios[row]
    ratios[row] = np.inf
    if ratios[ratios.argmin()] <= theta + tol * (1.0 + abs(theta)):  # a tie (degenerate step): the kernel's rule decides
        return _tied_ratio_test_numpy(Binv, xB, col, basis, artificial, tol, candidates)
    return row


def _free_rows_numpy(basis: np.ndarray, n: int, free: int) -> np.ndarray:
    """The rows whose basic variable is one of the free ``z[:free]`` (never leaving)."""
    return (basis >= n) & (basis < n + free)


def _tied_ratio_test_numpy(
    Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, basis: np.ndarray, artificial: int, tol: float, candidates: np.ndarray
) -> int:
    """:func:`_ratio_test` where ratios tie: the rows within the tie width, ``z0``'s first, else the lexicographic rule."""
    rows = np.flatnonzero(candidates)
    ratios = xB[rows] / col[rows]
    theta = ratios.min()
    rows = rows[ratios <= theta + tol * (1.0 + abs(theta))]
    artificial_rows = rows[basis[rows] == artificial]
    if artificial_rows.size > 0:
        return int(artificial_rows[0])  # z0 can leave: that ends the path at a solution
    return _tie_break_numpy(Binv, col, rows, tol)


def _tie_break_numpy(Binv: np.ndarray, col: np.ndarray, rows: np.ndarray, tol: float) -> int:
    """The column loop of :func:`_ratio_test` in whole-array steps: the same row.

    The loop keeps, column by column of ``B^-1``, the rows whose value is within
    ``tol`` of the smallest among the rows still kept. A column where every row is
    close keeps them all, and while a row attaining the smallest value of all the
    rows here is still kept, that is the smallest among those kept: so every
    separating column up to the first where no such row is left is applied at once
    (a cumulative AND of their masks), then the values are read again from there.
    """
    start = 0
    while rows.size > 1:
        values = Binv[rows, start:] / col[rows, None]
        smallest = values.min(axis=0)
        close = values <= smallest + tol
        separating = np.flatnonzero(~close.all(axis=0))
        if separating.size == 0:
            break
        kept = np.logical_and.accumulate(close[:, separating], axis=1)  # the rows kept after each separating column
        kept_before = np.column_stack((np.ones(rows.size, dtype=bool), kept[:, :-1]))
        exact = ((values[:, separating] == smallest[separating]) & kept_before).any(axis=0)
        steps = separating.size if exact.all() else int(exact.argmin())
        if steps == 0:  # nothing attains the smallest value: NaN data
            break
        rows = rows[kept[:, steps - 1]]
        start += int(separating[steps - 1]) + 1
    return int(rows[0])


def _basic_z_numpy(basis: np.ndarray, xB: np.ndarray) -> np.ndarray:
    """Whole-array twin of :func:`_basic_z`."""
    n = xB.shape[0]
    z = np.zeros(n)
    basic_z = (basis >= n) & (basis < 2 * n)
    z[basis[basic_z] - n] = xB[basic_z]
    return z


# Without numba: the C extension when it was built, else the numpy twin.
_PLAIN_LEMKE = compiled_lemke if HAVE_EXTENSION else _lemke_numpy


@njit
def numba_lemke(
    M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float, free: int
) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Solve ``w = M z + q, z >= 0, w >= 0, z . w = 0`` by Lemke's method: the kernel whose choices the others make.

    numba compiles it; :func:`lemke` runs the extension's C instead where it was built.

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
    free : int
        ``z[:free]`` are free variables: once basic, never leaving (module docstring); 0 for none.

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
        _pivot(Binv, xB, col, row)
        basis[row] = entering
        pivots += 1
        if leaving == artificial:
            return SOLUTION, _basic_z(basis, xB), pivots, basis
        if pivots >= max_pivots:
            return PIVOT_LIMIT, _basic_z(basis, xB), pivots, basis
        entering = leaving + n if leaving < n else leaving - n
        _column(Binv, M, d, entering, col)
        row = _ratio_test(Binv, xB, col, basis, artificial, tol, free)
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
        col[:] = Binv[:, entering]
    elif entering < 2 * n:
        col[:] = -(Binv @ np.ascontiguousarray(M[:, entering - n]))
    else:
        col[:] = -(Binv @ d)


@njit
def _ratio_test(Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, basis: np.ndarray, artificial: int, tol: float, free: int) -> int:
    """Leaving row by the lexicographic minimum ratio; -1 when the column has no positive entry in a row whose basic
    variable may leave (a free ``z[:free]`` never does)."""
    pivot_tol = tol * max(1.0, np.max(np.abs(col)))
    n = col.shape[0]
    rows = np.flatnonzero((col > pivot_tol) & ~((basis >= n) & (basis < n + free)))
    if rows.size == 0:
        return -1
    ratios = xB[rows] / col[rows]
    theta = np.min(ratios)
    rows = rows[ratios <= theta + tol * (1.0 + abs(theta))]
    artificial_rows = rows[basis[rows] == artificial]
    if artificial_rows.size > 0:
        return int(artificial_rows[0])  # z0 can leave: that ends the path at a solution
    # Break the tie on the rows of B^-1, column by column (never a tie in exact arithmetic).
    for j in range(col.shape[0]):
        if rows.size == 1:
            break
        values = Binv[rows, j] / col[rows]
        rows = rows[values <= np.min(values) + tol]
    return int(rows[0])


@njit
def _pivot(Binv: np.ndarray, xB: np.ndarray, col: np.ndarray, row: int) -> None:
    """Eliminate the entering column on ``row``: update ``B^-1`` and the basic values in place."""
    scale = 1.0 / col[row]
    Binv[row] *= scale
    xB[row] *= scale
    factors = col.copy()
    factors[row] = 0.0
    Binv -= np.outer(factors, Binv[row])
    xB -= factors * xB[row]


# The C entry point quasistatic_lemke (src/quasistatic/_lemke.c), as kernels call it:
# (n, M, q, d, max_pivots, tol, free, z, basis, pivots, work, rows) -> status; work: n (n + 3), rows: n scratch entries.
_C_LEMKE = "quasistatic_lemke"
_C_SIGNATURE = (
    "int64(int64, CPointer(float64), CPointer(float64), CPointer(float64), int64, float64, int64,"
    " CPointer(float64), CPointer(int64), CPointer(int64), CPointer(float64), CPointer(int64))"
)


def _numba_lemke_by_pointers(
    n: int, M: Any, q: Any, d: Any, max_pivots: int, tol: float, free: int, z: Any, basis: Any, pivots: Any, work: Any, rows: Any
) -> int:
    """:func:`numba_lemke` behind the C entry point's signature (pointers; ``work`` and ``rows`` unused): where numba is
    installed but the extension was not built, the kernels call this instead, by the same name."""
    M_, q_, d_ = np.empty((n, n)), np.empty(n), np.empty(n)
    for i in range(n):
        q_[i], d_[i] = q[i], d[i]
        for j in range(n):
            M_[i, j] = M[i * n + j]
    status, z_, pivots_, basis_ = numba_lemke(M_, q_, d_, max_pivots, tol, free)
    for i in range(n):
        z[i], basis[i] = z_[i], basis_[i]
    pivots[0] = pivots_
    return status


_c_lemke: Any = None  # the C entry point as kernels call it (numba installed)
if HAVE_NUMBA:
    _c_lemke = c_function(
        _C_LEMKE, _C_SIGNATURE, LEMKE_ADDRESS if HAVE_EXTENSION else cfunc_address(_C_SIGNATURE, _numba_lemke_by_pointers)
    )


@njit(python=_PLAIN_LEMKE)
def lemke(M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float, free: int) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Solve ``w = M z + q, z >= 0, w >= 0, z . w = 0`` by Lemke's method: :func:`numba_lemke`'s pivots, in C where built.

    Arguments and results as :func:`numba_lemke`'s.

    Raises
    ------
    ValueError
        When ``M`` is not (n, n) or ``d`` not (n,) for ``q`` (n,).
    """
    n = q.shape[0]
    if M.shape[0] != n or M.shape[1] != n or d.shape[0] != n:
        raise ValueError("lemke: M must be (n, n) and d (n,) for q (n,)")
    M, q, d = np.ascontiguousarray(M), np.ascontiguousarray(q), np.ascontiguousarray(d)
    z, basis, pivots = np.empty(n), np.empty(n, dtype=np.int64), np.zeros(1, dtype=np.int64)
    work, rows = np.empty(n * (n + 3)), np.empty(n, dtype=np.int64)
    status = _c_lemke(
        n, M.ctypes, q.ctypes, d.ctypes, max_pivots, tol, free, z.ctypes, basis.ctypes, pivots.ctypes, work.ctypes, rows.ctypes
    )
    return status, z, pivots[0], basis
