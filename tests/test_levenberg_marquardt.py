"""The refinement's Levenberg-Marquardt loop on the fixed-mode laws (``solvers/numerics/levenberg_marquardt.py``):
it finds the zeros SciPy's ``least_squares`` finds (the loop it replaced), to round-off; it reports its residual
where no zero is near; and its step's compiled linear algebra is its numpy twin's."""

from __future__ import annotations

import numpy as np
import pytest

from quasistatic.laws import ModeMasks, Problem, RawMotion, contact_modes
from quasistatic.laws.assemble import assemble
from quasistatic.laws.fixed_modes import FixedModeLaws
from quasistatic.solvers.fast import solve_fast
from quasistatic.solvers.numerics.levenberg_marquardt import _damped_step_numpy, damped_step, fixed_mode_fit
from quasistatic.solvers.numerics.optimize import least_squares
from quasistatic.solvers.result import Options
from quasistatic.tolerances import FIXED_MODE_RESIDUAL, LEAST_SQUARES_STEP
from quasistatic.tools.bench.families import grasp_3d


def _fast_motion(contacts: int, index: int) -> tuple[Problem, RawMotion]:
    problem = assemble(grasp_3d(contacts, index))
    return problem, solve_fast(problem, Options()).motions[0]


def _patterns(problem: Problem, motion: RawMotion) -> list[FixedModeLaws]:
    """The laws with the motion's modes, and with each of its sliding contacts opened instead."""
    masks = ModeMasks.of(problem, np.array(contact_modes(problem, motion.q), dtype=object))
    laws = [FixedModeLaws(problem, masks)]
    for sliding in np.flatnonzero(masks.sliding):
        closed = masks.closed.copy()
        closed[sliding] = False
        laws.append(FixedModeLaws(problem, ModeMasks(closed, masks.rolling & closed, masks.sliding & closed)))
    return laws


@pytest.mark.parametrize(("contacts", "index"), [(4, 0), (6, 3), (8, 0)])
def test_finds_the_zero_scipy_finds(contacts: int, index: int) -> None:
    """From the exact motion perturbed by 0.1 %, both land on it: the same twist to 1e-12, residual to machine precision."""
    problem, motion = _fast_motion(contacts, index)
    laws = _patterns(problem, motion)[0]
    x0 = laws.start(motion.q, motion.c) * (1.0 + 1e-3 * np.cos(np.arange(laws.size)))
    x, worst, evaluations = fixed_mode_fit(laws, x0, FIXED_MODE_RESIDUAL, 200 * x0.size)
    tolerances = {"xtol": LEAST_SQUARES_STEP, "ftol": LEAST_SQUARES_STEP, "gtol": LEAST_SQUARES_STEP}
    scipy_fit = least_squares(laws.residual, x0, jac=laws.jacobian, method="lm", **tolerances)
    assert worst <= 1e-13 and evaluations < 50
    np.testing.assert_allclose(x[: laws.n], scipy_fit.x[: laws.n], rtol=0, atol=1e-12)


def test_reports_its_residual_where_no_zero_is_near() -> None:
    """grasp-3d 8 #1 with one sliding contact opened: some such patterns have no zero near the motion; the fit
    says so (its residual above the tolerance) within its budget of evaluations, and others converge."""
    problem, motion = _fast_motion(8, 1)
    worst = []
    for laws in _patterns(problem, motion)[1:]:
        x0 = laws.start(motion.q, motion.c)
        _, residual, evaluations = fixed_mode_fit(laws, x0, FIXED_MODE_RESIDUAL, 20 * x0.size)
        assert evaluations <= 20 * x0.size
        worst.append(residual)
    assert max(worst) > FIXED_MODE_RESIDUAL and min(worst) <= FIXED_MODE_RESIDUAL


def test_the_damped_step_is_its_numpy_twin() -> None:
    """The compiled step (loops, Cholesky's factor) and its twin (numpy's products, LAPACK's solve) agree to
    round-off on random Jacobians, tall, square and with a zero column, at small and large damping."""
    pytest.importorskip("numba")
    rng = np.random.default_rng(11)
    for rows, size in [(12, 12), (20, 9), (5, 5), (30, 30)]:
        jacobian, residual = rng.normal(size=(rows, size)) * 10.0 ** rng.uniform(-3, 3, size), rng.normal(size=rows)
        jacobian[:, size // 2] = 0.0
        for damping in (1e-9, 1e-3, 1e3):
            step, predicted, solved = damped_step(jacobian, residual, damping)
            twin_step, twin_predicted, twin_solved = _damped_step_numpy(jacobian, residual, damping)
            assert solved and twin_solved
            np.testing.assert_allclose(step, twin_step, rtol=1e-6, atol=1e-12 * np.max(np.abs(twin_step)))
            assert predicted == pytest.approx(twin_predicted, rel=1e-8)


def test_a_singular_damped_matrix_is_refused() -> None:
    """Undamped, a zero Jacobian's normal matrix is singular: the step says so (compiled or twin), and the fit then
    raises its damping instead of stepping."""
    for step in (damped_step, _damped_step_numpy):
        assert not step(np.zeros((3, 2)), np.ones(3), 0.0)[2]
