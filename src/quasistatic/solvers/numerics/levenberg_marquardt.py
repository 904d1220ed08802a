"""Levenberg-Marquardt on small smooth equations whose residual and Jacobian come in one call.

The exact-cone refinement solves the fixed-mode laws (10-30 unknowns) from a pyramid motion. SciPy's
``least_squares`` costs ~0.2-0.3 ms of Python per evaluation there, where the laws themselves are compiled and
cost microseconds; this loop costs one small linear solve per step, so a refinement takes a few milliseconds
(docs/performance.md). It is a local method, as SciPy's is: it finds a zero near the start or stalls; the caller
checks what it returns.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

__all__ = ["EquationFit", "levenberg_marquardt"]

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
