"""The HiGHS wrapper hands HiGHS a dense constraint matrix column by column exactly as SciPy's CSC conversion
holds it (``solvers/numerics/highs.py``), so every LP is the same model, to the bit, as before it skipped SciPy."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from quasistatic.solvers.numerics import highs


@pytest.mark.parametrize("shape", [(19, 6), (1, 3), (0, 4), (7, 1)])
def test_dense_columns_are_scipy_s_csc(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(sum(shape))
    A = rng.normal(size=shape)
    A[rng.random(shape) < 0.4] = 0.0
    if A.size:
        A.flat[0] = -0.0  # a signed zero is dropped, as SciPy drops it
    start, index, value = highs._columnwise(A)
    csc = sp.csc_matrix(A)
    for ours, scipys in ((start, csc.indptr), (index, csc.indices), (value, csc.data)):
        np.testing.assert_array_equal(ours, scipys)
        assert ours.dtype == scipys.dtype


def test_a_dense_lp_answers_as_its_sparse_copy() -> None:
    A = np.array([[1.0, 0.0, 2.0], [0.0, -1.0, 1.0], [1.0, 1.0, 0.0]])
    lower, upper = np.array([1.0, -np.inf, 0.5]), np.array([4.0, 2.0, np.inf])
    cost = np.array([1.0, 2.0, -1.0])
    bounds = (np.zeros(3), np.full(3, 5.0))
    dense = highs.solve_lp(cost, A, lower, upper, *bounds)
    sparse = highs.solve_lp(cost, sp.csr_matrix(A), lower, upper, *bounds)
    assert dense.status == sparse.status == "optimal"
    np.testing.assert_array_equal(dense.x, sparse.x)
    assert dense.objective == sparse.objective
