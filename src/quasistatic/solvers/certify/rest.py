"""Rest proven the only motion on the exact cones, when every mover is still.

The exact-cone search proves completeness for an inscribed pyramid only; for
the most common scene of all, parts at rest under gravity with the robot
holding still, a proof on the circle itself is cheap:

1. **The load cannot do positive work.** With every mover still (``b = 0``),
   any motion ``q`` with forces ``c`` satisfies, by equilibrium
   ``J^T c + g = 0``, normal complementarity and maximum dissipation::

       g . q = -c . (J q) = sum_i mu_i cn_i |u_t,i|  >= 0.

   If the LP ``max g . q  s.t.  Jn q >= 0`` (every admissible twist, no force
   involved) has value 0, then every motion has ``g . q = 0``, and so
   ``mu_i cn_i |u_t,i| = 0``: **a loaded contact neither opens nor slips**
   (frictionless ones may slip).
2. **No motion away from rest.** A motion ``q`` therefore has forces in the
   cones that balance the load using only contacts that are still under
   ``q``. A mixed-integer program asks for such ``(q, c)`` with ``q`` not
   rest, the cones replaced by the pyramid *circumscribed* about each circle
   (a superset of the exact forces).
   Every condition on ``q`` is homogeneous, so asking for ``|q_j| >= 1`` in
   some entry asks for any twist other than rest; SCIP proving the program
   infeasible proves that rest is the only motion.

Neither step uses anything the circle does not satisfy, so the proof holds
for the exact cones themselves; it says nothing when a mover moves, when the
load could descend (then step 1 fails and the pyramid search decides), or
when SCIP runs out of time.

Step 2 is first tried without SCIP (:mod:`.rest_lp`: which contacts can stay
still under a twist away from rest, by singular values, and a checked Farkas
twist showing that those cannot balance the load); SCIP runs where that does
not close. The Allegro grasp of the benchmark closes there (about 1 ms against
about 25 ms for the SCIP program).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...laws import Problem
from ...tolerances import ZERO
from ..numerics.highs import solve_lp
from ..numerics.scip_model import exclude_box, linear, new_model, optimize
from ..result import Options
from .rest_lp import rest_proven_by_lps

__all__ = ["rest_proof", "load_cannot_descend", "no_motion_away_from_rest", "REST_PROOF", "REST_PROOF_LP"]

_STEP_1 = "every mover is still, the load cannot do positive work on any admissible twist (LP), so loaded contacts neither open nor slip"
REST_PROOF = f"{_STEP_1}, and no motion away from rest balances the load that way (SCIP, circumscribed pyramids)"
REST_PROOF_LP = (
    f"{_STEP_1}, and no set of contacts a motion away from rest can leave still balances the load "
    "(LPs: Gordan multipliers, singular values, Farkas twists)"
)
_OUTER_EDGES = 8  # edges of the pyramid circumscribed about each friction circle
_AWAY = 1.0  # |q_j| a twist away from rest reaches in some entry, after scaling (module docstring, step 2)


def rest_proof(problem: Problem, q: np.ndarray, options: Options) -> str | None:
    """The proof, when ``q`` is rest, every mover is still, and rest is proven the only motion (module docstring); else None."""
    if problem.dimension != 3 or np.any(problem.b != 0.0) or np.max(np.abs(q), initial=0.0) > ZERO:
        return None
    if not load_cannot_descend(problem):
        return None
    if rest_proven_by_lps(problem):
        return REST_PROOF_LP
    return REST_PROOF if no_motion_away_from_rest(problem, options) else None


def load_cannot_descend(problem: Problem) -> bool:
    """``max g . q`` over admissible twists (``Jn q >= 0``) is 0: checked in the unit box, the cone's scale."""
    n = problem.n_dof
    bound = np.ones(n)
    result = solve_lp(
        problem.g, problem.Jn, np.zeros(problem.n_contacts), np.full(problem.n_contacts, np.inf), -bound, bound, maximize=True
    )
    return result.status == "optimal" and result.objective <= ZERO


def no_motion_away_from_rest(problem: Problem, options: Options) -> bool:
    """SCIP proves infeasible: a twist away from rest, with the load balanced by contacts it leaves still."""
    scip = new_model(options.remaining())
    q = [scip.addVar(lb=None, ub=None, name=f"q{j}") for j in range(problem.n_dof)]
    forces = [_contact(scip, problem, i, q) for i in range(problem.n_contacts)]
    wrench = np.einsum("mdk->kmd", problem.J).reshape(problem.n_dof, -1)  # J^T, columns per (contact, frame row)
    flat = [f for contact in forces for f in contact]
    for row in range(problem.n_dof):
        scip.addCons(linear(wrench[row], flat) == -float(problem.g[row]))
    for i in range(problem.n_contacts):
        scip.addCons(linear(problem.Jn[i], q) >= 0.0)
    scip.addCons(linear(problem.g, q) == 0.0)  # step 1: every motion has g . q = 0 (a valid cut that prunes)
    # Every constraint on q is homogeneous (scaling q by t > 0 keeps (q, c) feasible), so a twist away from
    # rest exists exactly when one with some |q_j| >= 1 does: the unit box, better conditioned than a tiny one.
    exclude_box(scip, q, np.zeros(problem.n_dof), _AWAY)
    return optimize(scip, "certified") == "infeasible"


def _contact(scip: Any, problem: Problem, i: int, q: list[Any]) -> list[Any]:
    """Contact ``i``'s force (tangents, then normal) in the circumscribed pyramid, zero unless the contact is still."""
    loaded = scip.addVar(vtype="B", name=f"loaded{i}")
    normal = scip.addVar(lb=0.0, name=f"cn{i}")
    scip.addConsIndicator(normal <= 0.0, loaded, activeone=False)  # unloaded: no force at all
    scip.addConsIndicator(linear(problem.Jn[i], q) <= 0.0, loaded)  # loaded: it does not open
    tangents = [scip.addVar(lb=None, ub=None, name=f"ct{i}_{t}") for t in range(problem.dimension - 1)]
    mu = float(problem.mu[i])
    if mu == 0.0:
        for tangent in tangents:
            scip.addCons(tangent == 0.0)
        return [*tangents, normal]
    for row in problem.Jt[i]:  # loaded and frictional: it does not slip
        scip.addConsIndicator(linear(row, q) <= 0.0, loaded)
        scip.addConsIndicator(-linear(row, q) <= 0.0, loaded)
    # |c_t| <= mu cn on the circle, inside the pyramid whose faces touch it: c_t . e_k <= mu cn for each edge direction.
    for k in range(_OUTER_EDGES):
        angle = 2.0 * math.pi * k / _OUTER_EDGES
        scip.addCons(math.cos(angle) * tangents[0] + math.sin(angle) * tangents[1] <= mu * normal)
    return [*tangents, normal]
