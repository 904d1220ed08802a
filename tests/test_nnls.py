"""The mode branch and bound's force fit (``solvers/numerics/nnls.py``): non-negative least squares on a mask of columns.

Whichever implementation this install runs (the numba kernel, its loops in C, or SciPy's ``nnls``), the fit is
optimal: non-negative, zero off the mask, no kept column that would lower the residual, and the residual's norm
SciPy's to round-off. The C loops give the numba kernel's bits, and the kernel's plain-Python loops its results.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest
from scipy.optimize import nnls

from quasistatic import compiled
from quasistatic.solvers.numerics import nnls as fit_module
from quasistatic.solvers.numerics.nnls import nonnegative_fit


def _problems() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """``(A, keep, b)``: random, wide (more columns than rows: several optimal fits), with repeated, zero and
    dependent columns, no kept column, a zero right-hand side, and a grasp's load columns."""
    rng = np.random.default_rng(7)
    for rows, columns in ((6, 4), (6, 12), (6, 60), (3, 30), (12, 40), (1, 5)):
        for _ in range(8):
            A = rng.normal(size=(rows, columns))
            yield A, rng.random(columns) < 0.7, rng.normal(size=rows)
    A = rng.normal(size=(6, 10))
    A[:, 3] = A[:, 1]  # a repeated column
    A[:, 5] = 0.0  # a zero column
    A[:, 7] = 2.0 * A[:, 0] - A[:, 2]  # a dependent one
    inside = A[:, :4] @ np.array([1.0, 0.5, 0.0, 2.0])  # a point of the cone: a zero residual
    for b in (rng.normal(size=6), inside, np.zeros(6)):
        yield A, np.ones(10, dtype=bool), b
    yield A, np.zeros(10, dtype=bool), rng.normal(size=6)


def _fit(A: np.ndarray, keep: np.ndarray, b: np.ndarray, fit: Callable[..., float] = nonnegative_fit) -> tuple[np.ndarray, float]:
    x = np.full(A.shape[1], np.nan)
    residual = fit(np.ascontiguousarray(A), keep, b, x)
    return x, residual


@pytest.mark.parametrize("fit", [nonnegative_fit, fit_module._nonnegative_fit_scipy], ids=["installed", "scipy-twin"])
def test_the_fit_is_optimal_and_has_scipys_residual(fit: Callable[..., float]) -> None:
    for A, keep, b in _problems():
        x, residual = _fit(A, keep, b, fit)
        assert np.all(x >= 0.0) and not x[~keep].any()
        assert residual == pytest.approx(float(np.linalg.norm(A @ x - b)), rel=1e-12, abs=1e-14)
        reference = nnls(A[:, keep], b)[1] if keep.any() else float(np.linalg.norm(b))
        assert residual == pytest.approx(reference, rel=1e-9, abs=1e-12)
        gradient = A.T @ (b - A @ x)  # no kept column lowers the residual; the used ones are at a stationary point
        scale = 1e-9 * (1.0 + np.abs(A).max() * (np.linalg.norm(b) + 1.0))
        assert np.all(gradient[keep] <= scale)
        assert np.all(np.abs(gradient[x > 0.0]) <= scale)


def test_a_point_of_the_cone_is_fitted_exactly() -> None:
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 30))
    b = A[:, [2, 9, 17]] @ np.array([0.3, 1.0, 2.5])
    x, residual = _fit(A, np.ones(30, dtype=bool), b)
    assert residual <= 1e-12 * np.linalg.norm(b)
    assert np.count_nonzero(x) <= 6


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_c_loops_give_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(nonnegative_fit, numba.core.registry.CPUDispatcher)
    for A, keep, b in _problems():
        A = np.ascontiguousarray(A)
        x, x_c = np.empty(A.shape[1]), np.empty(A.shape[1])
        residual = nonnegative_fit(A, keep, b, x)
        residual_c = compiled.nonnegative_fit(A, keep, b, x_c, fit_module.INDEPENDENT)
        assert residual_c == residual
        np.testing.assert_array_equal(x_c, x)


def test_the_kernels_plain_python_loops_give_its_results() -> None:
    """The loops as written (what numba compiles; plain Python when it is missing) against what this install runs."""
    loops = getattr(nonnegative_fit, "py_func", None)
    if loops is None:
        pytest.skip("without numba the kernel's name is bound to its twin")
    for A, keep, b in _problems():
        if A.shape[1] > 12:
            continue  # plain Python loops: small ones only
        x, residual = _fit(A, keep, b)
        x_loops = np.empty(A.shape[1])
        assert loops(np.ascontiguousarray(A), keep, b, x_loops) == pytest.approx(residual, rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(x_loops, x, rtol=1e-10, atol=1e-14)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ((np.ones((3, 4)).T, np.ones(3, dtype=bool), np.ones(4), np.empty(3)), "A must be a C-contiguous"),
        ((np.ones((3, 4)), np.ones(4), np.ones(3), np.empty(4)), "keep must be a C-contiguous bool"),
        ((np.ones((3, 4)), np.ones(4, dtype=bool), np.ones(4), np.empty(4)), "b must have 1 dimensions"),
        ((np.ones((3, 4)), np.ones(4, dtype=bool), np.ones(3), np.empty(4)[::-1]), "x must be a C-contiguous"),
    ],
)
def test_the_c_loops_reject_bad_arguments(arguments: tuple[np.ndarray, ...], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        compiled.nonnegative_fit(*arguments, fit_module.INDEPENDENT)
