"""Frictionless forward object motion problem: one LP through HiGHS (paper section 2.2).

Velocity formulation (eq. 25, 7):  min -g.q  s.t.  Jn q >= bn.
Its duals are the normal forces; the dual LP is the force formulation
(eq. 12, 26, 27):  max bn.c  s.t.  Jn^T c + g = 0, c >= 0, and strong
duality is the power balance (eq. 19): mover power = potential-energy gain.
"""

from __future__ import annotations

import numpy as np

from ..evaluate import RawMotion
from ..problem import Problem
from .base import ZERO, BackendResult, Options, cone_is_trivial, ranges_are_wide, twist_extremes, value_ranges
from .diagnose import CERTIFICATE_TOL, kinematic_certificate
from .highs import INF, solve_lp

__all__ = ["solve_frictionless", "JAMMED_MESSAGE", "UNSTABLE_MESSAGE"]


JAMMED_MESSAGE = (
    "jammed: no motion of the free bodies is compatible with the commanded mover motion "
    "(the movers would have to penetrate them); change the commanded motion"
)
UNSTABLE_MESSAGE = (
    "unstable: no quasi-static equilibrium exists (the load can do unbounded work), so the "
    "object falls or accelerates; add support or friction"
)


def solve_frictionless(problem: Problem, options: Options) -> BackendResult:
    """Solve with every contact frictionless (mu ignored)."""
    Jn, bn, g = problem.Jn, problem.bn, problem.g
    m = problem.n_contacts
    lp = solve_lp(-g, Jn, bn, np.full(m, INF))
    if lp.status != "optimal":
        return _verdict(problem, lp.status)
    q, forces = lp.x, np.maximum(lp.row_dual, 0.0)
    c = np.zeros((m, problem.dimension))
    c[:, -1] = forces
    slack = Jn @ q - bn
    support = forces > ZERO
    tight = (slack <= ZERO) & ~support
    if not cone_is_trivial(Jn[support], Jn[tight]):
        extremes, unbounded = twist_extremes(q.size, Jn[support], bn[support], Jn[~support], bn[~support])
        motion = RawMotion(q, c, tuple(extremes), unbounded)
        return BackendResult("ambiguous", _ambiguous_message(unbounded), (motion,))
    ranges = _force_ranges(Jn, g, slack)
    if ranges is not None:
        return BackendResult("solved", "solved: one motion; the contact forces are indeterminate", (RawMotion(q, c),), ranges)
    return BackendResult("solved", "solved: one motion with unique contact forces", (RawMotion(q, c),))


def _force_ranges(Jn: np.ndarray, g: np.ndarray, slack: np.ndarray) -> list[tuple[float, float | None]] | None:
    """Normal-force ranges over the dual optimal face, or None when the forces are unique.

    Only closed contacts (zero slack) may carry force on that face.
    """
    closed = slack <= ZERO
    k = int(closed.sum())
    if np.linalg.matrix_rank(Jn[closed], tol=1e-10) == k:
        return None
    closed_ranges = iter(value_ranges(Jn[closed].T, -g, np.eye(k), np.zeros(k)))
    ranges = [next(closed_ranges) if is_closed else (0.0, 0.0) for is_closed in closed]
    return ranges if ranges_are_wide(ranges) else None


def _verdict(problem: Problem, status: str) -> BackendResult:
    """Jammed or unstable, each confirmed by a checked certificate."""
    Jn, g = problem.Jn, problem.g
    m, n = Jn.shape
    multipliers = kinematic_certificate(problem)
    if multipliers is not None:
        return BackendResult("jammed", JAMMED_MESSAGE, details={"certificate": "farkas", "multipliers": multipliers.tolist()})
    # Unstable: a twist d with Jn d >= 0 and g.d > 0 does unbounded work; box |d| <= 1 keeps the LP bounded.
    ray = solve_lp(g, Jn, np.zeros(m), np.full(m, INF), np.full(n, -1.0), np.full(n, 1.0), maximize=True)
    if ray.status == "optimal" and ray.objective > CERTIFICATE_TOL and np.all(Jn @ ray.x >= -CERTIFICATE_TOL * ray.objective):
        direction = ray.x / ray.objective
        return BackendResult("unstable", UNSTABLE_MESSAGE, details={"certificate": "ray", "direction": direction.tolist()})
    return BackendResult("failed", f"failed: HiGHS reported {status} but no certificate could be checked")


def _ambiguous_message(unbounded: bool) -> str:
    extent = "unbounded" if unbounded else "bounded"
    return (
        f"ambiguous: an {extent} continuum of motions satisfies the laws "
        "(frictionless contacts leave it undetermined); its extreme motions are listed"
    )
