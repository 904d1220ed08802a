"""A proof that exact 3-D friction cones admit no motion: infeasibility of a sector relaxation of the exact laws.

A pyramid that jams proves nothing about the circle: its maximum-dissipation
force for a slip between two edges is not opposite the slip. This module
checks a relaxation that every exact solution satisfies. Split each
contact's tangent plane into sectors (each narrower than a half-turn). An
exact solution's contact either rolls (no slip, force inside the cone) or
its slip ``u`` lies in some sector, and then its friction force ``-p = -mu cn
u/|u|`` lies on the cone's circle opposite it: ``p`` inside the same sector,
beyond the chord of the sector's arc (``p.mid >= mu cn cos(width/2)``) and
inside the circle's tangents at the arc's ends and middle. A separating
contact carries no force, which every sector allows. Non-penetration,
equilibrium and ``cn _|_ un`` are kept exactly.

Each piece is a polyhedral cone in ``(u, p, cn)``, so "one of them" is
written as their convex hull (the contact's ``(u, p, cn)`` is a sum of one
part per cone) with an SOS1 constraint: at most one part is nonzero. The LP
relaxation is then the hull itself, and no bound on a twist or a force is
assumed (no big-M).

If SCIP proves the relaxation infeasible, the exact laws have no solution
(with the prescribed modes, if any) for the commanded motion, with any finite
forces: a certificate. If it finds a point, the sectors its sliding contacts
use are halved and it tries again (the relaxation tightens only where a
point escaped), until a sector would be narrower than ``FINEST`` or the time
runs out: then nothing is decided.

Without prescribed modes the same relaxation is first decided by the mode
branch and bound (:func:`~.patterns.relaxation_excluded`): "one piece per
contact" is a choice of mode (separating, rolling, sliding in one sector), and
with the modes fixed the twist's rows and the forces' cone share no unknown,
so every pattern is excluded by a checked Farkas vector, by its twist rows
(loosened by ``LP_FEASIBILITY``, as SCIP's) or by an LP; the forces each
piece allows are the same polygon's (chord, tangents, the rolling 16-gon).
A closed tree proves the relaxation infeasible, as SCIP would. A pattern that
survives halves its sliding contacts' sectors, as SCIP's point does, for at
most :data:`BRANCH_AND_BOUND_ROUNDS` rounds; where it gives no answer (a
node budget, an LP without a status, no sector left to halve) the SCIP loop
goes on from the sectors reached. A surviving pattern's twist that is an
exact motion (``is_motion``) stops both, as a SCIP point's does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ...laws import Problem
from ...solution import Mode
from ...tolerances import EXACT_SECTOR_FRICTION, MODE_SPEED, SECTOR_ACTIVE
from ..numerics.scip_model import linear, new_model, optimize
from ..result import Options
from .patterns import ROLLING_POLYGON, relaxation_excluded

__all__ = ["exact_cones_jam", "split_sectors", "SECTORS", "FINEST", "BRANCH_AND_BOUND_ROUNDS", "BY_BRANCH_AND_BOUND", "BY_SCIP"]

SECTORS = 8  # initial slip sectors per contact
FINEST = 2.0 * np.pi / 256  # narrowest sector [rad] the refinement makes
BRANCH_AND_BOUND_ROUNDS = 24  # refinements decided by the mode branch and bound before SCIP's loop goes on
BY_BRANCH_AND_BOUND = "mode branch and bound, Farkas vectors and LPs"  # what decided a proof, for its certificate
BY_SCIP = "SCIP, complete search"


def exact_cones_jam(
    problem: Problem,
    options: Options,
    modes: Sequence[Mode | None] | None = None,
    is_motion: Callable[[np.ndarray], bool] | None = None,
) -> tuple[bool, int, str]:
    """Whether the sector relaxation was proven infeasible (the exact cones admit no motion), the most sectors
    used, and what decided it (:data:`BY_BRANCH_AND_BOUND` or :data:`BY_SCIP`).

    With ``modes`` (prescribed per contact, None free) the relaxation keeps
    them: True then proves that no exact motion has those modes. ``is_motion``
    (optional) says whether a relaxed point's twist is an exact motion: then
    the refinement stops early, since nothing is left to prove.
    """
    sectors = [2.0 * np.pi * np.arange(SECTORS + 1) / SECTORS for _ in range(problem.n_contacts)]
    if modes is None:
        decided = _by_branch_and_bound(problem, options, sectors, is_motion)
        if decided is not None:
            return decided, max(len(s) - 1 for s in sectors), BY_BRANCH_AND_BOUND
    while options.remaining() > 0.0:
        status, active, q = _relaxation(problem, options, sectors, modes)
        if status == "infeasible":
            return True, max(len(s) - 1 for s in sectors), BY_SCIP
        if status != "feasible" or (is_motion is not None and is_motion(q)) or not split_sectors(sectors, active):
            break  # out of time, or the point already satisfies the exact laws' friction: a motion is likely
    return False, max(len(s) - 1 for s in sectors), BY_SCIP


def _by_branch_and_bound(
    problem: Problem, options: Options, sectors: list[np.ndarray], is_motion: Callable[[np.ndarray], bool] | None
) -> bool | None:
    """The relaxation decided by the mode branch and bound, refining ``sectors`` in place: True, infeasible
    (proven); False, a surviving pattern's twist is an exact motion; None, no answer (SCIP's loop goes on)."""
    passed = None  # what the rounds before excluded: the next resumes where the last stopped
    for _ in range(BRANCH_AND_BOUND_ROUNDS):
        if options.remaining() <= 0.0:
            return None
        proof = relaxation_excluded(problem, sectors, options.remaining, passed=passed)
        passed = proof.passed
        if proof.excluded:
            return True
        if proof.sectors is None or proof.q is None:
            return None
        if is_motion is not None and is_motion(proof.q):
            return False
        if not split_sectors(sectors, proof.sectors):
            return None
    return None


def split_sectors(sectors: list[np.ndarray], active: Sequence[int], finest: float = FINEST) -> bool:
    """Halve each sector a relaxed point slides in (``active``: per contact its sector, negative for none), in
    place; False when each is already narrower than twice ``finest``."""
    changed = False
    for i, k in enumerate(active):
        if k < 0:
            continue
        lo, hi = sectors[i][k], sectors[i][k + 1]
        if hi - lo > 2.0 * finest:
            sectors[i] = np.insert(sectors[i], k + 1, 0.5 * (lo + hi))
            changed = True
    return changed


def _relaxation(
    problem: Problem, options: Options, sectors: list[np.ndarray], modes: Sequence[Mode | None] | None
) -> tuple[str, list[int], np.ndarray]:
    """Solve the relaxation: its status, per contact the sector its point slides in (-1: none or exact), its twist."""
    scip = new_model(options.remaining())
    n = problem.n_dof
    q = [scip.addVar(lb=None, ub=None, name=f"q{j}") for j in range(n)]
    push: list[Any] = [float(problem.g[j]) for j in range(n)]  # sum_i J_i^T c_i + g
    parts = []  # per contact, per sector: (size, [cn], u, p) variables
    for i in range(problem.n_contacts):
        cn = scip.addVar(lb=0.0, ub=None, name=f"cn{i}")
        mode = None if modes is None else modes[i]
        lower, upper = (MODE_SPEED, None) if mode == "separating" else (0.0, None if mode is None else 0.0)
        opening = scip.addVar(lb=lower, ub=upper, name=f"un{i}")
        scip.addCons(linear(problem.Jn[i], q) - opening == float(problem.bn[i]))
        scip.addConsSOS1([cn, opening])
        slip = [linear(problem.Jt[i, t], q) - float(problem.bt[i, t]) for t in range(2)]
        p, contact_parts = _friction(scip, float(problem.mu[i]), cn, slip, str(i), sectors[i], mode)
        parts.append(contact_parts)
        for j in range(n):
            push[j] = push[j] + float(problem.Jn[i, j]) * cn - float(problem.Jt[i, 0, j]) * p[0] - float(problem.Jt[i, 1, j]) * p[1]
    for j in range(n):
        scip.addCons(push[j] == 0.0)
    status = optimize(scip, "scip")
    if status == "infeasible":
        return "infeasible", [], np.zeros(n)
    if scip.getNSols() == 0:
        return "unknown", [], np.zeros(n)
    best = scip.getBestSol()
    active = []
    for mu, contact_parts in zip(problem.mu, parts, strict=True):
        values = np.array([scip.getSolVal(best, part[0]) for part in contact_parts])
        k = int(np.argmax(values)) if values.size and values.max() > SECTOR_ACTIVE else -1
        if k >= 0:
            cn_k, u_k, p_k = (np.array([scip.getSolVal(best, v) for v in group]) for group in contact_parts[k][1:])
            if _exact_friction(float(mu), float(cn_k[0]), u_k, p_k):
                k = -1
        active.append(k)
    return "feasible", active, np.array([scip.getSolVal(best, v) for v in q])


def _exact_friction(mu: float, cn: float, u: np.ndarray, p: np.ndarray) -> bool:
    """The relaxed point's friction is already the exact law's: ``p`` along the slip, on the circle (to 1e-6)."""
    speed, force = float(np.linalg.norm(u)), float(np.linalg.norm(p))
    if speed <= SECTOR_ACTIVE:
        return force <= mu * cn * (1.0 + EXACT_SECTOR_FRICTION)
    return bool(np.linalg.norm(p - mu * cn * u / speed) <= EXACT_SECTOR_FRICTION * max(mu * cn, SECTOR_ACTIVE))


def _friction(
    scip: Any, mu: float, cn: Any, slip: list[Any], name: str, bounds: np.ndarray, mode: Mode | None
) -> tuple[list[Any], list[tuple[Any, ...]]]:
    """``p = -c_t`` of contact ``name``: rolling, or sliding in one sector (hull of the cones with SOS1); and the sliding parts."""
    import pyscipopt

    if mode == "rolling":
        for t in range(2):
            scip.addCons(slip[t] == 0.0)
    if mu <= 0.0:
        return [0.0, 0.0], []
    # The rolling part: no slip, p inside the circle's tangents.
    cn_roll = scip.addVar(lb=0.0, ub=0.0 if mode == "sliding" else None, name=f"cn_roll{name}")
    p_roll = [scip.addVar(lb=None, ub=None, name=f"p_roll{name}_{t}") for t in range(2)]
    for angle in 2.0 * np.pi * np.arange(ROLLING_POLYGON) / ROLLING_POLYGON:
        scip.addCons(np.cos(angle) * p_roll[0] + np.sin(angle) * p_roll[1] <= mu * cn_roll)
    cn_parts, p_parts, u_parts, sizes, parts = [cn_roll], [p_roll], [], [], []
    for k in range(len(bounds) - 1 if mode != "rolling" else 0):
        lo, hi = bounds[k], bounds[k + 1]
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        cn_k = scip.addVar(lb=0.0, ub=None, name=f"cn{name}_{k}")
        u_k = [scip.addVar(lb=None, ub=None, name=f"u{name}_{k}_{t}") for t in range(2)]
        p_k = [scip.addVar(lb=None, ub=None, name=f"p{name}_{k}_{t}") for t in range(2)]
        for v in (u_k, p_k):  # inside the sector: cross(a_lo, v) >= 0, cross(v, a_hi) >= 0
            scip.addCons(np.cos(lo) * v[1] - np.sin(lo) * v[0] >= 0.0)
            scip.addCons(v[0] * np.sin(hi) - v[1] * np.cos(hi) >= 0.0)
        scip.addCons(np.cos(mid) * p_k[0] + np.sin(mid) * p_k[1] >= mu * np.cos(half) * cn_k)  # beyond the arc's chord
        for angle in (lo, mid, hi):  # inside the circle's tangents at the arc's ends and middle
            scip.addCons(np.cos(angle) * p_k[0] + np.sin(angle) * p_k[1] <= mu * cn_k)
        size = scip.addVar(lb=0.0, ub=None, name=f"size{name}_{k}")  # zero only when the part is
        scip.addCons(size == cn_k + np.cos(mid) * u_k[0] + np.sin(mid) * u_k[1])
        cn_parts.append(cn_k)
        p_parts.append(p_k)
        u_parts.append(u_k)
        sizes.append(size)
        parts.append((size, [cn_k], u_k, p_k))
    scip.addConsSOS1([cn_roll, *sizes])
    if mode == "sliding":  # |slip| > MODE_SPEED: its part along its sector's bisector exceeds that times cos(half)
        mids = 0.5 * (bounds[:-1] + bounds[1:])
        along = [np.cos(mid) * u[0] + np.sin(mid) * u[1] for mid, u in zip(mids, u_parts, strict=True)]
        scip.addCons(pyscipopt.quicksum(along) >= MODE_SPEED * np.cos(0.5 * np.max(np.diff(bounds))))
    scip.addCons(pyscipopt.quicksum(cn_parts) == cn)
    for t in range(2 if u_parts else 0):
        scip.addCons(pyscipopt.quicksum(u[t] for u in u_parts) == slip[t])
    return [pyscipopt.quicksum(p[t] for p in p_parts) for t in range(2)], parts
