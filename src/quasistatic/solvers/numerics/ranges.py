"""Extents of polyhedra by LPs: twist extremes of a continuum, ranges of linear functions, trivial cones.

Everything here is scene-relative, so absolute thresholds (from
:mod:`quasistatic.tolerances`) mean the same in every scene.
"""

from __future__ import annotations

import numpy as np

from ...tolerances import AT_LOWER_BOUND, FORCE_RANK, LP_FEASIBILITY, MOTION_RANK, SAME_TWIST
from ..result import Range
from .highs import INF, WarmLP, optimise_each, solve_lp

__all__ = ["null_space", "cone_is_trivial", "twist_extremes", "value_ranges", "ranges_are_wide"]


def null_space(A: np.ndarray, tol: float = MOTION_RANK) -> np.ndarray:
    """Orthonormal basis of the null space of A, singular values below ``tol`` counted as zero.

    The threshold is absolute: the matrices are scene-relative, so 1e-9 means
    "zero" whatever the scene's units (scipy's default is relative to the
    largest singular value, which calls a 1x1 matrix of 1e-17 full rank).
    """
    if A.shape[0] == 0:
        return np.eye(A.shape[1])
    _, sigma, vt = np.linalg.svd(A)
    rank = int(np.sum(sigma > tol))
    return vt[rank:].T


def cone_is_trivial(equalities: np.ndarray, inequalities: np.ndarray) -> bool:
    """True when ``{d : E d = 0, I d >= 0}`` is only the origin."""
    n = equalities.shape[1] if equalities.size else inequalities.shape[1]
    basis = null_space(equalities) if equalities.shape[0] else np.eye(n)
    if basis.shape[1] == 0:
        return True
    A = inequalities @ basis
    if A.shape[0] == 0 or null_space(A).shape[1] > 0:
        return False
    lp = solve_lp(A.sum(axis=0), A, np.zeros(A.shape[0]), np.ones(A.shape[0]), maximize=True)
    return lp.status == "optimal" and lp.objective <= LP_FEASIBILITY


def twist_extremes(
    n_twist: int,
    A_eq: np.ndarray,
    b_eq: np.ndarray,
    A_in: np.ndarray,
    b_in: np.ndarray,
    col_lower: np.ndarray | None = None,
) -> tuple[list[np.ndarray], tuple[int, ...]]:
    """Extreme points of a polyhedron along each of its first ``n_twist`` coordinates.

    Polyhedron: ``A_eq x = b_eq, A_in x >= b_in`` (columns free unless
    ``col_lower``). Returns the distinct finite extremes and the directions
    along which the twist projection is unbounded: ``+(j + 1)`` for coordinate
    ``j`` growing without bound, ``-(j + 1)`` for it falling without bound.
    """
    A = np.vstack([A_eq, A_in])
    lower = np.r_[b_eq, b_in]
    upper = np.r_[b_eq, np.full(b_in.size, INF)]
    points: list[np.ndarray] = []
    free: list[int] = []
    axes = [(j, sign) for j in range(n_twist) for sign in (1, -1)]
    objectives = [(sign * np.eye(1, A.shape[1], j)[0], False) for j, sign in axes]
    for (j, sign), lp in zip(axes, optimise_each(objectives, A, lower, upper, col_lower), strict=True):
        if lp.status == "optimal":
            q = lp.x[:n_twist]
            if not any(np.max(np.abs(q - p)) <= SAME_TWIST for p in points):
                points.append(q)
        else:  # minimising sign * x_j is unbounded: x_j runs to -sign infinity
            free.append(-sign * (j + 1))
    return points, tuple(free)


def value_ranges(A_eq: np.ndarray, b_eq: np.ndarray, targets: np.ndarray, col_lower: np.ndarray) -> list[Range]:
    """Range of each linear function ``targets[i] . x`` over ``{A_eq x = b_eq, x >= col_lower}``.

    Two LPs per target at most, fewer where the answer is known without one:
    a target in the row space of ``A_eq`` is constant on the set (its value at
    any point), and a single coordinate already seen at its lower bound at
    an optimal vertex of an earlier LP has that bound as its minimum. In a
    large statically indeterminate set most minima are found this way.
    """
    model = WarmLP(A_eq, b_eq, b_eq, col_lower)
    constant = _in_row_space(A_eq, targets)
    coordinate = [_unit_index(t) for t in targets]
    at_bound = np.zeros(A_eq.shape[1], dtype=bool)  # coordinates seen at their lower bound
    ranges: list[Range] = []
    for target, fixed, j in zip(targets, constant, coordinate, strict=True):
        if j >= 0 and at_bound[j]:
            low: float | None = float(col_lower[j])
        else:
            result = model.optimise(target)
            low = result.objective if result.status == "optimal" else None
            if result.status == "optimal":
                at_bound |= result.x <= col_lower + AT_LOWER_BOUND
        if fixed and low is not None:
            ranges.append((max(low, 0.0), low))
            continue
        result = model.optimise(target, maximize=True)
        if result.status == "optimal":
            at_bound |= result.x <= col_lower + AT_LOWER_BOUND
        ranges.append((max(low or 0.0, 0.0), result.objective if result.status == "optimal" else None))
    return ranges


def _unit_index(target: np.ndarray) -> int:
    """``j`` when ``target`` is the unit vector e_j (the target is one coordinate), else -1."""
    nonzero = np.flatnonzero(target)
    return int(nonzero[0]) if nonzero.size == 1 and target[nonzero[0]] == 1.0 else -1


def _in_row_space(A: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Which targets are combinations of A's rows (constant wherever ``A x`` is fixed)."""
    if A.size == 0:
        return np.all(targets == 0.0, axis=1)
    _, sigma, vt = np.linalg.svd(A, full_matrices=False)
    basis = vt[sigma > FORCE_RANK * max(1.0, float(sigma[0]))]
    residual = targets - (targets @ basis.T) @ basis
    return np.linalg.norm(residual, axis=1) <= MOTION_RANK * np.maximum(1.0, np.linalg.norm(targets, axis=1))


def ranges_are_wide(ranges: list[Range], tol: float = LP_FEASIBILITY) -> bool:
    """True when some range is unbounded or wider than ``tol`` (scene-relative)."""
    return any(hi is None or hi - lo > tol for lo, hi in ranges)
