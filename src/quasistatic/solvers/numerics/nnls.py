"""Non-negative least squares on a subset of a matrix's columns, compiled: the mode branch and bound's force fit.

The branch and bound (:mod:`..certify.patterns`) fits non-negative forces on a node's load columns thousands of
times per proof, on matrices of a few rows (the twist's entries) and tens to hundreds of columns. SciPy's
``nnls`` costs ~50-90 us a call there (argument checks, the columns copied out, a BLAS call per column); this
kernel takes the whole load matrix and the node's columns as a mask and costs a few microseconds. Lawson and
Hanson's active-set method: the kept column of the largest gradient enters the passive set, a least-squares
solve on the passive columns (Householder QR, made afresh: at most as many columns as rows) gives the new
coefficients, and a step back towards the last feasible point drops those that turn non-positive. A column
that depends on the passive ones (relative :data:`INDEPENDENT`), or whose own coefficient would not be
positive, is passed over until another enters.

Any fit is a candidate only: the search checks that it balances the load, or that its residual is a Farkas
vector, before pruning anything. Where several fits are optimal (more columns than rows), this one and SciPy's
may differ; the residual's norm is the same to round-off.

:func:`fit_or_farkas` makes the branch and bound's whole step at a node in one call: the fit on the columns a bit set
keeps, then, where it does not balance the load, its residual checked as a Farkas vector (which columns it cannot
exclude, as bits); a few microseconds where the same step in numpy calls and Python integers cost ~20.

With numba the loops below are compiled; without it, the same loops in C (``quasistatic._kernels``, where the
default install built it), else SciPy's ``nnls`` on the kept columns and numpy's products.
"""

from __future__ import annotations

import math

import numpy as np

from ...compiled import HAVE_FIT_OR_FARKAS, HAVE_KERNELS
from ...compiled import fit_or_farkas as compiled_fit_or_farkas
from ...compiled import nonnegative_fit as compiled_nonnegative_fit
from ...jit import njit
from .optimize import nnls

__all__ = ["nonnegative_fit", "fit_or_farkas", "column_words", "INDEPENDENT", "FIT_BALANCES", "FIT_EXCLUDED", "FIT_CANDIDATE"]

INDEPENDENT = 1e-12  # a column whose part off the passive columns' span is below this share of its norm depends on them
FIT_BALANCES, FIT_EXCLUDED, FIT_CANDIDATE = 0, 1, 2  # fit_or_farkas's outcomes


def _nonnegative_fit_compiled(A: np.ndarray, keep: np.ndarray, b: np.ndarray, x: np.ndarray) -> float:
    """:func:`nonnegative_fit`'s loops in C (without numba, where the extension was built)."""
    return compiled_nonnegative_fit(A, keep, b, x, INDEPENDENT)


def _nonnegative_fit_scipy(A: np.ndarray, keep: np.ndarray, b: np.ndarray, x: np.ndarray) -> float:
    """:func:`nonnegative_fit` by SciPy's ``nnls`` on the kept columns (without numba or the C extension)."""
    x[:] = 0.0
    if keep.any():
        x[keep] = nnls(A[:, keep], b)[0]
    residual = A @ x - b
    return math.sqrt(float(residual @ residual))


