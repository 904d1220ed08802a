"""Force distributions consistent with a given motion (statically indeterminate grasps).

With the twist fixed, every contact's velocity is known, and the laws on the
forces are linear: an opening contact carries nothing, a sliding one pushes
on the maximum-dissipation face of its friction polygon, a rolling one
anywhere in its polygon. The set is convex; we report each normal force's
range over it when it is not a single point.
"""

from __future__ import annotations

import numpy as np

from ..problem import Problem
from .base import ZERO, ranges_are_wide, value_ranges

__all__ = ["force_ranges"]


def force_ranges(problem: Problem, edges: np.ndarray, q: np.ndarray) -> list[tuple[float, float | None]] | None:
    """Normal-force ranges (scene-relative) over all forces consistent with twist ``q``.

    Returns None when the forces are unique.
    """
    m, K = edges.shape[:2]
    n = problem.n_dof
    u = np.einsum("mdn,n->md", problem.J, q) - problem.b
    u_n, u_t = u[:, -1], u[:, :-1]
    drive = -np.einsum("mkt,mt->mk", edges, u_t)  # dissipation rate per unit edge force
    best = drive.max(axis=1)
    sliding = best > ZERO * 10
    cols = m + m * K + m  # cn, beta, slack of the friction bound
    JD = np.einsum("mkt,mtn->mkn", edges, problem.Jt).reshape(m * K, n)
    rows = [np.hstack([problem.Jn.T, JD.T, np.zeros((n, m))])]
    rhs = [-problem.g]
    bound = np.hstack([np.diag(problem.mu), -np.repeat(np.eye(m), K, axis=1), -np.eye(m)])
    rows.append(bound)
    rhs.append(np.zeros(m))
    zero = np.zeros(cols, dtype=bool)
    zero[:m] = u_n > ZERO * 10  # opening contacts carry no force
    zero[m : m + m * K] = (drive < best[:, None] - ZERO * 10).ravel()  # only maximising edges
    zero[m + m * K :] = sliding  # sliding: on the boundary of the polygon
    zero[m : m + m * K] |= np.repeat(problem.mu <= 0, K)
    rows.append(np.eye(cols)[zero])
    rhs.append(np.zeros(int(zero.sum())))
    A = np.vstack(rows)
    b = np.concatenate(rhs)
    free = ~zero
    if np.linalg.matrix_rank(A[:, free], tol=1e-10) == int(free.sum()):
        return None
    targets = np.eye(cols)[:m]
    ranges = value_ranges(A, b, targets, np.zeros(cols))
    return ranges if ranges_are_wide(ranges) else None
