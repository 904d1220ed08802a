"""Rest proven the only motion by small LPs and singular values, before the SCIP program of :mod:`.rest`.

Setting (as in :mod:`.rest`): 3-D, every mover still (``b = 0``), and step 1
of that proof has shown that the load cannot do positive work on any
admissible twist, so every motion ``q`` has ``g . q = 0`` and **a loaded
contact is still** under it: ``J_i q = 0`` (``Jn_i q = 0`` if frictionless).
SCIP then shows that no twist away from rest has a balance of the load by
contacts it leaves still. This module tries to show the same without SCIP.

1. **Which contacts can stay still while the body moves.** ``K = {q : Jn q >= 0,
   g . q = 0}`` holds every motion's twist. One LP (Freund, Roundy and Todd's)
   finds multipliers ``y >= 0``, positive on as many rows ``T`` as possible,
   and ``w`` with ``e = Jn_T^T y_T + w g`` ~ 0. For a unit twist ``q`` of ``K``:
   ``y_T . Jn_T q = e . q - w g . q``, every term on the left is >= 0 and
   ``0 <= g . q <= ZERO`` (step 1's LP), so ``|Jn_T q| <= r = (|e| + |w| ZERO)
   |1/y_T|`` (Gordan's theorem made quantitative, as in :mod:`.cheap`). Contact
   ``i`` can be still under a unit ``q`` of ``K`` only if ``|A_i q| <=
   hypot(r, ZERO)`` with ``A_i = [Jn_T; g; J_i]``; when the smallest singular
   value of ``A_i`` exceeds that (and ``MOTION_RANK``), no motion away from rest
   leaves contact ``i`` still. The others form ``S``. The same test on ``[Jn_T;
   g; J_i; J_j]`` tells whether ``i`` and ``j`` can be still together: ``B_i``,
   the contacts that can be still with ``i``.
2. **No set that can be still balances the load.** A motion away from rest
   has loaded contacts (the load is not zero), all still, so all in ``B_i`` for
   any one ``i`` of them. A twist ``v`` with ``g . v > 0`` whose velocity at every
   contact of a set lies in the dual of its friction cone (``Jn_i v >= mu_i
   |Jt_i v|``; ``Jn_i v >= 0`` when frictionless) shows that no forces in the
   cones on that set balance the load: ``0 = v . (J^T c + g) = sum c_i . J_i v
   + g . v > 0`` (Farkas). One LP (the cones' duals replaced by an inscribed
   octagon, its rows tightened by ``2 LP_FEASIBILITY``) looks for ``v``; the
   exact circle inequalities are then checked on it in floating point. With
   ``S`` empty the load itself is such a twist. Such a ``v`` for ``S``, or for
   every ``B_i``, proves rest the only motion.

Nothing here relaxes the laws the other way: a contact is dropped from ``S``
only by the bound, and a set only by a checked Farkas twist. Where either
does not close, the caller runs the SCIP program.
"""

from __future__ import annotations

import math

import numpy as np

from ...laws import Problem
from ...tolerances import LP_FEASIBILITY, MOTION_RANK, ZERO
from ..numerics.highs import solve_lp

__all__ = ["rest_proven_by_lps"]

_DUAL_EDGES = 8  # edges of the octagon inscribed in each dual cone's circle (step 2)


def rest_proven_by_lps(problem: Problem) -> bool:
    """True when no motion away from rest exists, given step 1 of :mod:`.rest` (module docstring); False: undecided."""
    if float(np.linalg.norm(problem.g)) <= ZERO:
        return False  # no load: a motion needs no loaded contact, and step 2 says nothing
    found = _multipliers(problem)
    if found is None:
        return False
    base, radius = found
    still = [_still_rows(problem, i) for i in range(problem.n_contacts)]
    can_be_still = [i for i in range(problem.n_contacts) if not _only_rest(np.vstack([base, still[i]]), radius)]
    if _no_balance(problem, can_be_still):
        return True
    unbalanced: list[set[int]] = []  # sets shown unable to balance the load: so is every subset (the same twist)
    for i in can_be_still:
        with_i = np.vstack([base, still[i]])
        company = {j for j in can_be_still if j == i or not _only_rest(np.vstack([with_i, still[j]]), radius)}
        if any(company <= known for known in unbalanced):
            continue
        if not _no_balance(problem, sorted(company)):
            return False
        unbalanced.append(company)
    return True


