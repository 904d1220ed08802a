"""The refinement's Levenberg-Marquardt loop (``solvers/numerics/levenberg_marquardt.py``): it reaches a zero
to machine precision where one is near, reports its residual where none is, and on the exact-cone refinement
finds the zeros SciPy's ``least_squares`` finds (the loop it replaced), to round-off."""

from __future__ import annotations

import numpy as np
import pytest

from quasistatic.laws import ModeMasks, contact_modes
from quasistatic.laws.assemble import assemble
from quasistatic.laws.fixed_modes import FixedModeLaws
from quasistatic.solvers.fast import solve_fast
from quasistatic.solvers.numerics.levenberg_marquardt import _fixed_mode_fit_numpy, fixed_mode_fit, levenberg_marquardt
from quasistatic.solvers.numerics.optimize import least_squares
from quasistatic.solvers.result import Options
from quasistatic.tolerances import FIXED_MODE_RESIDUAL, LEAST_SQUARES_STEP
from quasistatic.tools.bench.families import grasp_3d


def _badly_scaled(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A circle meeting a line, with the second unknown scaled by 1e4 (twists and forces differ so in scale)."""
    a, b = x[0], 1e-4 * x[1]
    residual = np.array([a * a + b * b - 1.0, a - 2.0 * b])
    jacobian = np.array([[2.0 * a, 2e-4 * b], [1.0, -2e-4]])
    return residual, jacobian


def test_reaches_a_near_zero_to_machine_precision() -> None:
    fit = levenberg_marquardt(_badly_scaled, np.array([0.5, 3e3]), 1e-10, 200)
    root = np.array([2.0, 1e4]) / np.sqrt(5.0)
    assert fit.worst <= 1e-15
    np.testing.assert_allclose(fit.x, root, rtol=1e-14)
    assert fit.evaluations < 30


def test_reports_the_residual_where_no_zero_exists() -> None:
    def parabola(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # x^2 + 1 has no real zero
        return np.array([x[0] * x[0] + 1.0]), np.array([[2.0 * x[0]]])

    fit = levenberg_marquardt(parabola, np.array([0.3]), 1e-10, 100)
    assert fit.worst == pytest.approx(1.0, abs=1e-6)
    assert fit.evaluations <= 100


@pytest.mark.parametrize(("contacts", "index"), [(4, 0), (6, 3), (8, 0)])
def test_finds_the_zero_scipy_finds_on_the_exact_laws(contacts: int, index: int) -> None:
    """From the fast path's pyramid-like start (the exact motion, perturbed), both land on the same motion."""
    problem = assemble(grasp_3d(contacts, index))
    raw = solve_fast(problem, Options()).motions[0]
    laws = FixedModeLaws(problem, ModeMasks.of(problem, np.array(contact_modes(problem, raw.q), dtype=object)))
    x0 = laws.start(raw.q, raw.c) * (1.0 + 1e-3 * np.cos(np.arange(laws.size)))
    fit = levenberg_marquardt(lambda x: (laws.residual(x), laws.jacobian(x)), x0, FIXED_MODE_RESIDUAL, 200 * x0.size)
    tolerances = {"xtol": LEAST_SQUARES_STEP, "ftol": LEAST_SQUARES_STEP, "gtol": LEAST_SQUARES_STEP}
    scipy_fit = least_squares(laws.residual, x0, jac=laws.jacobian, method="lm", **tolerances)
    assert fit.worst <= FIXED_MODE_RESIDUAL
    np.testing.assert_allclose(fit.x[: laws.n], scipy_fit.x[: laws.n], rtol=0, atol=1e-12)


@pytest.mark.parametrize(("contacts", "index"), [(6, 1), (8, 1)])
def test_the_compiled_fit_is_its_numpy_twin(contacts: int, index: int) -> None:
    """``fixed_mode_fit`` (numba) and its twin agree on every refinement attempt of two bench grasps: the same
    verdict, and where they converge the same zero to round-off (where they stall, the stalls may differ)."""
    pytest.importorskip("numba")
    problem = assemble(grasp_3d(contacts, index))
    raw = solve_fast(problem, Options()).motions[0]
    masks = ModeMasks.of(problem, np.array(contact_modes(problem, raw.q), dtype=object))
    converged = 0
    for k, sliding in enumerate(np.flatnonzero(masks.sliding)):  # the motion's modes, and each slider opened
        closed = masks.closed.copy()
        closed[sliding] = k == 0
        laws = FixedModeLaws(problem, ModeMasks(closed, masks.rolling & closed, masks.sliding & closed))
        x0 = laws.start(raw.q, raw.c) * (1.0 + 1e-2 * np.cos(np.arange(laws.size)))
        args = (laws.J, laws.b, laws.mu, laws.g, x0, laws.kind, laws.column, laws.n, FIXED_MODE_RESIDUAL, 20 * x0.size)
        compiled, twin = fixed_mode_fit(*args), _fixed_mode_fit_numpy(*args)
        assert (compiled[1] <= FIXED_MODE_RESIDUAL) == (twin[1] <= FIXED_MODE_RESIDUAL)
        if twin[1] <= FIXED_MODE_RESIDUAL:
            converged += 1
            np.testing.assert_allclose(compiled[0], twin[0], rtol=0, atol=1e-12)
    assert converged >= 1
