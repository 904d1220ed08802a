"""Certified verdicts when no motion exists: ``jammed`` or ``unstable``, in that order.

1. No twist keeps every contact closed or opening for the commanded mover
   motion (``Jn q >= bn`` infeasible): jammed, with a Farkas certificate.
2. No force distribution inside the friction cones balances the load:
   unstable (no quasi-static equilibrium even with the movers stopped).
3. Otherwise the commanded motion wedges the parts: jammed.
"""

from __future__ import annotations

import numpy as np

from ..problem import Problem
from .base import BackendResult
from .highs import solve_lp

__all__ = ["diagnose", "equilibrium_exists", "kinematic_certificate", "CERTIFICATE_TOL"]

CERTIFICATE_TOL = 1e-7  # HiGHS meets constraints to 1e-7; a certificate is checked to the same

JAMMED_KINEMATIC = (
    "jammed: no motion of the free bodies is compatible with the commanded mover motion "
    "(the movers would have to penetrate them); change the commanded motion"
)
JAMMED_WEDGED = (
    "jammed: the parts could be held at rest, but friction wedges them against the commanded "
    "motion (no solution with finite forces); change the commanded motion or reduce friction"
)
UNSTABLE = (
    "unstable: no quasi-static equilibrium exists within the friction cones, so the object "
    "falls, slides or accelerates; add support or friction"
)


def kinematic_certificate(problem: Problem) -> np.ndarray | None:
    """Multipliers y >= 0 with Jn^T y = 0, bn.y = 1 (proof of infeasibility), or None."""
    Jn, bn = problem.Jn, problem.bn
    m, n = Jn.shape
    A = np.vstack([Jn.T, bn[None, :]])
    rhs = np.r_[np.zeros(n), 1.0]
    lp = solve_lp(np.zeros(m), A, rhs, rhs, np.zeros(m))
    if lp.status == "optimal" and np.max(np.abs(A @ lp.x - rhs), initial=0.0) <= CERTIFICATE_TOL:
        return lp.x
    return None


def equilibrium_exists(problem: Problem, edges: np.ndarray) -> bool:
    """True when some forces in the (polyhedral) cones balance the load.

    Variables ``cn >= 0`` and edge intensities ``beta >= 0`` with
    ``sum beta <= mu cn`` per contact.
    """
    m, K = edges.shape[:2]
    n = problem.n_dof
    JD = np.einsum("mkt,mtn->mkn", edges, problem.Jt).reshape(m * K, n)
    cols = m + m * K + m  # cn, beta, slack of the friction bound
    A = np.zeros((n + m, cols))
    A[:n, :m] = problem.Jn.T
    A[:n, m : m + m * K] = JD.T
    A[n:, :m] = np.diag(problem.mu)
    A[n:, m : m + m * K] = -np.repeat(np.eye(m), K, axis=1)
    A[n:, m + m * K :] = -np.eye(m)
    rhs = np.r_[-problem.g, np.zeros(m)]
    lp = solve_lp(np.zeros(cols), A, rhs, rhs, np.zeros(cols))
    return lp.status == "optimal"


def diagnose(problem: Problem, inner_edges: np.ndarray, outer_edges: np.ndarray | None = None) -> BackendResult:
    """Explain why no motion exists. ``inner_edges`` span cones inside the true ones.

    For the exact 3-D cone pass ``outer_edges`` too (a polygon around the circle):
    no equilibrium with the outer cones proves none with the exact ones.
    """
    certificate = kinematic_certificate(problem)
    if certificate is not None:
        return BackendResult("jammed", JAMMED_KINEMATIC, details={"certificate": "kinematic (Farkas multipliers)"})
    if equilibrium_exists(problem, inner_edges):
        return BackendResult("jammed", JAMMED_WEDGED, details={"certificate": "equilibrium exists; no motion found by the complete search"})
    if outer_edges is None or not equilibrium_exists(problem, outer_edges):
        return BackendResult("unstable", UNSTABLE, details={"certificate": "no equilibrium in the friction cones (LP infeasible)"})
    return BackendResult(
        "failed",
        "failed: no motion was found, and whether the exact cones admit an equilibrium is too close to call",
    )


