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
the last two). A frictionless contact's three closed modes share their force
(along the normal) and together allow any slip: one mode, ``wn = 0``. So the
LCP's solutions are the union, over the ``4^m`` mode assignments, of
polyhedra, and each of these is a product ``Q x F``: twists
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
- ``Q`` is empty (every row loosened by ``LP_FEASIBILITY``), or its exact points
  lie within ``SAME_TWIST / 2`` of the seed's twist ``q*`` and every twist that
  meets its rows to ``ZERO`` (as the seed is checked) within ``DISTINCT_TWIST / 2``
  (decided where the closed rows leave one twist or a line: bounds from their
  pseudo-inverse);
- at a leaf whose rows leave a polyhedron of twists, HiGHS finds it empty
  (LP status), or all its extremes within ``SAME_TWIST / 2`` of ``q*``.

Without a seed, the first surviving leaf whose twist and forces satisfy every law
of the form (checked as Lemke's point is, :func:`~.cheap.satisfies_form`) becomes
the seed, and the search goes on: nodes pruned before did not depend on it.

If every node is pruned the search is complete: every motion's twist is ``q*``
(to ``SAME_TWIST`` exactly, to ``DISTINCT_TWIST / 2`` within the tolerance,
which is the box the SCIP search excludes around a found motion), and no mode
assignment holds a continuum. Without a seed, a closed tree proves that no
motion exists.

**Listing every motion.** A leaf that survives is one full mode assignment,
so its motions are exactly ``Q x F`` (no node below it), with ``F`` non-empty
(its non-negative fit balances the load). Its twist set ``Q`` is measured by
``2 n`` LPs (the least and largest of each twist entry): empty (pruned), one
twist (a single motion, as when the closed rows pin it), or a continuum: its
extremes (the LPs' optima, distinct to ``SAME_TWIST``), the entries that run
to infinity, and a point inside it. Every twist listed is paired with the
leaf's forces and checked on every law of the form (:func:`~.cheap.satisfies_form`);
``Q x F`` is a product, so each of these pairs is a motion. A single twist
within ``DISTINCT_TWIST`` of one listed is not listed again (the SCIP search
excludes the same box around a motion it found), nor one on a listed
continuum's rows whose forces cannot leave the continuum's (one LP; the
search excludes a continuum's polyhedron by the same margin), nor a continuum
with the same extremes. Completeness: every motion
lies in some leaf's ``Q x F``; every leaf is either pruned (its ``F`` or ``Q``
empty, or its twists the seed's, which is listed) or listed as above. So the
list holds every motion, to the tolerances above; the seed is listed first,
unless a listed continuum holds it with the continuum's own contact modes.

A leaf whose point or extremes fail the form's check (too close to call), an
LP that does not answer, more motions than asked for, or more than
:data:`PATTERN_NODES` nodes give no answer: the caller runs the SCIP search
instead, unchanged, which lists as many as asked and says when the list may be
incomplete.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from scipy.optimize import nnls

from ...laws import Problem, RawMotion, contact_modes
from ...laws.polyhedral import LCPForm
from ...tolerances import DISTINCT_TWIST, FORCE_CEILING, LP_FEASIBILITY, MOTION_RANK, PATTERN_NODES, SAME_TWIST, ZERO
from ..numerics.highs import WarmLP, solve_lp
from .cheap import satisfies_form
from .search import relative_interior_point

__all__ = ["PatternVerdict", "PatternProof", "prove_by_patterns", "PATTERN_PROOF", "NO_MOTION_PROOF", "ENUMERATION_PROOF"]

PATTERN_PROOF = "every contact-mode pattern excluded or holding the found twist alone (mode branch and bound, LPs and Farkas vectors)"
NO_MOTION_PROOF = "no contact-mode pattern holds a motion (mode branch and bound, LPs and Farkas vectors)"
ENUMERATION_PROOF = (
    "every contact-mode pattern excluded or its motions listed: single twists, continua by their extremes "
    "(mode branch and bound, LPs and Farkas vectors)"
)

_SEPARATING, _ROLLING, _SLIDE_PLUS, _SLIDE_MINUS, _CLOSED = range(5)  # _CLOSED: a frictionless contact's three closed modes


class PatternVerdict(Enum):
    UNIQUE = "unique"  # every motion is the seed's twist
    NONE = "none"  # no motion at all (no seed given)
    ENUMERATED = "enumerated"  # several motions, or a continuum: every one of them listed in ``motions``
    UNDECIDED = "undecided"  # a leaf too close to call, or a budget ran out: run the SCIP search


@dataclass
class PatternProof:
    """The verdict, the seed it holds for (a point ``[q, cn, beta, lam]`` of the form), every motion when
    ``ENUMERATED`` (the seed's first), and the work done."""

    verdict: PatternVerdict
    seed: np.ndarray | None = None
    nodes: int = 0
    lps: int = 0
    motions: tuple[RawMotion, ...] = ()
    equilibrium: bool | None = None  # at the root: True, a balancing fit; False, a checked Farkas vector; None, neither


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
    seed: np.ndarray | None  # the seed's twist
    form: LCPForm
    frictionless: np.ndarray  # (m,) bool: mu = 0
    order: list[int]  # contacts in the order they are fixed
    proof: PatternProof = field(default_factory=lambda: PatternProof(PatternVerdict.UNDECIDED))
    closed_sets: dict[bytes, _ClosedSet | _Twists] = field(default_factory=dict)  # by which bank rows are closed
    max_motions: int = 16
    found: list[_Found] = field(default_factory=list)  # the leaves' motions other than the seed's, distinct

    @property
    def m(self) -> int:
        return self.loads.shape[1] // 2


@dataclass(frozen=True, slots=True)
class _Node:
    """Which bank rows hold as equalities and inequalities, which load columns may carry force, how deep."""

    equal: np.ndarray
    at_least: np.ndarray
    columns: np.ndarray
    depth: int
    closed_rows: int = 0  # how many entries of ``equal`` are set

    def child(self, rows: _Rows, contact: int, mode: int) -> _Node:
        columns = self.columns.copy()
        columns[2 * contact : 2 * contact + 2] &= _EDGES_OF[mode]
        if mode == _SEPARATING:  # a free contact's twist rows: the parent's arrays, shared (no node writes them)
            return _Node(self.equal, self.at_least, columns, self.depth + 1, self.closed_rows)
        m = rows.m
        equal, at_least = self.equal.copy(), self.at_least.copy()
        at_least[contact], equal[contact] = False, True
        closed_rows = self.closed_rows + 1
        if mode == _ROLLING:
            equal[m + contact] = True
            closed_rows += 1
        elif mode != _CLOSED:
            at_least[(2 if mode == _SLIDE_PLUS else 3) * m + contact] = True
        return _Node(equal, at_least, columns, self.depth + 1, closed_rows)


@dataclass(frozen=True, slots=True)
class _Ball:
    """Every loosened twist of a node lies within ``radius`` (2-norm) of ``center``."""

    center: np.ndarray
    radius: float


_EDGES_OF = {  # which of a contact's two load columns each mode keeps
    _SEPARATING: np.array([False, False]),
    _ROLLING: np.array([True, True]),
    _SLIDE_PLUS: np.array([True, False]),
    _SLIDE_MINUS: np.array([False, True]),
    _CLOSED: np.array([True, False]),  # frictionless: both columns are the normal
}
_ALL_MODES = (_ROLLING, _SLIDE_PLUS, _SLIDE_MINUS, _SEPARATING)  # separating last: see _search
_FRICTIONLESS_MODES = (_CLOSED, _SEPARATING)


def prove_by_patterns(form: LCPForm, seed_x: np.ndarray | None, max_motions: int = 16) -> PatternProof:
    """Every motion of the planar polyhedral laws ``form`` (two edges per contact): whether each has the twist of
    ``seed_x`` (a point ``[q, cn, beta, lam]`` of it), or of a seed found on the way, or, without one, whether
    no motion exists; else every motion listed (at most ``max_motions``); see the module docstring."""
    problem, n_q = form.problem, form.n_q
    Jn, Jt, bn, bt = problem.Jn, problem.Jt[:, 0, :], problem.bn, problem.bt[:, 0]
    mu = problem.mu[:, None]
    loads = np.stack([Jn + mu * Jt, Jn - mu * Jt], axis=1).reshape(-1, problem.n_dof).T
    bank = np.vstack([Jn, Jt, -Jt, Jt])
    seed = None if seed_x is None else seed_x[:n_q]
    rows = _Rows(
        bank,
        np.concatenate([bn, bt, -bt, bt]),
        np.linalg.norm(bank, axis=1),
        loads,
        problem.g,
        seed,
        form,
        problem.mu <= 0.0,
        _order(problem, seed_x, n_q),
        max_motions=max_motions,
    )
    rows.proof.seed = seed_x
    m = problem.n_contacts
    root = _Node(np.zeros(4 * m, dtype=bool), np.arange(4 * m) < m, np.ones(2 * m, dtype=bool), 0)
    fit = _forces(rows, root.columns, None)
    rows.proof.equilibrium = False if fit is None else _balances(rows, fit)
    closed = fit is None or _search(rows, root, fit, _UNKNOWN)
    rows.proof.verdict = _verdict(rows, closed)
    return rows.proof


def _verdict(rows: _Rows, closed: bool) -> PatternVerdict:
    """The search's verdict; a closed tree with other motions than the seed's lists them all, the seed's first."""
    seed_x = rows.proof.seed
    if not closed:
        return PatternVerdict.UNDECIDED
    if not rows.found:
        return PatternVerdict.NONE if seed_x is None else PatternVerdict.UNIQUE
    found = list(rows.found)
    if seed_x is not None and not any(_on_continuum(rows, f, rows.seed) for f in found):  # unless a continuum has it
        found.insert(0, _Found(RawMotion(seed_x[: rows.form.n_q], rows.form.forces(seed_x)), np.zeros(0, dtype=bool)))
    if len(found) > rows.max_motions:
        return PatternVerdict.UNDECIDED  # the SCIP search lists as many as asked and says the list is incomplete
    rows.proof.motions = tuple(f.motion for f in found)
    return PatternVerdict.ENUMERATED


def _order(problem: Problem, seed_x: np.ndarray | None, n_q: int) -> list[int]:
    """The seed's loaded contacts first, most loaded first: their modes pin the twist to the seed's soonest."""
    m = problem.n_contacts
    if seed_x is None:
        return list(range(m))
    return [int(i) for i in np.argsort(-seed_x[n_q : n_q + m], kind="stable")]


def _search(rows: _Rows, node: _Node, fit: np.ndarray, twists: _Twists) -> bool:
    """True when every mode assignment below ``node`` is pruned, or its motions listed (``rows.found``).

    ``fit``: forces on the node's columns with ``|G fit + g|`` within the margin; ``twists``: what the node's
    twists are known to be.
    """
    if node.depth == len(rows.order):
        return False  # a leaf that survived: another motion may exist
    contact = rows.order[node.depth]
    slide_blocked = False  # a closed sibling's Farkas vector also holds for separating, which keeps fewer columns
    for mode in _possible_modes(rows, contact, twists.ball):
        rows.proof.nodes += 1
        if rows.proof.nodes > PATTERN_NODES:
            return False
        child = node.child(rows, contact, mode)
        child_fit = None if mode == _SEPARATING and slide_blocked else _forces(rows, child.columns, fit)
        if child_fit is None:
            slide_blocked |= mode in (_SLIDE_PLUS, _SLIDE_MINUS, _CLOSED)
            continue  # no equilibrium below this node
        child_twists = _child_twists(rows, child, mode, twists)
        if child_twists.pruned:
            continue
        if child.depth == len(rows.order):
            if child_twists is twists:  # every row counted: a tighter ball, perhaps the seed's
                child_twists = _twist(rows, child)
                if child_twists.pruned:
                    continue
            if child_twists.point and child_twists.ball is not None and _adopted(rows, child_twists.ball.center, child_fit):
                continue
            if child_twists.point and child_twists.ball is not None:
                listed = _record_point(rows, child_twists.ball.center, child_fit, child.columns)
            else:
                listed = _record_polyhedron(rows, child, child_fit)
            if not listed:
                return False  # too close to call, or too many motions
            continue
        if not _search(rows, child, child_fit, child_twists):
            return False
    return True


def _child_twists(rows: _Rows, child: _Node, mode: int, parent: _Twists) -> _Twists:
    """The child's twists: the parent's when its rows are the same (a separating contact, as a free one) or
    already pin one twist (the child's lie in the same ball, and its modes were filtered against it)."""
    if not (mode == _SEPARATING or parent.point):
        return _twist(rows, child)
    ball, spread = parent.ball, parent.spread
    if parent.point and ball is not None and spread is not None and _near_seed(rows, ball.center, ball.center, spread):
        return _PRUNED  # a seed adopted since the parent was seen
    return parent


def _adopted(rows: _Rows, q: np.ndarray, fit: np.ndarray) -> bool:
    """Without a seed: the leaf's twist ``q`` and forces ``fit`` as the seed, when they satisfy every law of the form."""
    if rows.seed is not None:
        return False
    x = _form_point(rows, q, fit)
    if x is None:
        return False
    rows.seed, rows.proof.seed = q, x
    return True


def _form_point(rows: _Rows, q: np.ndarray, fit: np.ndarray) -> np.ndarray | None:
    """The point ``[q, cn, beta, lam]`` of twist ``q`` and forces ``fit``, when it satisfies every law of the form."""
    m = rows.m
    mu = rows.form.problem.mu
    pairs = fit.reshape(m, 2)  # unit normal forces on edges +t, -t
    slip = rows.bank[m : 2 * m] @ q - rows.rhs[m : 2 * m]
    x = np.concatenate([q, pairs.sum(axis=1), (mu[:, None] * pairs).ravel(), np.abs(slip)])
    # Round-off (a 1e-16 edge force, a rolling contact's 1e-16 slip) to exact zeros, as Lemke's pivots leave them:
    # the search reads a point's pattern from which of each pair is nearer zero.
    pairs_part = x[q.size :]  # a view: forces and slip speeds, all >= 0
    pairs_part[pairs_part <= ZERO] = 0.0
    return x if satisfies_form(rows.form, x) else None


_Region = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # a leaf's twist rows: E q = e, A q >= a


@dataclass(frozen=True, slots=True)
class _Found:
    """A motion a leaf holds; a continuum keeps its leaf's twist rows (``E q = e``, ``A q >= a``) to tell which
    twists it holds."""

    motion: RawMotion
    columns: np.ndarray  # the leaf's force columns (a unit normal force on each edge it keeps)
    region: _Region | None = None


def _record_point(rows: _Rows, q: np.ndarray, fit: np.ndarray, columns: np.ndarray) -> bool:
    """A leaf's one twist ``q`` with forces ``fit``: listed unless a listed motion has it; False when its point
    fails a law of the form (too close to call) or there are too many motions."""
    x = _form_point(rows, q, fit)
    if x is None:
        return False
    if not _known_point(rows, q, columns):
        rows.found.append(_Found(RawMotion(q, rows.form.forces(x)), columns))
    return len(rows.found) <= rows.max_motions


def _known_point(rows: _Rows, q: np.ndarray, columns: np.ndarray) -> bool:
    """Whether twist ``q`` (forces on ``columns``) is within ``DISTINCT_TWIST`` of a listed single motion, or
    every such motion is a listed continuum's (:func:`_holds`)."""
    for found in rows.found:
        if found.region is not None and _holds(rows, found, q, columns):
            return True
        motion = found.motion
        if not motion.continuum and float(np.max(np.abs(motion.q - q))) <= DISTINCT_TWIST:
            return True
    return False


def _record_polyhedron(rows: _Rows, node: _Node, fit: np.ndarray) -> bool:
    """A leaf whose rows leave a polyhedron of twists: HiGHS measures its extent along each twist entry (2 n LPs
    on one warm model). Empty, or every extreme within ``SAME_TWIST / 2`` of the seed: nothing new. One
    extreme: a single motion there. Else a continuum: its extremes, its free directions, and a point inside it
    (every inequality as slack as it can be), each with the leaf's forces and checked on every law of the form.
    False when a check or an LP fails (too close to call) or there are too many motions."""
    E, e = rows.bank[node.equal], rows.rhs[node.equal]
    A, a = rows.bank[node.at_least], rows.rhs[node.at_least]
    n = rows.g.size
    model = WarmLP(np.vstack([E, A]), np.concatenate([e, a]), np.concatenate([e, np.full(a.size, np.inf)]))
    extremes: list[np.ndarray] = []
    free: list[int] = []
    for j in range(n):
        for maximize in (False, True):
            rows.proof.lps += 1
            lp = model.optimise(np.eye(1, n, j)[0], maximize)
            if lp.status == "infeasible":
                return True
            if lp.status == "unbounded":
                free.append((j + 1) if maximize else -(j + 1))
            elif lp.status != "optimal":
                return False
            elif not any(np.max(np.abs(lp.x - p)) <= SAME_TWIST for p in extremes):
                extremes.append(lp.x)
    seed = rows.seed
    if not free and seed is not None and all(np.max(np.abs(p - seed)) <= 0.5 * SAME_TWIST for p in extremes):
        return True  # the seed's twist alone
    if not free and len(extremes) == 1:
        return _record_point(rows, extremes[0], fit, node.columns)
    return _record_continuum(rows, (E, e, A, a), extremes, tuple(free), fit, node.columns)


def _record_continuum(
    rows: _Rows, region: _Region, extremes: list[np.ndarray], free: tuple[int, ...], fit: np.ndarray, columns: np.ndarray
) -> bool:
    """A leaf's continuum (see :func:`_record_polyhedron`), listed unless one with the same extremes is."""
    E, e, A, a = region
    n = rows.g.size
    inside = relative_interior_point(E, e, A, a, np.full(n, -np.inf), np.full(n, np.nan))  # NaN: no point found
    if not free:
        # The slack-maximising point may be a vertex (its slacks' caps do not bind in scene units): averaged with
        # the extremes, it is inside the segment or polygon they span, so its modes are the continuum's own.
        inside = np.mean([inside, *extremes], axis=0)
    x = _form_point(rows, inside, fit) if np.all(np.isfinite(inside)) else None
    if x is None or any(_form_point(rows, p, fit) is None for p in extremes):
        return False
    motion = RawMotion(inside, rows.form.forces(x), tuple(extremes), bool(free), free, extremes_share_forces=True)
    if not any(_same_continuum(motion, f.motion) for f in rows.found):
        listed = _Found(motion, columns, region)
        rows.found[:] = [f for f in rows.found if f.motion.continuum or not _holds(rows, listed, f.motion.q, f.columns)]
        rows.found.append(listed)
    return len(rows.found) <= rows.max_motions


def _holds(rows: _Rows, found: _Found, q: np.ndarray, columns: np.ndarray) -> bool:
    """Whether the continuum ``found`` holds every motion of twist ``q`` and forces on ``columns`` (a leaf's):
    ``q`` meets its rows (each loosened by ``LP_FEASIBILITY``), and no balancing forces on ``columns`` put more
    than ``DISTINCT_TWIST`` on a column the continuum's leaf does not keep (one LP; the SCIP search excludes a
    continuum's polyhedron by the same margin). A twist on its boundary whose forces may leave it (both fingers
    rolling at the end of a drag, with a harder squeeze) is a motion of its own, as the SCIP search lists it."""
    if found.region is None:
        return False  # a single motion holds no other
    E, e, A, a = found.region
    if not (np.all(np.abs(E @ q - e) <= LP_FEASIBILITY) and np.all(A @ q - a >= -LP_FEASIBILITY)):
        return False
    extra = columns & ~found.columns
    if not extra.any():
        return True
    G = rows.loads[:, columns]
    rows.proof.lps += 1
    lp = solve_lp(extra[columns].astype(float), G, -rows.g, -rows.g, np.zeros(G.shape[1]), maximize=True)
    return lp.status == "optimal" and lp.objective <= DISTINCT_TWIST


def _on_continuum(rows: _Rows, found: _Found, q: np.ndarray | None) -> bool:
    """Whether twist ``q`` is one of the continuum ``found``'s own: it meets the continuum's rows (each loosened by
    ``LP_FEASIBILITY``) with the contact modes of the continuum's inner point. A twist on its boundary with other
    modes (both fingers rolling at the end of a slip) is a motion of its own, as the SCIP search lists it."""
    if q is None or found.region is None:
        return False
    E, e, A, a = found.region
    inside = np.all(np.abs(E @ q - e) <= LP_FEASIBILITY) and np.all(A @ q - a >= -LP_FEASIBILITY)
    problem = rows.form.problem
    return bool(inside) and contact_modes(problem, q) == contact_modes(problem, found.motion.q)


def _same_continuum(motion: RawMotion, other: RawMotion) -> bool:
    """Two continua with the same free directions and the same extremes (within ``SAME_TWIST``)."""
    if not other.continuum or other.free_axes != motion.free_axes or len(other.extremes) != len(motion.extremes):
        return False
    return all(any(np.max(np.abs(p - r)) <= SAME_TWIST for r in other.extremes) for p in motion.extremes)


def _possible_modes(rows: _Rows, contact: int, ball: _Ball | None) -> tuple[int, ...]:
    """The modes whose twist rows some point of ``ball`` meets (loosened by ``LP_FEASIBILITY``); all of them without one."""
    frictionless = bool(rows.frictionless[contact])
    if ball is None:
        return _FRICTIONLESS_MODES if frictionless else _ALL_MODES
    m = rows.m
    normal, tangent = contact, m + contact
    wn = float(rows.bank[normal] @ ball.center - rows.rhs[normal])
    reach_n = float(rows.norms[normal]) * ball.radius + LP_FEASIBILITY
    if abs(wn) > reach_n:
        return (_SEPARATING,)
    if frictionless:
        return _FRICTIONLESS_MODES
    slip = float(rows.bank[tangent] @ ball.center - rows.rhs[tangent])
    reach_t = float(rows.norms[tangent]) * ball.radius + LP_FEASIBILITY
    modes = []
    if abs(slip) <= reach_t:
        modes.append(_ROLLING)
    if slip <= reach_t:
        modes.append(_SLIDE_PLUS)
    if slip >= -reach_t:
        modes.append(_SLIDE_MINUS)
    return (*modes, _SEPARATING)


def _margin(rows: _Rows) -> float:
    """How far from the load a balancing fit may be (``LP_FEASIBILITY`` per row) [-]."""
    return math.sqrt(rows.g.size) * LP_FEASIBILITY


def _balances(rows: _Rows, fit: np.ndarray) -> bool | None:
    """True when ``fit`` balances the load within the margin; None when it only failed to be excluded."""
    return True if float(np.linalg.norm(rows.loads @ fit + rows.g)) <= _margin(rows) else None


def _forces(rows: _Rows, columns: np.ndarray, fit: np.ndarray | None) -> np.ndarray | None:
    """Non-negative forces on ``columns`` balancing the load within the margin, or None with a checked Farkas vector:
    then no forces on them (sum below FORCE_CEILING) leave ``|G lam + g|`` below ``LP_FEASIBILITY`` per row.

    ``fit``: the parent's forces; kept when they use none of the columns taken away.
    """
    margin = _margin(rows)
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


@dataclass(frozen=True, slots=True)
class _Twists:
    """What a node's twists are known to be: ``pruned`` (empty, or the seed's); else within ``ball`` (2-norm,
    for filtering modes) when known, and ``point`` when the closed rows leave one twist (a leaf there is another
    motion)."""

    pruned: bool
    ball: _Ball | None = None
    point: bool = False
    spread: np.ndarray | None = None  # of a point: how far, per entry, a loosened twist may lie from it


_PRUNED, _UNKNOWN = _Twists(True), _Twists(False)


def _twist(rows: _Rows, node: _Node) -> _Twists:
    """The node's twists, loosened by ``LP_FEASIBILITY`` per row, bounded by the closed rows ``E q = e``.

    What the closed rows leave is worked out once per set of closed rows (:func:`_closed_set`; the two sliding
    children of a node, and many nodes of the tree, share it); the node's inequality rows are then read off it.
    """
    n = rows.g.size
    k = node.closed_rows
    if k < n - 1 or k == 0:
        return _UNKNOWN
    key = node.equal.tobytes()
    closed = rows.closed_sets.get(key)
    if closed is None:
        closed = rows.closed_sets[key] = _closed_set(rows, node.equal, k)
    if isinstance(closed, _Twists):
        return closed
    reserve = closed.reserve[node.at_least]
    if closed.slope is not None:
        return _on_line(rows, closed.q0, closed.direction, closed.radius, closed.spread, closed.slope[node.at_least], reserve)
    if (reserve < 0.0).any():
        return _PRUNED  # an open gap or slip sign fails on the whole set
    if _near_seed(rows, closed.q0, closed.q0, closed.spread):
        return _PRUNED
    return _Twists(False, _Ball(closed.q0, closed.radius), point=True, spread=closed.spread)


@dataclass(frozen=True, slots=True)
class _ClosedSet:
    """The twists the closed rows leave: ``q0`` (a point, or a point of the line ``q0 + t direction``), within
    ``radius`` (2-norm) and ``spread`` (per entry) of the loosened and the ``ZERO``-exact sets; for every bank row,
    its best slack at ``q0`` (``reserve``) and its rate along the line (``slope``, None for a point)."""

    q0: np.ndarray
    radius: float
    spread: np.ndarray
    reserve: np.ndarray
    direction: np.ndarray
    slope: np.ndarray | None


def _closed_set(rows: _Rows, equal: np.ndarray, k: int) -> _ClosedSet | _Twists:
    """What the ``k`` closed rows ``E q = e`` leave, every row loosened by ``LP_FEASIBILITY``.

    With ``E+`` the pseudo-inverse of the ``k`` rows and ``q0 = E+ e``, the part of ``q - q0`` in E's row space
    is ``E+ (E q - e)`` (the residual ``E q0 - e`` is orthogonal to E's range), so its 2-norm is at most
    ``R = sqrt(k) LP_FEASIBILITY / s`` (``s``: the smallest singular value), and no twist exists when the
    residual exceeds ``sqrt(k) LP_FEASIBILITY``: emptiness and the modes left are decided with every row
    loosened by the LPs' tolerance. Whether the twists are the seed's is decided for twists meeting the rows
    to ``ZERO``, as the seed itself is checked (:func:`~.cheap.satisfies_form`): entry ``j`` then lies within
    ``ZERO |E+_j|_1`` of the exact set (an ill-conditioned pair of contacts turns the LPs' 1e-7 into more than
    the search's ``DISTINCT_TWIST``). Rows of full column rank pin the twists to one point; ``n - 1`` rows
    leave a line ``q0 + t d``, on which every inequality row bounds ``t``.
    """
    n = rows.g.size
    E, e = rows.bank[equal], rows.rhs[equal]
    u, sigma, vt = np.linalg.svd(E, full_matrices=k < n)  # a line's direction is the last row of the full vt
    if sigma[-1] <= MOTION_RANK or k > n and sigma[n - 1] <= MOTION_RANK:
        return _UNKNOWN
    r = min(k, n)
    pseudo_inverse = (vt[:r].T / sigma[:r]) @ u[:, :r].T
    q0 = pseudo_inverse @ e
    residual = E @ q0 - e
    if residual @ residual > k * LP_FEASIBILITY**2:
        return _PRUNED
    spread = ZERO * np.abs(pseudo_inverse).sum(axis=1)  # as far as a twist meeting the rows as the seed does may lie
    radius = math.sqrt(k) * LP_FEASIBILITY / float(sigma[r - 1])
    # Each bank row's best slack at q0 (t = 0 on a line), every row loosened by LP_FEASIBILITY.
    bank = rows.bank
    reserve = bank @ q0 + LP_FEASIBILITY * np.abs(bank @ pseudo_inverse).sum(axis=1) - rows.rhs + LP_FEASIBILITY
    direction = vt[-1]
    slope = bank @ direction if k < n else None
    return _ClosedSet(q0, radius, spread, reserve, direction, slope)


def _on_line(
    rows: _Rows, q0: np.ndarray, d: np.ndarray, radius: float, spread: np.ndarray, slope: np.ndarray, reserve: np.ndarray
) -> _Twists:
    """Twists ``q0 + t d`` (within ``spread`` per entry) with ``slope t + reserve >= 0`` for every inequality row."""
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
    if _near_seed(rows, *ends, spread):
        return _PRUNED
    return _Twists(False, _Ball(0.5 * (ends[0] + ends[1]), 0.5 * (high - low) + radius))


def _near_seed(rows: _Rows, first: np.ndarray, second: np.ndarray, spread: np.ndarray) -> bool:
    """Whether the segment ``first``-``second`` lies within ``SAME_TWIST / 2`` of the seed, and within
    ``DISTINCT_TWIST / 2`` with ``spread`` added to each entry."""
    if rows.seed is None:
        return False
    offset = np.maximum(np.abs(first - rows.seed), np.abs(second - rows.seed))
    return bool(offset.max() <= 0.5 * SAME_TWIST and (offset + spread).max() <= 0.5 * DISTINCT_TWIST)
