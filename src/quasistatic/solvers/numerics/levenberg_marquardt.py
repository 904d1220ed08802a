"""Levenberg-Marquardt on small smooth equations whose residual and Jacobian come in one call.

The exact-cone refinement solves the fixed-mode laws (10-30 unknowns) from a pyramid motion. SciPy's
``least_squares`` costs ~0.2-0.3 ms of Python per evaluation there, where the laws themselves are compiled and
cost microseconds; :func:`levenberg_marquardt` costs ~40 us of numpy calls per step, and
:func:`fixed_mode_fit`, the same loop on the fixed-mode laws compiled by numba, a few (docs/performance.md). It
is a local method, as SciPy's is: it finds a zero near the start or stalls; the caller checks what it returns.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from ...jit import njit
from ...laws.fixed_modes import system

__all__ = ["EquationFit", "levenberg_marquardt", "fixed_mode_fit"]

Equations = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # x -> residual (N,), Jacobian (N, N)

FIRST_DAMPING = 1e-3  # Marquardt's damping at the start, relative to each unknown's own curvature
POLISH_STEPS = 3  # steps taken once the residual is within the tolerance, towards machine precision
MOST_DAMPING = 1e30  # the damping at which the method has stalled (steps of ~1e-30 of a Newton step)


class EquationFit(NamedTuple):
    """Where the iteration stopped: the unknowns, their largest residual entry, and how many evaluations it took."""

    x: np.ndarray
    worst: float
    evaluations: int


def levenberg_marquardt(equations: Equations, x0: np.ndarray, tolerance: float, max_evaluations: int) -> EquationFit:
    """A zero of ``equations`` near ``x0``: Levenberg-Marquardt steps until the largest residual entry is at most
    ``tolerance``, then :data:`POLISH_STEPS` more (or until one fails to lower the residual), or until it stalls or
    has made ``max_evaluations`` evaluations; the caller judges the returned ``worst``.

    The damping scales each unknown by its own curvature (Marquardt's ``diag(J^T J)``: twists and forces differ
    in scale, and a plain identity stalled on grasp-3d 6 #0 where MINPACK's scaled method converges) and follows
    Nielsen's rule (shrunk by the step's gain ratio, doubled and redoubled on failure).
    """
    x = np.array(x0, dtype=float)
    residual, jacobian = equations(x)
    cost = float(residual @ residual)
    evaluations, damping, growth, converged = 1, FIRST_DAMPING, 2.0, 0
    while evaluations < max_evaluations and damping < MOST_DAMPING:
        if float(np.max(np.abs(residual), initial=0.0)) <= tolerance:
            converged += 1
            if converged > POLISH_STEPS:
                break
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ residual
        curvature = normal.diagonal().copy()
        scale = np.maximum(curvature, 1e-12 * float(curvature.max(initial=1.0)))  # a zero column still damped
        normal.flat[:: normal.shape[0] + 1] += damping * scale  # J^T J + damping diag(scale), in place
        try:
            step = np.linalg.solve(normal, -gradient)
        except np.linalg.LinAlgError:
            damping, growth = damping * growth, 2.0 * growth
            continue
        new_residual, new_jacobian = equations(x + step)
        evaluations += 1
        new_cost = float(new_residual @ new_residual)
        predicted = float(step @ (damping * scale * step - gradient))  # the decrease the damped model promised
        gain = (cost - new_cost) / predicted if predicted > 0.0 and np.isfinite(new_cost) else -1.0
        if gain > 0.0:
            x, residual, jacobian, cost = x + step, new_residual, new_jacobian, new_cost
            damping *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
            growth = 2.0
        elif converged:
            break  # within the tolerance, and no step lowers the residual further: machine precision
        else:
            damping, growth = damping * growth, 2.0 * growth
    return EquationFit(x, float(np.max(np.abs(residual), initial=0.0)), evaluations)


def _fixed_mode_fit_numpy(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    x0: np.ndarray,
    kind: np.ndarray,
    column: np.ndarray,
    n: int,
    tolerance: float,
    max_evaluations: int,
) -> tuple[np.ndarray, float, int]:
    """:func:`fixed_mode_fit` without numba: :func:`levenberg_marquardt` on :func:`system` (the C extension's)."""
    fit = levenberg_marquardt(lambda x: system(J, b, mu, g, x, kind, column, n)[:2], x0, tolerance, max_evaluations)
    return fit.x, fit.worst, fit.evaluations


@njit(python=_fixed_mode_fit_numpy)
def fixed_mode_fit(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    x0: np.ndarray,
    kind: np.ndarray,
    column: np.ndarray,
    n: int,
    tolerance: float,
    max_evaluations: int,
) -> tuple[np.ndarray, float, int]:
    """:func:`levenberg_marquardt` on the fixed-mode laws :func:`~quasistatic.laws.fixed_modes.system` (its
    arguments, ``x0`` (N,) the start): the zero's unknowns, their largest residual entry, and the evaluations made.
    The same steps, in the same order, as the numpy loop (its twin without numba)."""
    x = x0.copy()
    residual, jacobian, _ = system(J, b, mu, g, x, kind, column, n)
    cost = np.dot(residual, residual)
    size = x.shape[0]
    evaluations, damping, growth, converged = 1, FIRST_DAMPING, 2.0, 0
    while evaluations < max_evaluations and damping < MOST_DAMPING:
        if np.max(np.abs(residual)) <= tolerance:
            converged += 1
            if converged > POLISH_STEPS:
                break
        normal = np.dot(jacobian.T, jacobian)
        gradient = np.dot(jacobian.T, residual)
        curvature = np.diag(normal).copy()
        scale = np.maximum(curvature, 1e-12 * max(np.max(curvature), 1.0))
        for i in range(size):
            normal[i, i] += damping * scale[i]
        try:
            step = np.linalg.solve(normal, -gradient)
        except Exception:  # numba raises numpy's LinAlgError as a plain exception
            damping, growth = damping * growth, 2.0 * growth
            continue
        new_residual, new_jacobian, _ = system(J, b, mu, g, x + step, kind, column, n)
        evaluations += 1
        new_cost = np.dot(new_residual, new_residual)
        predicted = np.dot(step, damping * scale * step - gradient)
        gain = (cost - new_cost) / predicted if predicted > 0.0 and np.isfinite(new_cost) else -1.0
        if gain > 0.0:
            x, residual, jacobian, cost = x + step, new_residual, new_jacobian, new_cost
            damping *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
            growth = 2.0
        elif converged:
            break
        else:
            damping, growth = damping * growth, 2.0 * growth
    return x, np.max(np.abs(residual)), evaluations
