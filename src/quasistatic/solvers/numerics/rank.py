"""Is a matrix of full column rank, to an absolute singular-value threshold, without a dense SVD of a large matrix.

A small matrix (its smaller side at most ``DENSE_MAX``) gets LAPACK's SVD:
cheap, exact and the same with any number of BLAS threads. A large one is
sparse (each contact row touches one or two bodies), and its dense SVD costs
O(r c^2) and depends on the BLAS thread count (the 1000-box pile: 12 s for
one), so its smallest singular value is tested through the sparse LU of the
augmented matrix

    K = [[a I, A], [A^T, 0]]    (a = the threshold)

whose eigenvalues are ``a`` (r - c times) and ``(a +- sqrt(a^2 + 4 s^2)) / 2``
for each singular value ``s`` of ``A``. The smallest in magnitude is
``f(s_min) = (sqrt(a^2 + 4 s_min^2) - a) / 2`` (``f`` grows with ``s`` and
``f(a) = 0.618 a < a``), so ``s_min > a`` exactly when every eigenvalue of
``K`` exceeds ``f(a)`` in magnitude, i.e. ``||K^-1||_2 < 1 / f(a)``. With
``a`` at the threshold, ``K`` is about as well conditioned as ``A`` near it
(Bjorck's scaling of the augmented system), so the LU resolves the question.
``||K^-1||_2`` (K symmetric) is found by power iteration with the LU's
solves; an exactly singular ``K`` stops the LU, and a nearly singular one
makes the iteration blow up at once.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

__all__ = ["full_column_rank", "DENSE_MAX"]

DENSE_MAX = 64  # largest smaller side whose rank is taken from a dense SVD
_POWER_STEPS = 30  # most power-iteration steps for ||K^-1||
_CONVERGED = 1e-3  # relative change of the estimate at which the iteration stops
_GOLDEN = (5.0**0.5 - 1.0) / 2.0  # f(a) / a


def full_column_rank(A: np.ndarray | sp.spmatrix, tol: float) -> bool:
    """True when every singular value of ``A`` (r, c) exceeds ``tol`` (absolute: the data are scene-relative).

    A matrix with more columns than rows, or none, is never of full column
    rank (an empty column set is: no column can depend on the others).
    """
    r, c = A.shape
    if c == 0:
        return True
    if r < c:
        return False
    if c <= DENSE_MAX:
        dense = np.asarray(A.toarray() if isinstance(A, sp.spmatrix | sp.sparray) else A, dtype=float)
        return bool(np.linalg.svd(dense, compute_uv=False)[-1] > tol)
    sparse = sp.csc_matrix(A)
    if np.count_nonzero(sparse.getnnz(axis=1)) < c:
        # Fewer rows with entries than columns: rank-deficient by its pattern. SuperLU is not asked, as its pivoting
        # can read uninitialised memory on the structurally singular K (xiaoyeli/superlu#33): a segfault, 1 run in
        # 10, on the force ranges of a random 3-D scene's ambiguous answer (140 x 134, 9 rows with entries).
        return False
    return _augmented_norm(sparse, tol) < 1.0 / (_GOLDEN * tol)


def _augmented_norm(A: sp.csc_matrix, a: float) -> float:
    """``||K^-1||_2`` of ``K = [[a I, A], [A^T, 0]]``; infinite when its LU finds ``K`` singular."""
    r, c = A.shape
    K = sp.bmat([[a * sp.identity(r, format="csc"), A], [A.T, None]], format="csc")
    try:
        lu = splu(K, permc_spec="COLAMD", diag_pivot_thresh=1.0)
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        return np.inf
    # A fixed, generic start: no random state, the same answer every run.
    x = np.cos(np.arange(r + c) * 1.618033988749895 + 0.5)
    x /= np.linalg.norm(x)
    estimate = 0.0
    for _ in range(_POWER_STEPS):
        y = lu.solve(x)
        size = float(np.linalg.norm(y))
        if not np.isfinite(size) or size == 0.0:
            return np.inf if not np.isfinite(size) else estimate
        x = y / size
        if abs(size - estimate) <= _CONVERGED * size:
            return size
        estimate = size
    return estimate
