"""The mode branch and bound's force fit (``solvers/numerics/nnls.py``): non-negative least squares on a mask of columns.

Whichever implementation this install runs (the numba kernel, its loops in C, or SciPy's ``nnls``), the fit is
optimal: non-negative, zero off the mask, no kept column that would lower the residual, and the residual's norm
SciPy's to round-off. The C loops give the numba kernel's bits, and the kernel's plain-Python loops its results.
The branch and bound's whole step (``fit_or_farkas``: the fit on a bit set of columns, then its residual checked as a
Farkas vector) keeps its promises in every implementation: a balancing fit balances, an excluding vector excludes.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import NamedTuple

import numpy as np
import pytest
from scipy.optimize import nnls

from quasistatic import compiled
from quasistatic.solvers.numerics import nnls as fit_module
from quasistatic.solvers.numerics.nnls import FIT_BALANCES, FIT_CANDIDATE, FIT_EXCLUDED, column_words, fit_or_farkas, nonnegative_fit
from quasistatic.tolerances import FORCE_CEILING


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


MARGIN = 1e-6


class _Step(NamedTuple):
    outcome: int
    x: np.ndarray
    y: np.ndarray
    bits: int


def _words(mask: np.ndarray) -> np.ndarray:
    return column_words(int.from_bytes(np.packbits(mask, bitorder="little").tobytes(), "little"), mask.size)


def _step(
    A: np.ndarray, keep: np.ndarray, b: np.ndarray, ceiling: float = FORCE_CEILING, step: Callable[..., int] = fit_or_farkas
) -> _Step:
    x, y, bits = np.full(A.shape[1], np.nan), np.full(A.shape[0], np.nan), np.full((A.shape[1] + 63) // 64, 7, dtype=np.int64)
    outcome = step(np.ascontiguousarray(A), _words(keep), b, MARGIN, ceiling, x, y, bits)
    return _Step(outcome, x, y, int.from_bytes(bits.tobytes(), "little"))


def _steps() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, float]]:
    """``(A, keep, b, ceiling)``: the fit's problems, loads balanced by a point of their cone, more than 64 columns
    (two words), and a huge ceiling (round-off in ``A^T y`` then blocks the kept columns: neither outcome)."""
    for A, keep, b in _problems():
        yield A, keep, b, FORCE_CEILING
        yield A, keep, A[:, keep] @ np.linspace(0.5, 1.0, int(keep.sum())) if keep.any() else b, FORCE_CEILING
    rng = np.random.default_rng(11)
    for _ in range(8):
        A = rng.normal(size=(6, 130))
        yield A, rng.random(130) < 0.3, rng.normal(size=6), FORCE_CEILING
        yield A, rng.random(130) < 0.05, rng.normal(size=6), 1e30


def test_column_words_hold_the_bits_in_order() -> None:
    columns = (1 << 129) | (1 << 64) | (1 << 63) | 5
    words = column_words(columns, 130)
    assert words.dtype == np.int64 and words.size == 3
    assert [j for j in range(130) if (int(words[j // 64]) >> (j % 64)) & 1] == [0, 2, 63, 64, 129]


def test_each_outcome_keeps_its_promise() -> None:
    seen = set()
    for A, keep, b, ceiling in _steps():
        step = _step(A, keep, b, ceiling)
        seen.add(step.outcome)
        support = int.from_bytes(np.packbits(step.x > 0.0, bitorder="little").tobytes(), "little")
        assert np.all(step.x >= 0.0) and not step.x[~keep].any()
        residual = float(np.linalg.norm(A @ step.x - b))
        if step.outcome == FIT_EXCLUDED:  # no forces on the kept columns below the ceiling come within the margin
            np.testing.assert_allclose(step.y, b - A @ step.x, rtol=1e-12, atol=1e-14)
            reserve = float(b @ step.y) - MARGIN * float(np.linalg.norm(step.y))
            assert reserve > 0.0
            assert np.all((A.T @ step.y)[keep] * ceiling < reserve * (1.0 + 1e-9))
            blockers = A.T @ step.y * ceiling >= reserve
            assert step.bits & ~int.from_bytes(np.packbits(blockers, bitorder="little").tobytes(), "little") == 0
        else:
            assert step.bits == support
            assert (residual <= MARGIN * (1.0 + 1e-9)) == (step.outcome == FIT_BALANCES)
    assert seen == {FIT_BALANCES, FIT_EXCLUDED, FIT_CANDIDATE}


def test_the_numpy_twin_decides_as_the_kernel() -> None:
    for A, keep, b, ceiling in _steps():
        if ceiling > FORCE_CEILING:
            continue  # round-off decides there
        step, twin = _step(A, keep, b, ceiling), _step(A, keep, b, ceiling, fit_module._fit_or_farkas_numpy)
        assert twin.outcome == step.outcome
        np.testing.assert_allclose(twin.x[keep], step.x[keep], rtol=1e-7, atol=1e-10)


@pytest.mark.skipif(not compiled.HAVE_FIT_OR_FARKAS, reason="built without the C extensions")
def test_the_c_step_gives_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(fit_or_farkas, numba.core.registry.CPUDispatcher)
    for A, keep, b, ceiling in _steps():
        step, c = _step(A, keep, b, ceiling), _step(A, keep, b, ceiling, fit_module._fit_or_farkas_compiled)
        assert c.outcome == step.outcome and c.bits == step.bits
        np.testing.assert_array_equal(c.x, step.x)
        if step.outcome != FIT_BALANCES:
            np.testing.assert_array_equal(c.y, step.y)


def test_the_steps_plain_python_loops_give_its_results() -> None:
    loops = getattr(fit_or_farkas, "py_func", None)
    if loops is None:
        pytest.skip("without numba the kernel's name is bound to its twin")
    for A, keep, b, ceiling in _steps():
        if A.shape[1] > 12:
            continue  # plain Python loops: small ones only
        step, plain = _step(A, keep, b, ceiling), _step(A, keep, b, ceiling, loops)
        assert plain.outcome == step.outcome and plain.bits == step.bits
        np.testing.assert_allclose(plain.x, step.x, rtol=1e-10, atol=1e-14)


@pytest.mark.skipif(not compiled.HAVE_FIT_OR_FARKAS, reason="built without the C extensions")
@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ((np.ones((3, 4)), np.ones(1, dtype=bool), np.ones(3), np.empty(4), np.empty(3), np.empty(1, np.int64)), "keep must be"),
        ((np.ones((3, 70)), np.ones(1, np.int64), np.ones(3), np.empty(70), np.empty(3), np.empty(2, np.int64)), "keep must have"),
        ((np.ones((3, 4)), np.ones(1, np.int64), np.ones(3), np.empty(4), np.empty(4), np.empty(1, np.int64)), "y must have"),
        ((np.ones((3, 4)), np.ones(1, np.int64), np.ones(3), np.empty(4), np.empty(3), np.empty(2, np.int64)), "bits must have"),
    ],
)
def test_the_c_step_rejects_bad_arguments(arguments: tuple[np.ndarray, ...], message: str) -> None:
    A, keep, b, x, y, bits = arguments
    with pytest.raises(ValueError, match=message):
        compiled.fit_or_farkas(A, keep, b, MARGIN, FORCE_CEILING, fit_module.INDEPENDENT, x, y, bits)
