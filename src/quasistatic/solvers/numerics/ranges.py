"""Extents of polyhedra by LPs: twist extremes of a continuum, ranges of linear functions, trivial cones.

Everything here is scene-relative, so absolute thresholds (from
:mod:`quasistatic.tolerances`) mean the same in every scene.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ...errors import SolverError
from ...tolerances import AT_LOWER_BOUND, FORCE_RANK, LP_FEASIBILITY, MOTION_RANK, SAME_TWIST
from ..result import Range
from .highs import INF, WarmLP, optimise_each, solve_lp
from .rank import DENSE_MAX, full_column_rank

__all__ = [
    "null_space",
    "cone_is_trivial",
    "polyhedron_extremes",
    "twist_extremes",
    "value_ranges",
    "ranges_are_wide",
    "linear_ranges",
    "rows_feasible",
    "in_row_space",
    "rows_in_row_space",
]

Bounds = tuple[float | None, float | None]


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
    if n > DENSE_MAX:
        return _large_cone_is_trivial(equalities, inequalities)
    basis = null_space(equalities) if equalities.shape[0] else np.eye(n)
    if basis.shape[1] == 0:
        return True
    A = inequalities @ basis
    if A.shape[0] == 0 or null_space(A).shape[1] > 0:
        return False
    lp = solve_lp(A.sum(axis=0), A, np.zeros(A.shape[0]), np.ones(A.shape[0]), maximize=True)
    return lp.status == "optimal" and lp.objective <= LP_FEASIBILITY


def _large_cone_is_trivial(E: np.ndarray, I: np.ndarray) -> bool:  # noqa: E741 - the names of the docstring
    """:func:`cone_is_trivial` without a null-space basis (a dense SVD of a matrix as large as the scene).

    The cone is the origin iff (a) ``[E; I]`` has full column rank (else a
    nonzero ``d`` has ``E d = 0 = I d``) and (b) no ``d`` in it has ``I d != 0``,
    i.e. ``max sum(I d)`` over ``E d = 0, 0 <= I d <= 1`` is 0: given (a), a
    nonzero ``d`` in the cone has ``I d >= 0`` and ``I d != 0``, so a multiple
    of it scores above 0, and (a) keeps that LP's feasible set bounded.
    """
    stacked = sp.vstack([sp.csr_matrix(E), sp.csr_matrix(I)], format="csr")
    if not full_column_rank(stacked, MOTION_RANK):
        return False
    if I.shape[0] == 0:
        return True
    e, i = E.shape[0], I.shape[0]
    lower, upper = np.zeros(e + i), np.r_[np.zeros(e), np.ones(i)]
    lp = solve_lp(np.asarray(I.sum(axis=0)).ravel(), stacked, lower, upper, maximize=True)
    return lp.status == "optimal" and lp.objective <= LP_FEASIBILITY


def twist_extremes(
    n_twist: int,
    A_eq: np.ndarray,
    b_eq: np.ndarray,
    A_in: np.ndarray,
    b_in: np.ndarray,
    col_lower: np.ndarray | None = None,
) -> tuple[list[np.ndarray], tuple[int, ...]]:
    """Extreme points of a polyhedron along each of its first ``n_twist`` coordinates (those coordinates only).

    See :func:`polyhedron_extremes`.
    """
    points, free = polyhedron_extremes(n_twist, A_eq, b_eq, A_in, b_in, col_lower)
    return [x[:n_twist] for x in points], free


def polyhedron_extremes(
    n_twist: int,
    A_eq: np.ndarray,
    b_eq: np.ndarray,
    A_in: np.ndarray,
    b_in: np.ndarray,
    col_lower: np.ndarray | None = None,
) -> tuple[list[np.ndarray], tuple[int, ...]]:
    """Extreme points of a polyhedron along each of its first ``n_twist`` coordinates, as whole points.

    Polyhedron: ``A_eq x = b_eq, A_in x >= b_in`` (columns free unless
    ``col_lower``). Returns the points (every coordinate: a twist's forces with it) of the distinct finite
    extremes of the first ``n_twist`` coordinates, and the directions along which that projection is
    unbounded: ``+(j + 1)`` for coordinate ``j`` growing without bound, ``-(j + 1)`` for it falling without bound.
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
            if not any(np.max(np.abs(lp.x[:n_twist] - p[:n_twist])) <= SAME_TWIST for p in points):
                points.append(lp.x)
        elif lp.status == "unbounded":  # minimising sign * x_j is unbounded: x_j runs to -sign infinity
            free.append(-sign * (j + 1))
        else:  # no answer is not an unbounded direction (it once made a bogus continuum free in every direction)
            raise SolverError("highs", f"the extent of a polyhedron along twist entry {j} could not be measured (LP {lp.status})")
    return points, tuple(free)


def value_ranges(A_eq: np.ndarray | sp.spmatrix, b_eq: np.ndarray, columns: np.ndarray, col_lower: np.ndarray) -> list[Range]:
    """Range of each coordinate ``x[j]``, ``j`` in ``columns``, over ``{A_eq x = b_eq, x >= col_lower}``.

    Two LPs per coordinate at most, fewer where the answer is known without
    one: a coordinate whose unit vector lies in the row space of ``A_eq`` is
    constant on the set (its value at any point), and a coordinate already
    seen at its lower bound at an optimal vertex of an earlier LP has that
    bound as its minimum. In a large statically indeterminate set most
    minima are found this way.
    """
    model = WarmLP(A_eq, b_eq, b_eq, col_lower)
    constant = in_row_space(A_eq, columns)
    at_bound = np.zeros(A_eq.shape[1], dtype=bool)  # coordinates seen at their lower bound
    ranges: list[Range] = []
    for j, fixed in zip(columns.tolist(), constant.tolist(), strict=True):
        target = np.zeros(A_eq.shape[1])
        target[j] = 1.0
        if at_bound[j]:
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


def linear_ranges(A_eq: sp.spmatrix, b_eq: np.ndarray, objectives: np.ndarray, col_lower: np.ndarray) -> list[Bounds]:
    """Range of each ``objectives[r] . x`` over ``{A_eq x = b_eq, x >= col_lower}`` (None for an unbounded side).

    Each objective is divided by its largest entry for the LP, so HiGHS's
    absolute tolerances see a scene-relative problem whatever its units, and
    the optimum is scaled back. The set must not be empty (it holds the motion's forces).
    """
    objectives = np.atleast_2d(objectives)
    model = WarmLP(A_eq, b_eq, b_eq, col_lower)
    ranges: list[Bounds] = []
    for row in objectives:
        scale = float(np.max(np.abs(row), initial=0.0))
        if scale == 0.0:  # a quantity no force reaches (a joint that moves no contact point)
            ranges.append((0.0, 0.0))
            continue
        low, high = (model.optimise(row / scale, maximize=maximize) for maximize in (False, True))
        ranges.append(
            (low.objective * scale if low.status == "optimal" else None, high.objective * scale if high.status == "optimal" else None)
        )
    return ranges


def rows_feasible(
    A_eq: sp.spmatrix, b_eq: np.ndarray, rows: np.ndarray, lower: np.ndarray, upper: np.ndarray, col_lower: np.ndarray
) -> bool:
    """Whether some ``x >= col_lower`` with ``A_eq x = b_eq`` has ``lower <= rows x <= upper`` (each row scaled as in
    :func:`linear_ranges`; a bound within :data:`LP_FEASIBILITY` of that row's scale is met)."""
    scale = np.max(np.abs(rows), axis=1, initial=0.0)
    reached = scale > 0.0
    if np.any(~reached & ((lower > 0.0) | (upper < 0.0))):
        return False  # a row no force reaches is 0, outside its bounds
    rows, scale = rows[reached], scale[reached]
    A = sp.vstack([sp.csr_matrix(A_eq), sp.csr_matrix(rows / scale[:, None])], format="csr")
    row_lower = np.r_[b_eq, lower[reached] / scale - LP_FEASIBILITY]
    row_upper = np.r_[b_eq, upper[reached] / scale + LP_FEASIBILITY]
    return solve_lp(np.zeros(A.shape[1]), A, row_lower, row_upper, col_lower).status == "optimal"


def in_row_space(A: np.ndarray | sp.spmatrix, columns: np.ndarray) -> np.ndarray:
    """Which coordinates ``x[j]`` are combinations of A's rows (constant wherever ``A x`` is fixed).

    Only worked out when A's smaller side is small (a thin SVD); on a large
    matrix every coordinate is taken as variable, which costs one more LP
    each and never a wrong range.
    """
    units = np.zeros((columns.size, A.shape[1]))
    units[np.arange(columns.size), columns] = 1.0
    return rows_in_row_space(A, units)


def rows_in_row_space(A: np.ndarray | sp.spmatrix, rows: np.ndarray) -> np.ndarray:
    """Which functionals ``rows[r] . x`` are combinations of A's rows (constant wherever ``A x`` is fixed).

    Each row is judged at unit length (a zero row is constant); large matrices as in :func:`in_row_space`.
    """
    if min(A.shape) == 0 or min(A.shape) > DENSE_MAX:
        return np.zeros(rows.shape[0], dtype=bool)
    dense = _dense(A)
    _, sigma, vt = np.linalg.svd(dense, full_matrices=False)
    basis = vt[sigma > FORCE_RANK * max(1.0, float(sigma[0]))]
    lengths = np.linalg.norm(rows, axis=1)
    units = rows[lengths > 0.0] / lengths[lengths > 0.0, None]
    # |f - P f| with P the projector on the row space, formed directly: as 1 - |P f|^2 its round-off
    # (1e-16) would reach 1e-8 under the square root, above the threshold, and no row would ever be in it.
    outside = units - (units @ basis.T) @ basis
    inside = np.ones(rows.shape[0], dtype=bool)
    inside[lengths > 0.0] = np.linalg.norm(outside, axis=1) <= MOTION_RANK
    return inside


def ranges_are_wide(ranges: list[Range], tol: float = LP_FEASIBILITY) -> bool:
    """True when some range is unbounded or wider than ``tol`` (scene-relative)."""
    return any(hi is None or hi - lo > tol for lo, hi in ranges)


def _dense(A: np.ndarray | sp.spmatrix) -> np.ndarray:
    return np.asarray(A.toarray() if isinstance(A, sp.spmatrix | sp.sparray) else A, dtype=float)
