"""A proof that exact 3-D friction cones wedge: infeasibility of a sector relaxation of the exact laws.

A pyramid that jams proves nothing about the circle: its maximum-dissipation
force for a slip between two edges is not opposite the slip. This module
checks a relaxation that every exact solution satisfies. Split the tangent
plane into ``SECTORS`` equal sectors. An exact solution's contact either
rolls (no slip, force inside the cone) or its slip ``u`` lies in some sector
and then its friction force ``-p = -mu cn u/|u|`` lies on the cone's circle
opposite it: ``p`` inside the sector too, with ``mu cn cos(pi/SECTORS) <=
p.mid <= mu cn`` (``mid`` the sector's bisector). A separating contact
carries no force, which every sector allows. Non-penetration, equilibrium and
``cn _|_ un`` are kept exactly.

Each of these pieces is a polyhedral cone in ``(u, p, cn)``, so "one of them"
is written as their convex hull (the contact's ``(u, p, cn)`` is a sum of one
part per cone) with an SOS1 constraint: at most one part is nonzero. The LP
relaxation is then the hull itself (tight), and no bound on a twist or a
force is assumed (no big-M).

If SCIP proves the relaxation infeasible, the exact laws have no solution
for the commanded motion with any finite forces: a certified wedge. If it
finds a point, nothing is decided (the relaxation is wider than the laws).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..evaluate import MODE_TOLERANCE
from ..problem import Problem
from ..solution import Mode
from .base import Options

__all__ = ["exact_cones_jam", "SECTORS"]

SECTORS = 16  # default number of slip sectors per contact


def exact_cones_jam(problem: Problem, options: Options, sectors: int = SECTORS, modes: Sequence[Mode | None] | None = None) -> bool:
    """True when the sector relaxation is proven infeasible (within the time left), so the exact cones jam.

    With ``modes`` (prescribed per contact, None free) the relaxation keeps them:
    True then proves that no exact motion has those modes.
    """
    import pyscipopt

    if options.remaining() <= 0.0:
        return False
    scip = pyscipopt.Model()
    scip.hideOutput()
    scip.setParam("display/verblevel", 0)
    scip.setParam("numerics/feastol", 1e-7)
    scip.setParam("limits/time", options.remaining())
    n = problem.n_dof
    q = [scip.addVar(lb=None, ub=None, name=f"q{j}") for j in range(n)]
    push: list[object] = [float(problem.g[j]) for j in range(n)]  # sum_i J_i^T c_i + g
    for i in range(problem.n_contacts):
        cn = scip.addVar(lb=0.0, ub=None, name=f"cn{i}")
        mode = None if modes is None else modes[i]
        lower, upper = (MODE_TOLERANCE, None) if mode == "separating" else (0.0, None if mode is None else 0.0)
        opening = scip.addVar(lb=lower, ub=upper, name=f"un{i}")
        scip.addCons(_dot(problem.Jn[i], q) - opening == float(problem.bn[i]))
        scip.addConsSOS1([cn, opening])
        slip = [_dot(problem.Jt[i, t], q) - float(problem.bt[i, t]) for t in range(2)]
        p = _friction(scip, float(problem.mu[i]), cn, slip, str(i), sectors, mode)
        for j in range(n):
            push[j] = push[j] + float(problem.Jn[i, j]) * cn - float(problem.Jt[i, 0, j]) * p[0] - float(problem.Jt[i, 1, j]) * p[1]
    for j in range(n):
        scip.addCons(push[j] == 0.0)
    scip.optimize()
    return bool(scip.getStatus() == "infeasible")


def _friction(scip: Any, mu: float, cn: Any, slip: list[Any], name: str, sectors: int, mode: Mode | None) -> list[Any]:
    """``p = -c_t`` of contact ``name``: rolling, or sliding in one of ``sectors`` sectors (hull of the cones with SOS1)."""
    import pyscipopt

    if mode == "rolling":
        for t in range(2):
            scip.addCons(slip[t] == 0.0)
    if mu <= 0.0:
        return [0.0, 0.0]
    bounds = 2.0 * np.pi * np.arange(sectors + 1) / sectors
    mids = bounds[:-1] + np.pi / sectors
    # The rolling part: no slip, p in the sectors-gon around the circle.
    cn_parts = [scip.addVar(lb=0.0, ub=0.0 if mode == "sliding" else None, name=f"cn_roll{name}")]
    p_parts = [[scip.addVar(lb=None, ub=None, name=f"p_roll{name}_{t}") for t in range(2)]]
    u_parts: list[list[Any]] = []
    for mid in mids:
        scip.addCons(np.cos(mid) * p_parts[0][0] + np.sin(mid) * p_parts[0][1] <= mu * cn_parts[0])
    sizes = [cn_parts[0]]
    for k in range(sectors if mode != "rolling" else 0):
        lo, hi, mid = bounds[k], bounds[k + 1], mids[k]
        cn_k = scip.addVar(lb=0.0, ub=None, name=f"cn{name}_{k}")
        u_k = [scip.addVar(lb=None, ub=None, name=f"u{name}_{k}_{t}") for t in range(2)]
        p_k = [scip.addVar(lb=None, ub=None, name=f"p{name}_{k}_{t}") for t in range(2)]
        for v in (u_k, p_k):  # inside the sector: cross(a_lo, v) >= 0, cross(v, a_hi) >= 0
            scip.addCons(np.cos(lo) * v[1] - np.sin(lo) * v[0] >= 0.0)
            scip.addCons(v[0] * np.sin(hi) - v[1] * np.cos(hi) >= 0.0)
        along = np.cos(mid) * p_k[0] + np.sin(mid) * p_k[1]
        scip.addCons(along >= mu * np.cos(np.pi / sectors) * cn_k)  # beyond the arc's chord
        scip.addCons(along <= mu * cn_k)  # inside the circumscribed polygon
        size = scip.addVar(lb=0.0, ub=None, name=f"size{name}_{k}")  # zero only when the part is
        scip.addCons(size == cn_k + np.cos(mid) * u_k[0] + np.sin(mid) * u_k[1])
        cn_parts.append(cn_k)
        p_parts.append(p_k)
        u_parts.append(u_k)
        sizes.append(size)
    scip.addConsSOS1(sizes)
    if mode == "sliding":  # |slip| > MODE_TOLERANCE, so its component along its sector's bisector exceeds that times cos
        scip.addCons(
            pyscipopt.quicksum(np.cos(m) * u[0] + np.sin(m) * u[1] for m, u in zip(mids, u_parts, strict=True))
            >= MODE_TOLERANCE * np.cos(np.pi / sectors)
        )
    scip.addCons(pyscipopt.quicksum(cn_parts) == cn)
    for t in range(2 if u_parts else 0):
        scip.addCons(pyscipopt.quicksum(u[t] for u in u_parts) == slip[t])
    return [pyscipopt.quicksum(p[t] for p in p_parts) for t in range(2)]


def _dot(row: np.ndarray, x: list) -> object:
    import pyscipopt

    return pyscipopt.quicksum(float(a) * v for a, v in zip(row, x, strict=True) if a != 0.0) + 0.0