@njit(python=_nonnegative_fit_compiled if HAVE_KERNELS else _nonnegative_fit_scipy)
def nonnegative_fit(A: np.ndarray, keep: np.ndarray, b: np.ndarray, x: np.ndarray) -> float:
    """Non-negative ``x`` (filled; zero off ``keep``) least-squares closest to ``A x = b``; returns ``|A x - b|``.

    ``A`` (m, N) and ``b`` (m,) float64, ``keep`` (N,) bool: the columns ``x`` may use; all C-contiguous.
    """
    m, N = A.shape
    passive = np.zeros(m, dtype=np.int64)  # the passive columns, in the order they entered
    rejected = np.zeros(N, dtype=np.bool_)  # passed over until another column enters
    r = np.empty(m)  # the residual b - A x
    R = np.empty((m, m))  # the passive columns, reduced to triangular form
    qb = np.empty(m)  # b under the same reflections
    z = np.empty(m)  # the least-squares coefficients of the passive columns
    for k in range(N):
        x[k] = 0.0
    p = 0
    for i in range(m):
        r[i] = b[i]
    for _ in range(3 * N + 1):  # SciPy's cap on the columns tried; past it the fit so far is returned (a candidate)
        best, j = 0.0, -1
        for k in range(N):
            if keep[k] and x[k] == 0.0 and not rejected[k]:
                w = 0.0
                for i in range(m):
                    w += A[i, k] * r[i]
                if w > best:
                    best, j = w, k
        if j < 0 or p == m:
            break
        passive[p] = j
        p += 1
        entered = False
        while True:
            if not _passive_least_squares(A, passive, p, b, R, qb, z):
                break  # the new column depends on the others
            if not entered:
                if z[p - 1] <= 0.0:
                    break  # its coefficient would not be positive
                entered = True
                for k in range(N):
                    rejected[k] = False
            alpha, leaving = 2.0, -1  # the step back to the first coefficient that reaches zero
            for c in range(p):
                if z[c] <= 0.0:
                    step = x[passive[c]] / (x[passive[c]] - z[c])
                    if step < alpha:
                        alpha, leaving = step, c
            if leaving < 0:
                for c in range(p):
                    x[passive[c]] = z[c]
                break
            kept = 0
            for c in range(p):
                k = passive[c]
                x[k] = x[k] + alpha * (z[c] - x[k])
                if x[k] > 0.0 and c != leaving:
                    passive[kept] = k
                    kept += 1
                else:
                    x[k] = 0.0
            p = kept
        if not entered:
            p -= 1
            rejected[j] = True
        for i in range(m):
            r[i] = b[i]
            for c in range(p):
                r[i] -= A[i, passive[c]] * x[passive[c]]
    total = 0.0
    for i in range(m):
        value = -b[i]
        for k in range(N):
            if x[k] != 0.0:
                value += A[i, k] * x[k]
        total += value * value
    return math.sqrt(total)


@njit
def _passive_least_squares(A: np.ndarray, passive: np.ndarray, p: int, b: np.ndarray, R: np.ndarray, qb: np.ndarray, z: np.ndarray) -> bool:
    """``z[:p]``, the least-squares coefficients of the ``p`` passive columns of ``A`` for ``b``, by Householder
    reflections; False when a column's part off the span of those before it is below :data:`INDEPENDENT` of its
    norm (only the newest can be, but for round-off: the others entered independent of those before them)."""
    m = A.shape[0]
    for c in range(p):
        for i in range(m):
            R[i, c] = A[i, passive[c]]
    for i in range(m):
        qb[i] = b[i]
    for c in range(p):
        tail = 0.0
        for i in range(c, m):
            tail += R[i, c] * R[i, c]
        tail = math.sqrt(tail)
        whole = tail * tail
        for i in range(c):
            whole += R[i, c] * R[i, c]
        if not tail > INDEPENDENT * math.sqrt(whole):
            return False
        head = -tail if R[c, c] >= 0.0 else tail  # the reflected entry, of the sign that avoids cancellation
        R[c, c] = R[c, c] - head  # the reflection's vector v: R[c:, c]
        scale = 0.0
        for i in range(c, m):
            scale += R[i, c] * R[i, c]
        for cc in range(c + 1, p):
            s = 0.0
            for i in range(c, m):
                s += R[i, c] * R[i, cc]
            s = 2.0 * s / scale
            for i in range(c, m):
                R[i, cc] -= s * R[i, c]
        s = 0.0
        for i in range(c, m):
            s += R[i, c] * qb[i]
        s = 2.0 * s / scale
        for i in range(c, m):
            qb[i] -= s * R[i, c]
        R[c, c] = head
    for c in range(p - 1, -1, -1):
        value = qb[c]
        for cc in range(c + 1, p):
            value -= R[c, cc] * z[cc]
        z[c] = value / R[c, c]
    return True


