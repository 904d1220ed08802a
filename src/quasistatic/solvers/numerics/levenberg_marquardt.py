"""Levenberg-Marquardt on the fixed-mode laws, the exact-cone refinement's solver.

The exact-cone refinement solves the fixed-mode laws (10-30 unknowns) from a pyramid motion. SciPy's
``least_squares`` costs ~0.2-0.3 ms of Python per evaluation there, where the laws themselves are compiled and
cost microseconds. :func:`fixed_mode_fit` is a Python loop around two compiled calls per step, the laws and
:func:`damped_step` (numba's loops; numpy's products and LAPACK without numba): ~17 us a step with numba, ~50
without (docs/performance.md). The loop itself is not compiled: numba took ~5-8 s to compile it (it compiles the
laws again inside it) on a cold cache, for ~13 us a step. It is a local method, as SciPy's is: it finds a zero
near the start or stalls; the caller checks what it returns.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...jit import njit
from ...laws.fixed_modes import FixedModeLaws, system

__all__ = ["EquationFit", "fixed_mode_fit", "damped_step"]

FIRST_DAMPING = 1e-3  # Marquardt's damping at the start, relative to each unknown's own curvature
POLISH_STEPS = 3  # steps taken once the residual is within the tolerance, towards machine precision
MOST_DAMPING = 1e30  # the damping at which the method has stalled (steps of ~1e-30 of a Newton step)


class EquationFit(NamedTuple):
    """Where the iteration stopped: the unknowns, their largest residual entry, and how many evaluations it took."""

    x: np.ndarray
    worst: float
    evaluations: int


def _damped_step_numpy(jacobian: np.ndarray, residual: np.ndarray, damping: float) -> tuple[np.ndarray, float, bool]:
    """:func:`damped_step` without numba: numpy's products and LAPACK's solve."""
    normal = jacobian.T @ jacobian
    gradient = jacobian.T @ residual
    curvature = normal.diagonal().copy()
    scale = np.maximum(curvature, 1e-12 * max(float(curvature.max(initial=0.0)), 1.0))  # a zero column still damped
    normal.flat[:: normal.shape[0] + 1] += damping * scale
    try:
        step = np.linalg.solve(normal, -gradient)
    except np.linalg.LinAlgError:
        return gradient, 0.0, False
    return step, float(step @ (damping * scale * step - gradient)), True


@njit(python=_damped_step_numpy)
def damped_step(jacobian: np.ndarray, residual: np.ndarray, damping: float) -> tuple[np.ndarray, float, bool]:
    """Levenberg-Marquardt's step ``-(J^T J + damping D)^-1 J^T r`` (``D``: the diagonal of ``J^T J``, each entry at
    least 1e-12 of the largest or of 1, so a zero column is still damped), the decrease of ``|r|^2`` its damped
    model predicts, and whether Cholesky's factorisation of the damped matrix held (a pivot not above 0: False).

    Loops: numba compiles them in a fraction of a second, where its ``np.dot`` and ``np.linalg.solve`` cost ~5 s
    of compilation on a cold cache; without numba, numpy's products and LAPACK run (the twin)."""
    rows, size = jacobian.shape
    normal = np.zeros((size, size))  # the lower half of J^T J
    gradient = np.zeros(size)
    for i in range(size):
        for j in range(i + 1):
            total = 0.0
            for k in range(rows):
                total += jacobian[k, i] * jacobian[k, j]
            normal[i, j] = total
        total = 0.0
        for k in range(rows):
            total += jacobian[k, i] * residual[k]
        gradient[i] = total
    largest = 1.0
    for i in range(size):
        largest = max(largest, normal[i, i])
    scale = np.empty(size)
    for i in range(size):
        scale[i] = max(normal[i, i], 1e-12 * largest)
        normal[i, i] += damping * scale[i]
    lower = np.zeros((size, size))  # Cholesky's factor of the damped matrix
    for j in range(size):
        pivot = normal[j, j]
        for k in range(j):
            pivot -= lower[j, k] * lower[j, k]
        if not pivot > 0.0:
            return gradient, 0.0, False
        lower[j, j] = np.sqrt(pivot)
        for i in range(j + 1, size):
            entry = normal[i, j]
            for k in range(j):
                entry -= lower[i, k] * lower[j, k]
            lower[i, j] = entry / lower[j, j]
    step = -gradient
    for i in range(size):  # lower y = -gradient
        for k in range(i):
            step[i] -= lower[i, k] * step[k]
        step[i] /= lower[i, i]
    for i in range(size - 1, -1, -1):  # lower^T step = y
        for k in range(i + 1, size):
            step[i] -= lower[k, i] * step[k]
        step[i] /= lower[i, i]
    predicted = 0.0
    for i in range(size):
        predicted += step[i] * (damping * scale[i] * step[i] - gradient[i])
    return step, predicted, True


def fixed_mode_fit(laws: FixedModeLaws, x0: np.ndarray, tolerance: float, max_evaluations: int) -> EquationFit:
    """A zero of the fixed-mode laws ``laws`` (their unknowns; ``x0`` (N,) the start) near ``x0``:
    Levenberg-Marquardt steps until the largest residual entry is at most ``tolerance``, then :data:`POLISH_STEPS`
    more (or until one fails to lower the residual), or until it stalls or has made ``max_evaluations``
    evaluations. The caller judges the fit's largest residual entry.

    The damping scales each unknown by its own curvature (:func:`damped_step`; twists and forces differ in scale,
    and a plain identity stalled on grasp-3d 6 #0 where MINPACK's scaled method converges) and follows Nielsen's
    rule (shrunk by the step's gain ratio, doubled and redoubled on failure)."""
    J, b, mu, g, kind, column, n = laws.J, laws.b, laws.mu, laws.g, laws.kind, laws.column, laws.n
    x = np.array(x0, dtype=float)
    residual, jacobian, _ = system(J, b, mu, g, x, kind, column, n)
    cost = float(residual @ residual)
    evaluations, damping, growth, converged = 1, FIRST_DAMPING, 2.0, 0
    while evaluations < max_evaluations and damping < MOST_DAMPING:
        if float(np.max(np.abs(residual))) <= tolerance:
            converged += 1
            if converged > POLISH_STEPS:
                break
        step, predicted, solved = damped_step(jacobian, residual, damping)
        if not solved:
            damping, growth = damping * growth, 2.0 * growth
            continue
        new_residual, new_jacobian, _ = system(J, b, mu, g, x + step, kind, column, n)
        evaluations += 1
        new_cost = float(new_residual @ new_residual)
        gain = (cost - new_cost) / predicted if predicted > 0.0 and np.isfinite(new_cost) else -1.0
        if gain > 0.0:
            x, residual, jacobian, cost = x + step, new_residual, new_jacobian, new_cost
            damping *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
            growth = 2.0
        elif converged:
            break  # within the tolerance, and no step lowers the residual further: machine precision
        else:
            damping, growth = damping * growth, 2.0 * growth
    return EquationFit(x, float(np.max(np.abs(residual))), evaluations)
