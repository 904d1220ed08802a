"""A complete certificate for small planar problems without SCIP: branch and bound over contact modes.

**What it proves.** Every solution of the planar polyhedral laws (the LCP of
:func:`~quasistatic.laws.polyhedral.polyhedral_form`, two edges per contact)
has, at each contact, one of four modes, and each mode is a set of *linear*
conditions (with ``s = Jt q - bt`` the slip, ``wn = Jn q - bn`` the gap rate)::

    separating  cn = 0 (so beta = 0)          twist: wn >= 0
    rolling     force in the friction cone     twist: wn = 0, s = 0
    sliding +   force on the edge n + mu t     twist: wn = 0, s <= 0
    sliding -   force on the edge n - mu t     twist: wn = 0, s >= 0

(a solution with ``cn = 0`` and ``wn = 0`` is in the first; one with ``lam = 0``
in the second; ``lam > 0`` saturates friction on the edge that opposes the slip:
the last two). So the LCP's solutions are the union, over the ``4^m`` mode
assignments, of polyhedra, and each of these is a product ``Q x F``: twists
``Q`` (kinematic rows only) times forces ``F`` (equilibrium with each contact's
generators: both edges when rolling, one when sliding, none when separating).
The twist and force conditions share no unknown once the modes are fixed.

A depth-first search fixes one contact's mode per level. At a node, the
contacts not yet fixed keep only what all their modes share: ``wn >= 0`` on the
twist and the whole cone on the force. The node's ``Q`` and ``F`` therefore
contain those of every assignment below it, and a node is pruned when

- ``F`` is empty: no forces on the allowed generators balance the load. The proof is
  a Farkas vector ``y`` from a non-negative least-squares fit (``G^T y <= 0``,
  ``-g.y > 0``), checked here; it excludes every equilibrium whose residual is below
  ``LP_FEASIBILITY`` per row and whose total force is below :data:`FORCE_CEILING`;
- ``Q`` is empty or lies, whole, within ``DISTINCT_TWIST / 2`` of the seed's
  twist ``q*`` and its exact point within ``SAME_TWIST / 2`` of it (only decided
  where the fixed rows leave one twist: a bound from their smallest singular
  value, every row loosened by ``LP_FEASIBILITY``);
- at a leaf whose rows leave a polyhedron of twists, HiGHS finds it empty
  (LP status), or all its extremes within ``SAME_TWIST / 2`` of ``q*``.

If every node is pruned the search is complete: every motion's twist is ``q*``
(to ``SAME_TWIST`` exactly, to ``DISTINCT_TWIST / 2`` within the tolerance,
which is the box the SCIP search excludes around a found motion), and no mode
assignment holds a continuum. Without a seed, a closed tree proves that no
motion exists. A surviving leaf (another motion, or a case too close to call)
or more than :data:`PATTERN_NODES` nodes gives no answer: the caller runs the
SCIP search instead, unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from scipy.optimize import nnls

from ...laws import Problem
from ...tolerances import DISTINCT_TWIST, FORCE_CEILING, LP_FEASIBILITY, MOTION_RANK, PATTERN_NODES, SAME_TWIST
from ..numerics.highs import WarmLP

__all__ = ["PatternVerdict", "PatternProof", "prove_by_patterns", "PATTERN_PROOF", "NO_MOTION_PROOF"]

PATTERN_PROOF = "every contact-mode pattern excluded or holding the found twist alone (mode branch and bound, LPs and Farkas vectors)"
NO_MOTION_PROOF = "no contact-mode pattern holds a motion (mode branch and bound, LPs and Farkas vectors)"

_SEPARATING, _ROLLING, _SLIDE_PLUS, _SLIDE_MINUS = range(4)


class PatternVerdict(Enum):
    UNIQUE = "unique"  # every motion is the seed's twist
    NONE = "none"  # no motion at all (no seed given)
    UNDECIDED = "undecided"  # another motion may exist, or the budget ran out: run the SCIP search


@dataclass
class PatternProof:
    verdict: PatternVerdict
    nodes: int = 0
    lps: int = 0


@dataclass
class _Rows:
    """A planar problem's rows, scene-relative, and the search's counters.

    ``bank`` (4 m, n) holds every twist row a mode can use, ``bank q >= or = rhs``: contact ``i``'s normal row
    (``i``), tangent row (``m + i``, rolling), and the slip signs of sliding + (``2 m + i``: ``-s >= 0``) and
    sliding - (``3 m + i``: ``s >= 0``). ``loads`` (n, 2 m): a unit normal force on each contact's edge +t, -t.
    """

    bank: np.ndarray
    rhs: np.ndarray
    norms: np.ndarray  # 2-norm of each bank row
    loads: np.ndarray
    g: np.ndarray
    seed: np.ndarray | None
    order: list[int]  # contacts in the order they are fixed
    proof: PatternProof = field(default_factory=lambda: PatternProof(PatternVerdict.UNDECIDED))

    @property
    def m(self) -> int:
        return self.loads.shape[1] // 2


@dataclass(frozen=True)
class _Node:
    """Which bank rows hold as equalities and inequalities, which load columns may carry force, how deep."""

    equal: np.ndarray
    at_least: np.ndarray
    columns: np.ndarray
    depth: int

    def child(self, rows: _Rows, contact: int, mode: int) -> _Node:
        m = rows.m
        equal, at_least, columns = self.equal.copy(), self.at_least.copy(), self.columns.copy()
        columns[2 * contact : 2 * contact + 2] &= _EDGES_OF[mode]
        if mode != _SEPARATING:
            at_least[contact], equal[contact] = False, True
        if mode == _ROLLING:
            equal[m + contact] = True
        elif mode != _SEPARATING:
            at_least[(2 if mode == _SLIDE_PLUS else 3) * m + contact] = True
        return _Node(equal, at_least, columns, self.depth + 1)


@dataclass(frozen=True)
class _Ball:
    """Every loosened twist of a node lies within ``radius`` (2-norm) of ``center``."""

    center: np.ndarray
    radius: float


_EDGES_OF = {  # which of a contact's two load columns each mode keeps
    _SEPARATING: np.array([False, False]),
    _ROLLING: np.array([True, True]),
    _SLIDE_PLUS: np.array([True, False]),
    _SLIDE_MINUS: np.array([False, True]),
}
_ALL_MODES = (_SEPARATING, _ROLLING, _SLIDE_PLUS, _SLIDE_MINUS)


def prove_by_patterns(problem: Problem, seed_x: np.ndarray | None, n_q: int) -> PatternProof:
    """Whether every motion of the planar polyhedral laws has the twist of ``seed_x`` (a point ``[q, cn, beta, lam]``
    of the form, two edges per contact), or, without one, whether no motion exists; see the module docstring."""
    Jn, Jt, bn, bt = problem.Jn, problem.Jt[:, 0, :], problem.bn, problem.bt[:, 0]
    mu = problem.mu[:, None]
    loads = np.stack([Jn + mu * Jt, Jn - mu * Jt], axis=1).reshape(-1, problem.n_dof).T
    bank = np.vstack([Jn, Jt, -Jt, Jt])
    seed = None if seed_x is None else seed_x[:n_q]
    rows = _Rows(
        bank, np.concatenate([bn, bt, -bt, bt]), np.linalg.norm(bank, axis=1), loads, problem.g, seed, _order(problem, seed_x, n_q)
    )
    m = problem.n_contacts
    root = _Node(np.zeros(4 * m, dtype=bool), np.arange(4 * m) < m, np.ones(2 * m, dtype=bool), 0)
    fit = _forces(rows, root.columns, None)
    closed = fit is None or _search(rows, root, fit, None)
    rows.proof.verdict = (PatternVerdict.UNIQUE if seed is not None else PatternVerdict.NONE) if closed else PatternVerdict.UNDECIDED
    return rows.proof


def _order(problem: Problem, seed_x: np.ndarray | None, n_q: int) -> list[int]:
    """The seed's loaded contacts first, most loaded first: their modes pin the twist to the seed's soonest."""
    m = problem.n_contacts
    if seed_x is None:
        return list(range(m))
    return [int(i) for i in np.argsort(-seed_x[n_q : n_q + m], kind="stable")]


def _search(rows: _Rows, node: _Node, fit: np.ndarray, ball: _Ball | None) -> bool:
    """True when every mode assignment below ``node`` is pruned.

    ``fit``: forces on the node's columns with ``|G fit + g|`` within the margin; ``ball``: where the node's
    twists lie, when its closed rows pin them.
    """
    if node.depth == len(rows.order):
        return False  # a leaf that survived: another motion may exist
    contact = rows.order[node.depth]
    for mode in _possible_modes(rows, contact, ball):
        rows.proof.nodes += 1
        if rows.proof.nodes > PATTERN_NODES:
            return False
        child = node.child(rows, contact, mode)
        child_fit = _forces(rows, child.columns, fit)
        if child_fit is None:
            continue  # no equilibrium below this node
        twist = _twist(rows, child)
        if twist.pruned:
            continue
        if child.depth == len(rows.order):
            if twist.point or not _leaf_polyhedron_pruned(rows, child):
                return False  # another motion, or too close to call
            continue
        if not _search(rows, child, child_fit, twist.ball):
            return False
    return True


def _possible_modes(rows: _Rows, contact: int, ball: _Ball | None) -> tuple[int, ...]:
    """The modes whose twist rows some point of ``ball`` meets (loosened by ``LP_FEASIBILITY``); all four without one."""
    if ball is None:
        return _ALL_MODES
    m = rows.m
    normal, tangent = contact, m + contact
    wn = float(rows.bank[normal] @ ball.center - rows.rhs[normal])
    slip = float(rows.bank[tangent] @ ball.center - rows.rhs[tangent])
    reach_n = float(rows.norms[normal]) * ball.radius + LP_FEASIBILITY
    reach_t = float(rows.norms[tangent]) * ball.radius + LP_FEASIBILITY
    if abs(wn) > reach_n:
        return (_SEPARATING,)
    modes = [_SEPARATING]
    if abs(slip) <= reach_t:
        modes.append(_ROLLING)
    if slip <= reach_t:
        modes.append(_SLIDE_PLUS)
    if slip >= -reach_t:
        modes.append(_SLIDE_MINUS)
    return tuple(modes)


def _forces(rows: _Rows, columns: np.ndarray, fit: np.ndarray | None) -> np.ndarray | None:
    """Non-negative forces on ``columns`` balancing the load within the margin, or None with a checked Farkas vector:
    then no forces on them (sum below FORCE_CEILING) leave ``|G lam + g|`` below ``LP_FEASIBILITY`` per row.

    ``fit``: the parent's forces; kept when they use none of the columns taken away.
    """
    margin = math.sqrt(rows.g.size) * LP_FEASIBILITY
    if fit is not None and not fit[~columns].any():
        return fit
    G = rows.loads[:, columns]
    lam = np.zeros(columns.size)
    if G.shape[1]:
        lam[columns], residual = nnls(G, -rows.g)
    else:
        residual = float(np.linalg.norm(rows.g))
    if residual <= margin:
        return lam
    y = -(rows.loads @ lam + rows.g)
    # For lam >= 0: y.(G lam + g) <= max(G^T y) sum(lam) + g.y, while |G lam + g| <= margin needs it >= -margin |y|.
    worst = max(float(np.max(G.T @ y, initial=0.0)), 0.0) * FORCE_CEILING
    proven = -float(rows.g @ y) - worst > margin * float(np.linalg.norm(y))
    return None if proven else lam


@dataclass(frozen=True)
class _Twists:
    """What a node's twists are known to be: ``pruned`` (empty, or the seed's); else within ``ball`` when
    known, and ``point`` when the closed rows leave one twist (a leaf there is another motion)."""

    pruned: bool
    ball: _Ball | None = None
    point: bool = False


_PRUNED, _UNKNOWN = _Twists(True), _Twists(False)


def _twist(rows: _Rows, node: _Node) -> _Twists:
    """The node's twists, loosened by ``LP_FEASIBILITY`` per row, bounded by the closed rows ``E q = e``.

    With ``q0`` their least-squares point and ``s`` their smallest singular value, the part of ``q - q0`` in
    E's row space has 2-norm at most ``R = sqrt(k) LP_FEASIBILITY / s`` (it is the part of ``E q - e`` in E's
    range), and no twist exists when the residual at ``q0`` exceeds ``sqrt(k) LP_FEASIBILITY``. Rows of full
    column rank pin the twists to the ball ``(q0, R)``; ``n - 1`` rows leave a line ``q0 + t d`` (within
    ``R``), on which every inequality row bounds ``t``.
    """
    E, e = rows.bank[node.equal], rows.rhs[node.equal]
    k, n = E.shape
    if k < n - 1 or k == 0:
        return _UNKNOWN
    u, sigma, vt = np.linalg.svd(E, full_matrices=True)
    if sigma[-1] <= MOTION_RANK or k > n and sigma[n - 1] <= MOTION_RANK:
        return _UNKNOWN
    r = min(k, n)
    q0 = vt[:r].T @ ((u[:, :r].T @ e) / sigma[:r])
    slack = math.sqrt(k) * LP_FEASIBILITY
    if float(np.linalg.norm(E @ q0 - e)) > slack:
        return _PRUNED
    radius = slack / float(sigma[r - 1])
    A, a = rows.bank[node.at_least], rows.rhs[node.at_least]
    reserve = A @ q0 + rows.norms[node.at_least] * radius - (a - LP_FEASIBILITY)  # each row's best slack at t = 0
    if k < n:
        return _on_line(rows, q0, vt[-1], radius, A @ vt[-1], reserve)
    if (reserve < 0.0).any():
        return _PRUNED  # an open gap or slip sign fails on the whole ball
    if _near_seed(rows, q0, q0, radius):
        return _PRUNED
    return _Twists(False, _Ball(q0, radius), point=True)


def _on_line(rows: _Rows, q0: np.ndarray, d: np.ndarray, radius: float, slope: np.ndarray, reserve: np.ndarray) -> _Twists:
    """Twists ``q0 + t d`` (within ``radius``) with ``slope t + reserve >= 0`` for every inequality row."""
    if (reserve[slope == 0.0] < 0.0).any():
        return _PRUNED
    rising, falling = slope > 0.0, slope < 0.0
    low = float(np.max(-reserve[rising] / slope[rising], initial=-np.inf))
    high = float(np.min(-reserve[falling] / slope[falling], initial=np.inf))
    if low > high:
        return _PRUNED
    if not (np.isfinite(low) and np.isfinite(high)):
        return _UNKNOWN
    ends = q0 + low * d, q0 + high * d
    if _near_seed(rows, *ends, radius):
        return _PRUNED
    return _Twists(False, _Ball(0.5 * (ends[0] + ends[1]), 0.5 * (high - low) + radius))


def _near_seed(rows: _Rows, first: np.ndarray, second: np.ndarray, radius: float) -> bool:
    """Whether the segment ``first``-``second`` lies within ``SAME_TWIST / 2`` of the seed, and within
    ``DISTINCT_TWIST / 2`` with ``radius`` added (largest entry)."""
    if rows.seed is None:
        return False
    offset = max(float(np.max(np.abs(first - rows.seed))), float(np.max(np.abs(second - rows.seed))))
    return offset <= 0.5 * SAME_TWIST and offset + radius <= 0.5 * DISTINCT_TWIST


def _leaf_polyhedron_pruned(rows: _Rows, node: _Node) -> bool:
    """A leaf whose rows leave a polyhedron of twists: pruned when HiGHS finds it empty, or every extreme
    within ``SAME_TWIST / 2`` of the seed (2 n LPs on one warm model)."""
    E, e = rows.bank[node.equal], rows.rhs[node.equal]
    A, a = rows.bank[node.at_least], rows.rhs[node.at_least]
    n = rows.g.size
    model = WarmLP(np.vstack([E, A]), np.concatenate([e, a]), np.concatenate([e, np.full(a.size, np.inf)]))
    for j in range(n):
        for maximize in (False, True):
            rows.proof.lps += 1
            lp = model.optimise(np.eye(1, n, j)[0], maximize)
            if lp.status == "infeasible":
                return True
            if lp.status != "optimal" or rows.seed is None or abs(lp.x[j] - rows.seed[j]) > 0.5 * SAME_TWIST:
                return False
    return True