def _still_rows(problem: Problem, i: int) -> np.ndarray:
    """The rows a still contact ``i`` sets to zero: its whole velocity, only the normal one when frictionless."""
    return problem.J[i] if problem.mu[i] > 0.0 else problem.Jn[i : i + 1]


def _multipliers(problem: Problem) -> tuple[np.ndarray, float] | None:
    """``[Jn_T; g]`` and the bound on ``|[Jn_T; g] q|`` over unit twists of ``K`` (step 1), or None if the LP fails."""
    m, n = problem.n_contacts, problem.n_dof
    # Columns [y (m), w, t (m)]: Jn^T y + w g = 0; y - t >= 0; maximise sum t with 0 <= t <= 1.
    rows = np.block([[problem.Jn.T, problem.g[:, None], np.zeros((n, m))], [np.eye(m), np.zeros((m, 1)), -np.eye(m)]])
    lower = np.zeros(n + m)
    upper = np.r_[np.zeros(n), np.full(m, np.inf)]
    col_lower = np.r_[np.zeros(m), -np.inf, np.zeros(m)]
    col_upper = np.r_[np.full(m + 1, np.inf), np.ones(m)]
    cost = np.r_[np.zeros(m + 1), np.ones(m)]
    lp = solve_lp(cost, rows, lower, upper, col_lower, col_upper, maximize=True)
    if lp.status != "optimal":
        return None
    marked = lp.x[m + 1 :] > 0.5
    y, w = np.where(marked, np.maximum(lp.x[:m], 0.0), 0.0), float(lp.x[m])
    residual = float(np.linalg.norm(problem.Jn.T @ y + w * problem.g))
    inverse = float(np.linalg.norm(1.0 / y[marked])) if marked.any() else 0.0
    radius = math.hypot((residual + abs(w) * ZERO) * inverse, ZERO)
    return np.vstack([problem.Jn[marked], problem.g[None, :]]), radius


def _only_rest(A: np.ndarray, radius: float) -> bool:
    """No unit twist has ``|A q| <= radius``: ``A``'s smallest singular value is above it (and above ``MOTION_RANK``)."""
    if A.shape[0] < A.shape[1]:
        return False
    smallest = float(np.linalg.svd(A, compute_uv=False)[-1])
    return smallest > max(radius, MOTION_RANK)


def _no_balance(problem: Problem, contacts: list[int]) -> bool:
    """A checked Farkas twist shows that forces in the exact cones of ``contacts`` alone cannot balance the load."""
    g = problem.g
    if not contacts:
        return True  # the load is not zero, and nothing carries it
    n = problem.n_dof
    angles = (2.0 * np.arange(_DUAL_EDGES) + 1.0) * math.pi / _DUAL_EDGES
    faces, reach = np.column_stack([np.cos(angles), np.sin(angles)]), math.cos(math.pi / _DUAL_EDGES)
    rows, uppers = [], []
    for i in contacts:
        mu = float(problem.mu[i])
        if mu > 0.0:  # mu f_k . (Jt_i v) - cos(pi/K) Jn_i v <= -tightening: the slip inside the dual octagon
            rows.append(mu * faces @ problem.Jt[i] - reach * problem.Jn[i][None, :])
            uppers.append(np.full(_DUAL_EDGES, -2.0 * LP_FEASIBILITY))
        else:
            rows.append(-problem.Jn[i][None, :])
            uppers.append(np.array([-2.0 * LP_FEASIBILITY]))
    A = np.vstack(rows)
    lp = solve_lp(g, A, np.full(A.shape[0], -np.inf), np.concatenate(uppers), -np.ones(n), np.ones(n), maximize=True)
    if lp.status != "optimal":
        return False
    v = lp.x
    normal, slip = problem.Jn[contacts] @ v, np.linalg.norm(problem.Jt[contacts] @ v, axis=1)
    dual = normal - problem.mu[contacts] * np.where(problem.mu[contacts] > 0.0, slip, 0.0)
    return bool(float(g @ v) > ZERO and np.all(dual >= 0.0))