def column_words(columns: int, count: int) -> np.ndarray:
    """A bit set of ``count`` columns as :func:`fit_or_farkas` reads it: int64 words, bit ``j`` of word ``j // 64`` for
    column ``j`` (read-only)."""
    return np.frombuffer(columns.to_bytes(8 * ((count + 63) // 64), "little"), dtype=np.int64)


def _fit_or_farkas_compiled(
    A: np.ndarray, keep: np.ndarray, b: np.ndarray, margin: float, ceiling: float, x: np.ndarray, y: np.ndarray, bits: np.ndarray
) -> int:
    """:func:`fit_or_farkas`'s loops in C (without numba, where the extension was built)."""
    return compiled_fit_or_farkas(A, keep, b, margin, ceiling, INDEPENDENT, x, y, bits)


def _fit_or_farkas_numpy(
    A: np.ndarray, keep: np.ndarray, b: np.ndarray, margin: float, ceiling: float, x: np.ndarray, y: np.ndarray, bits: np.ndarray
) -> int:
    """:func:`fit_or_farkas` in numpy calls (without numba or the C extension)."""
    mask = np.unpackbits(keep.view(np.uint8), count=A.shape[1], bitorder="little").view(bool)
    residual = nonnegative_fit(A, mask, b, x)
    if residual > margin:
        y[:] = b - A @ x
        reserve = float(b @ y) - margin * math.sqrt(float(y @ y))
        if reserve > 0.0:
            _pack(A.T @ y * ceiling >= reserve, bits)
            if not (bits & keep).any():
                return FIT_EXCLUDED
    _pack(x > 0.0, bits)
    return FIT_BALANCES if residual <= margin else FIT_CANDIDATE


def _pack(mask: np.ndarray, bits: np.ndarray) -> None:
    """``mask`` (bool) written into ``bits`` as :func:`column_words` reads it."""
    packed = np.packbits(mask, bitorder="little")
    bits[:] = 0
    bits.view(np.uint8)[: packed.size] = packed


@njit(python=_fit_or_farkas_compiled if HAVE_FIT_OR_FARKAS else _fit_or_farkas_numpy)
def fit_or_farkas(
    A: np.ndarray, keep: np.ndarray, b: np.ndarray, margin: float, ceiling: float, x: np.ndarray, y: np.ndarray, bits: np.ndarray
) -> int:
    """The branch and bound's step at a node: :func:`nonnegative_fit` on the columns ``keep`` sets (int64 words, as
    :func:`column_words` makes them), then, where it does not balance the load, its residual as a Farkas vector.

    Returns :data:`FIT_BALANCES` (``|A x - b| <= margin``: ``bits`` the columns ``x`` uses), :data:`FIT_EXCLUDED`
    (``y = b - A x`` excludes every balancing ``x`` on the kept columns whose sum is below ``ceiling``: with
    ``reserve = b.y - margin |y| > 0``, ``bits`` the columns ``j`` it cannot exclude, ``(A^T y)_j ceiling >=
    reserve``, and the kept columns hold none of them) or :data:`FIT_CANDIDATE` (neither: ``bits`` the columns
    ``x`` uses). ``A`` (m, N), ``b`` (m,) float64 C-contiguous; ``x`` (N,), ``y`` (m,), ``bits`` (words) filled.
    Every outcome is a candidate: the caller's proofs rest on the checks here, made in floats as written.
    """
    m, N = A.shape
    mask = np.empty(N, dtype=np.bool_)
    for k in range(N):
        mask[k] = (keep[k >> 6] >> (k & 63)) & 1 == 1
    residual = nonnegative_fit(A, mask, b, x)
    if residual > margin:
        toward, square = 0.0, 0.0
        for i in range(m):
            s = 0.0
            for k in range(N):
                s += A[i, k] * x[k]
            y[i] = b[i] - s
            toward += b[i] * y[i]
            square += y[i] * y[i]
        reserve = toward - margin * math.sqrt(square)
        if reserve > 0.0:
            met = 0
            bits[:] = 0
            for k in range(N):
                s = 0.0
                for i in range(m):
                    s += A[i, k] * y[i]
                if s * ceiling >= reserve:
                    bits[k >> 6] |= np.int64(1) << (k & 63)
            for w in range(bits.size):
                met |= bits[w] & keep[w]
            if met == 0:
                return FIT_EXCLUDED
    bits[:] = 0
    for k in range(N):
        if x[k] > 0.0:
            bits[k >> 6] |= np.int64(1) << (k & 63)
    return FIT_BALANCES if residual <= margin else FIT_CANDIDATE
