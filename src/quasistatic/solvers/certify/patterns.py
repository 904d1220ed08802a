"""A complete certificate for small planar and 3-D pyramid problems without SCIP: branch and bound over contact modes.

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

**3-D pyramids** (``K`` unit edges ``d_k`` per contact, a regular polygon, so
``0`` is inside it and at most two neighbouring edges are most opposed to any
slip ``u = Jt q - bt``). The LCP's friction rows are ``0 <= beta_k _|_
d_k.u + lam >= 0`` and ``0 <= lam _|_ mu cn - sum beta >= 0``. Its modes::

    separating    cn = 0 (so beta = 0)                     twist: wn >= 0
    rolling       force anywhere in the pyramid             twist: wn = 0, u = 0
    vertex j      force on edge j, n + mu d_j               twist: wn = 0, (d_{j+1} - d_j).u >= 0, (d_{j-1} - d_j).u >= 0
    face j, j+1   force on edges j and j + 1                twist: wn = 0, (d_j - d_{j+1}).u = 0, -(d_j + d_{j+1}).u >= 0

cover every solution: ``wn > 0`` forces ``cn = 0`` (separating). A closed
contact with ``lam = 0`` has ``d_k.u >= 0`` for every edge, and as the edges
positively span the plane, ``u = 0`` (rolling; any force of the pyramid is
``cn`` times a convex combination of its edges, ``sum beta = mu cn``).
With ``lam > 0``, ``sum beta = mu cn`` and ``beta_k > 0`` only where
``d_k.u = -lam = min_k d_k.u``: the edges most opposed to ``u``, one edge
``j`` (then ``u`` lies in the closed sector where ``j`` wins, bounded by its
two neighbours' rows: vertex ``j``) or two neighbours (then ``u`` lies along
the face's inner normal: face ``j, j+1``). A frictionless contact's closed modes are
one, ``wn = 0`` (each of its columns is the normal). Each mode is again
linear rows on the twist times generators of the force, so a full assignment
is a product ``Q x F`` as in 2-D, and a set of modes that keeps the union of
their rows' *common* constraints and their columns holds them all. The tree
splits each contact's modes coarse to fine (:func:`_contact_tree`: closed or
separating; rolling, or sliding in one of four arcs of sectors, each at most a
half-plane, whose two boundary rows and edges hold every vertex and face mode
in it; arcs halved down to one vertex and the face after it), and takes every
contact at one depth before any goes deeper (a proof takes the seed's least
loaded contacts first, a search for a first motion its most loaded). Where the closed rows leave a
plane of twists (``n - 2`` of them), its polygon is decided exactly
(:func:`_on_plane`), which bounds the twists (and so prunes modes) long
before the rows pin them.
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

**Reuse.** A child that keeps its parent's closed rows (an arc halved, a vertex) has the parent's twists cut by
its new inequality rows: the line's interval narrowed, or the polygon's points cut by each row, keeping the
points that meet it (with the same round-off leniency) and the two outermost points where a segment between a
point above the row's line and one below crosses it. Every edge of the hull is such a segment, so the hull of
the points kept holds the cut polygon, and the child is pruned and bounded from it as from its own rows. A fit
found at an earlier node that balances the load serves every node whose columns hold the columns it uses;
a Farkas vector is kept as the columns that stop it from excluding (it excludes a node's columns exactly
when they hold none of them). ``reuse=False`` works every node out from its own rows instead: the same nodes
and verdicts, for cross-checks.

Without a seed, the first surviving leaf whose twist and forces satisfy every law
of the form (checked as Lemke's point is, :func:`~.cheap.satisfies_form`) becomes
the seed, and the search goes on: nodes pruned before did not depend on it.

If every node is pruned the search is complete: every motion's twist is ``q*``
(to ``SAME_TWIST`` exactly, to ``DISTINCT_TWIST / 2`` within the tolerance,
which is the box the SCIP search excludes around a found motion), and no mode
assignment holds a continuum. Without a seed, a closed tree proves that no
motion exists.

**Listing every motion.** (3-D: isolated motions only; a leaf holding a
continuum gives no answer, as its family's faces are continua of other
patterns that SCIP's search lists once.) A leaf that survives is one full mode assignment,
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

**The sector relaxation of exact cones** (:func:`relaxation_excluded`, for :mod:`.wedge`) is searched by the
same tree with other modes: per contact separating, rolling (force in a 16-gon around the circle) or sliding
with its slip in one sector (force in that sector's polygon of chord and tangents), arcs of sectors halved
down to one. Its nodes are pruned as above; a leaf is pruned only by an LP on its twist rows (infeasible),
and the first that survives ends the search with its sectors (no seed, nothing listed): a closed tree proves
that no point of the relaxation exists, within :data:`PYRAMID_PATTERN_NODES` nodes. The siblings before each node
on the way to that leaf were excluded: as regions (a product over contacts of sets of modes) they let the next
search, on the survivor's sectors halved, pass over what they hold (each halved sector's polygon lies inside the
one it was cut from, so their exclusions still hold) and resume about where this one stopped.

A leaf whose point or extremes fail the form's check (too close to call), an
LP that does not answer, more motions than asked for, or more than
:data:`PATTERN_NODES` (3-D: :data:`PYRAMID_PATTERN_NODES`) nodes give no answer: the caller runs the SCIP search
instead, unchanged, which lists as many as asked and says when the list may be
incomplete.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, NamedTuple

import numpy as np

from ...laws import Problem, RawMotion, contact_modes
from ...laws.polyhedral import LCPForm
from ...tolerances import (
    DISTINCT_TWIST,
    FORCE_CEILING,
    JACOBI_ORTHOGONAL,
    LP_FEASIBILITY,
    MOTION_RANK,
    PATTERN_NODES,
    PYRAMID_PATTERN_NODES,
    SAME_TWIST,
    ZERO,
)
from ..numerics.closed_set import closed_rows, row_bounds
from ..numerics.highs import WarmLP, solve_lp
from ..numerics.line_extent import AxisExtents, line_axis_extents
from ..numerics.nnls import FIT_BALANCES, FIT_EXCLUDED, column_words, fit_or_farkas
from ..numerics.polygon import NEAR_SEED, UNBOUNDED, polygon_ball, polygon_vertices
from .cheap import satisfies_form
from .search import relative_interior_point

__all__ = [
    "mask_bits",
    "PatternVerdict",
    "PatternProof",
    "prove_by_patterns",
    "PATTERN_PROOF",
    "NO_MOTION_PROOF",
    "ENUMERATION_PROOF",
    "RelaxationProof",
    "PassedRegions",
    "SlipSet",
    "TreeShape",
    "relaxation_excluded",
    "ROLLING_POLYGON",
    "CLOSED_LEAF",
    "SEPARATING_LEAF",
]

PATTERN_PROOF = "every contact-mode pattern excluded or holding the found twist alone (mode branch and bound, LPs and Farkas vectors)"
NO_MOTION_PROOF = "no contact-mode pattern holds a motion (mode branch and bound, LPs and Farkas vectors)"
ENUMERATION_PROOF = (
    "every contact-mode pattern excluded or its motions listed: single twists, continua by their extremes "
    "(mode branch and bound, LPs and Farkas vectors)"
)


class PatternVerdict(Enum):
    UNIQUE = "unique"  # every motion is the seed's twist
    NONE = "none"  # no motion at all (no seed given)
    ENUMERATED = "enumerated"  # several motions, or a continuum: every one of them listed in ``motions``
    UNDECIDED = "undecided"  # a leaf too close to call, or a budget ran out: run the SCIP search
    FOUND = "found"  # ``stop_at``: the search stopped at the first motion it accepts (``motions``), proving nothing more


@dataclass
class PatternProof:
    """The verdict, the seed it holds for (a point ``[q, cn, beta, lam]`` of the form), every motion when
    ``ENUMERATED`` (the seed's first), and the work done."""

    verdict: PatternVerdict
    seed: np.ndarray | None = None
    nodes: int = 0
    lps: int = 0
    fits: int = 0  # non-negative least-squares fits made
    motions: tuple[RawMotion, ...] = ()
    equilibrium: bool | None = None  # at the root: True, a balancing fit; False, a checked Farkas vector; None, neither


@dataclass(frozen=True, slots=True)
class _Mode:
    """A set of a contact's modes as data: the bank rows its twists meet as equalities (``equal``: the gap row,
    and the slip rows it pins) and as inequalities (``at_least``), which of the contact's load columns its force
    may use (``keep``), and the sets it splits into (``children``; none for one mode). The twist rows and force
    columns of a set hold those of every mode in it, so a node that keeps them holds every assignment below it."""

    equal: np.ndarray  # int: bank rows, ``bank q = rhs``
    at_least: np.ndarray  # int: bank rows, ``bank q >= rhs``
    keep: np.ndarray  # bool (K,): the contact's load columns its force may use
    children: tuple[_Mode, ...] = ()
    separating: bool = False  # no force, the gap row stays an inequality (as at the root)
    # The same sets as bits (bit j: bank row or load column j), which a node combines in integer operations.
    equal_bits: int = 0
    at_least_bits: int = 0
    removes: int = 0  # the contact's load columns its force may not use


@dataclass(frozen=True, slots=True)
class _Layout:
    """A problem's twist rows (``bank q >= or = rhs``), its load columns (a unit normal force on each edge of
    each contact, ``K`` per contact), each contact's set of every mode (``roots``) and the levels of the tree (each
    the contact whose current set of modes, the node's, it splits into its children)."""

    bank: np.ndarray
    rhs: np.ndarray
    loads: np.ndarray
    roots: tuple[_Mode, ...]
    levels: tuple[int, ...]


@dataclass
class _Rows:
    """A problem's rows (:class:`_Layout`), scene-relative, and the search's counters."""

    bank: np.ndarray
    rhs: np.ndarray
    norms: np.ndarray  # 2-norm of each bank row
    loads: np.ndarray  # C-contiguous (the fit's kernel reads it in place)
    g: np.ndarray
    seed: np.ndarray | None  # the seed's twist
    form: LCPForm | None  # None: the sector relaxation of exact cones (:func:`relaxation_excluded`)
    levels: tuple[int, ...]  # the contact each level of the tree splits
    budget: int  # most nodes
    farkas: _FarkasVectors
    fits: _Fits = field(default_factory=lambda: _Fits())
    filters: dict[int, _ModeFilter] = field(default_factory=dict)  # by the ``id`` of a tuple of the tree's modes
    outside: list[int] = field(default_factory=list)  # per contact: the load columns not its own (bits)
    proof: PatternProof = field(default_factory=lambda: PatternProof(PatternVerdict.UNDECIDED))
    closed_sets: dict[int, _ClosedSet | _Twists] = field(default_factory=dict)  # by which bank rows are closed (bits)
    max_motions: int = 16
    remaining: Callable[[], float] | None = None  # seconds left to the caller
    reuse: bool = True  # narrow a node's twists from its parent's; try earlier nodes' fits (see prove_by_patterns)
    stop_at: Callable[[RawMotion], bool] | None = None  # stop at the first motion this accepts (the fast path's fallback)
    width: int = 2  # load columns per contact
    survivor: _Node | None = None  # the sector relaxation's leaf whose twists and forces were not excluded
    survivor_twist: np.ndarray | None = None  # a twist of it (None: its LP did not answer)
    covered: Callable[[_Node], bool] | None = None  # sector relaxation leaves the caller proves by other means
    by_rank: bool = False  # closed rows of deficient rank still bound the twists (see :func:`_closed_set`)
    seed_rows: _SeedRows | None = None  # the sector relaxation's seed: the rows it meets (see :func:`_seed_alone`)
    found: list[_Found] = field(default_factory=list)  # the leaves' motions other than the seed's, distinct
    target: np.ndarray = field(default_factory=lambda: np.zeros(0))  # what the load columns' forces balance, -g
    passed: _PassedOver | None = None  # the sector relaxation's regions excluded by earlier searches, and by this one

    @classmethod
    def of(cls, layout: _Layout, g: np.ndarray, width: int, budget: int, **search: Any) -> _Rows:
        """The rows of ``layout`` under the load ``g``, ``width`` load columns per contact, with what follows from
        them (row norms, an empty Farkas store, each contact's outside columns); ``search``: the other fields."""
        n_loads = layout.loads.shape[1]
        every, block = (1 << n_loads) - 1, (1 << width) - 1
        return cls(
            layout.bank,
            layout.rhs,
            np.linalg.norm(layout.bank, axis=1),
            np.ascontiguousarray(layout.loads),
            g,
            levels=layout.levels,
            budget=budget,
            farkas=_FarkasVectors(layout.loads, g, math.sqrt(g.size) * LP_FEASIBILITY),
            outside=[every & ~(block << (width * i)) for i in range(len(layout.roots))],
            width=width,
            target=-g,
            **search,
        )

    @property
    def lcp(self) -> LCPForm:
        """The polyhedral laws searched (a motion search, not the sector relaxation's)."""
        assert self.form is not None
        return self.form

    def columns(self, bits: int) -> np.ndarray:
        """Load columns as a boolean mask."""
        return _mask(bits, self.loads.shape[1])

    def row_mask(self, bits: int) -> np.ndarray:
        """Bank rows as a boolean mask."""
        return _mask(bits, self.bank.shape[0])


@dataclass(slots=True)  # made per node: not frozen, whose __init__ costs 3x; no one writes one
class _Node:
    """Which bank rows hold as equalities and inequalities, which load columns may carry force (bit sets: bit
    ``j`` for row or column ``j``), each contact's current set of modes, how deep."""

    equal: int
    at_least: int
    columns: int
    modes: tuple[_Mode, ...]
    depth: int
    closed_rows: int = 0  # how many rows ``equal`` holds

    def child(self, contact: int, mode: _Mode, levels: tuple[int, ...]) -> _Node:
        """The node with ``contact``'s set narrowed to ``mode``, past the next levels whose contact's set is one mode
        already (nothing to split; ``levels``: the contact each splits)."""
        columns = self.columns & ~mode.removes
        modes = (*self.modes[:contact], mode, *self.modes[contact + 1 :])
        new_equal = mode.equal_bits & ~self.equal
        at_least = (self.at_least & ~new_equal) | (mode.at_least_bits & ~self.at_least)
        depth = _settled_depth(levels, modes, self.depth + 1)
        return _Node(self.equal | new_equal, at_least, columns, modes, depth, self.closed_rows + new_equal.bit_count())


def _settled_depth(levels: tuple[int, ...], modes: tuple[_Mode, ...], depth: int) -> int:
    """The first level from ``depth`` whose contact's set of ``modes`` splits (or the leaves' depth)."""
    while depth < len(levels) and not modes[levels[depth]].children:
        depth += 1
    return depth


def mask_bits(mask: np.ndarray) -> int:
    """A boolean array as a bit set (bit ``j`` set where ``mask[j]``)."""
    return int.from_bytes(np.packbits(mask, bitorder="little").tobytes(), "little")


def _mask(bits: int, size: int) -> np.ndarray:
    """A bit set as a boolean array of ``size`` entries (the inverse of :func:`mask_bits`)."""
    packed = np.frombuffer(bits.to_bytes((size + 7) // 8, "little"), dtype=np.uint8)
    return np.unpackbits(packed, count=size, bitorder="little").view(bool)


@dataclass(slots=True)  # made per node: not frozen, whose __init__ costs 3x; no one writes one
class _Ball:
    """Every loosened twist of a node lies within ``radius`` (2-norm) of ``center``."""

    center: np.ndarray
    radius: float


def _mode(
    contact: int, equal: list[int], at_least: list[int], keep: np.ndarray, children: tuple[_Mode, ...] = (), separating: bool = False
) -> _Mode:
    """Contact ``contact``'s set of modes (``keep``: its block of ``K = keep.size`` load columns)."""
    removes = mask_bits(~keep) << (keep.size * contact)  # a relaxation's block holds ~60 columns: no loop over them
    equal_bits, at_least_bits = sum(1 << r for r in set(equal)), sum(1 << r for r in set(at_least))
    return _Mode(np.array(equal, dtype=int), np.array(at_least, dtype=int), keep, children, separating, equal_bits, at_least_bits, removes)


def _planar_layout(problem: Problem, order: list[int]) -> _Layout:
    """Planar rows: ``bank`` (4 m, n) holds contact ``i``'s normal row (``i``), tangent row (``m + i``, rolling),
    and the slip signs of sliding + (``2 m + i``: ``-s >= 0``) and sliding - (``3 m + i``: ``s >= 0``); ``loads``
    (n, 2 m): a unit normal force on each contact's edge +t, -t. One level per contact: rolling, sliding +,
    sliding -, separating (last: see :func:`_search`); a frictionless contact's three closed modes are one."""
    m = problem.n_contacts
    Jn, Jt, bn, bt = problem.Jn, problem.Jt[:, 0, :], problem.bn, problem.bt[:, 0]
    mu = problem.mu[:, None]
    loads = np.stack([Jn + mu * Jt, Jn - mu * Jt], axis=1).reshape(-1, problem.n_dof).T
    roots = tuple(_planar_tree(i, m, bool(problem.mu[i] > 0.0)) for i in range(m))
    bank, rhs = np.vstack([Jn, Jt, -Jt, Jt]), np.concatenate([bn, bt, -bt, bt])
    return _Layout(bank, rhs, loads, roots, tuple(order))


@functools.lru_cache(maxsize=4096)
def _planar_tree(i: int, m: int, frictional: bool) -> _Mode:
    """Contact ``i``'s planar modes (bank rows as in :func:`_planar_layout`); the same for every problem of
    ``m`` contacts, so made once (no node writes a mode)."""
    both, plus, minus, none = np.array([True, True]), np.array([True, False]), np.array([False, True]), np.array([False, False])
    separating = _mode(i, [], [], none, separating=True)
    if not frictional:  # both columns are the normal
        return _mode(i, [], [], both, (_mode(i, [i], [], plus), separating))
    modes = (_mode(i, [i, m + i], [], both), _mode(i, [i], [2 * m + i], plus), _mode(i, [i], [3 * m + i], minus), separating)
    return _mode(i, [], [], both, modes)


def _pyramid_layout(form: LCPForm, groups: list[list[int]]) -> _Layout:
    """3-D pyramid rows, with ``u = Jt q - bt`` a contact's slip and ``d_k`` its edges (``K``): ``bank`` holds the
    normal rows (``i``), the two tangent rows (``m + i``, ``2 m + i``), then per contact and edge ``j`` the rows
    of the sector where ``d_j`` is the most opposed edge, ``(d_{j+1} - d_j).u >= 0`` and ``(d_{j-1} - d_j).u >= 0``,
    and of the face ``(j, j + 1)``: ``(d_j - d_{j+1}).u = 0`` and ``-(d_j + d_{j+1}).u >= 0``. ``loads``
    (n, m K): a unit normal force on each edge, ``J_n + mu d_k.J_t``.

    Each contact's modes form a tree of sets (:func:`_slip_tree`): closed or separating; a closed contact
    rolling, or sliding with its slip in an arc of sectors (at most a half-plane) and its force on their
    edges; arcs halved down to one sector, which splits into its vertex and the face after it. The levels
    take every contact of a group (those the seed closes, then the others) at one depth of its tree before
    any goes deeper: coarse sets of all contacts together exclude whole regions of the tree (a Farkas vector
    for forces on half of each polygon), and the twist is pinned (closed normals, rolling contacts) before
    the slip's finest modes are tried."""
    problem = form.problem
    m, K = form.edges.shape[:2]
    n = problem.n_dof
    Jn, Jt, bn, bt, mu = problem.Jn, problem.Jt, problem.bn, problem.bt, problem.mu
    JD = np.einsum("mkt,mtn->mkn", form.edges, Jt)  # slip along each edge per unit twist
    bD = np.einsum("mkt,mt->mk", form.edges, bt)
    after, b_after = np.roll(JD, -1, axis=1), np.roll(bD, -1, axis=1)
    before, b_before = np.roll(JD, 1, axis=1), np.roll(bD, 1, axis=1)
    blocks = [(after - JD, b_after - bD), (before - JD, b_before - bD), (JD - after, bD - b_after), (-(JD + after), -(bD + b_after))]
    bank = np.vstack([Jn, Jt[:, 0], Jt[:, 1], *(rows.reshape(m * K, n) for rows, _ in blocks)])
    rhs = np.concatenate([bn, bt[:, 0], bt[:, 1], *(values.ravel() for _, values in blocks)])
    loads = (Jn[:, None, :] + mu[:, None, None] * JD).reshape(m * K, n).T
    roots = tuple(_contact_tree(i, m, K, bool(mu[i] > 0.0)) for i in range(m))
    rounds = max(_tree_depth(root) for root in roots)
    levels = [i for group in groups for _ in range(rounds) for i in group]
    return _Layout(bank, rhs, loads, roots, tuple(levels))


@functools.lru_cache(maxsize=1024)
def _contact_tree(i: int, m: int, K: int, frictional: bool) -> _Mode:
    """Contact ``i``'s modes as a tree of sets (bank rows as in :func:`_pyramid_layout`): separating, or closed
    (its gap row an equality); closed and frictional: rolling (both tangent rows), or sliding in one of
    :data:`SLIP_ARCS` arcs of sectors (a half-plane at most, so their rows are its two boundary rays). The same
    for every problem of ``m`` contacts and ``K`` edges, so made once (no node writes a mode)."""
    every, none = np.ones(K, dtype=bool), np.zeros(K, dtype=bool)
    separating = _mode(i, [], [], none, separating=True)
    if not frictional:  # its closed modes are one: its columns are all the normal, so one of them is kept
        return _mode(i, [], [], every, (_mode(i, [i], [], np.arange(K) == 0), separating))
    parts = min(SLIP_ARCS, K)
    bounds = [round(K * p / parts) for p in range(parts + 1)]
    arcs = tuple(_arc(i, m, K, bounds[p], bounds[p + 1] - 1) for p in range(parts))
    closed = _mode(i, [i], [], every, (_mode(i, [i, m + i, 2 * m + i], [], every), *arcs))
    return _mode(i, [], [], every, (closed, separating))


def _arc(i: int, m: int, K: int, first: int, last: int) -> _Mode:
    """Contact ``i`` sliding with its slip in sectors ``first..last``: the edges they oppose, and the faces after
    each (``(last, last + 1)`` included, whose slip lies on the arc's boundary), so its force is on edges
    ``first..last + 1``; halved until one sector is left, which is its vertex mode or the face after it."""
    sector_next, sector_prev, face_equal, face_sign = (3 * m + block * m * K + i * K for block in range(4))
    keep = np.zeros(K, dtype=bool)
    keep[np.arange(first, last + 2) % K] = True
    rows = [sector_prev + first % K, sector_next + last % K]
    if first == last:
        j, edge = first % K, np.eye(K, dtype=bool)
        vertex = _mode(i, [i], [sector_next + j, sector_prev + j], edge[j])
        face = _mode(i, [i, face_equal + j], [face_sign + j], edge[j] | edge[(j + 1) % K])
        return _mode(i, [i], rows, keep, (vertex, face))
    middle = (first + last) // 2
    return _mode(i, [i], rows, keep, (_arc(i, m, K, first, middle), _arc(i, m, K, middle + 1, last)))


def _tree_depth(mode: _Mode) -> int:
    return 1 + max((_tree_depth(child) for child in mode.children), default=-1)


RELAXATION_ARC = 0.5 * np.pi  # widest arc of sectors (radians) a closed contact's first split gives in the sector
# relaxation; measured: 22 % fewer nodes than half-turns on 62 relaxations of 8 and 16 sectors, the same verdicts


class TreeShape(NamedTuple):
    """The shape of the sector relaxation's tree: the order its levels split the contacts in, at each depth, and
    the widest arc of sectors [rad] a closed contact's first split gives (below a half-turn)."""

    order: Sequence[int]
    widest_arc: float = RELAXATION_ARC


class SlipSet(NamedTuple):
    """A set of one contact's modes in the sector relaxation: separating, rolling (closed and still; a frictionless
    contact's one closed mode), and sliding with its slip angle [rad] in ``low..high`` (none where ``low > high``)."""

    separating: bool
    rolling: bool
    low: float
    high: float


_NO_SLIP = (math.inf, -math.inf)  # a SlipSet's angles where it slides in no sector


@dataclass(frozen=True)
class PassedRegions:
    """Regions of the sector relaxation a search excluded (each a product over contacts of sets of modes), the
    ``sectors`` and ``twist`` it searched with: a later search with the same twist, a ``covered`` that accepts
    at least as much and sectors that keep every boundary of these (halved: each polygon inside the one it was
    cut from, so every exclusion still holds) passes over them (:func:`relaxation_excluded`)."""

    sectors: tuple[np.ndarray, ...]
    twist: np.ndarray | None
    regions: tuple[tuple[SlipSet, ...], ...] = ()


@dataclass(frozen=True)
class RelaxationProof:
    """The mode branch and bound on the sector relaxation of exact cones (:func:`relaxation_excluded`).

    ``excluded``: no pattern holds a point of the relaxation (then no exact motion exists), but those the
    caller ``covered``. Otherwise ``sectors`` names, per contact, the sector a surviving pattern slides in
    (:data:`CLOSED_LEAF`: rolling, or closed and frictionless; :data:`SEPARATING_LEAF`), with a twist ``q`` of it;
    ``sectors`` is None when the search gave no answer (budget, time, an LP that did not answer). ``farkas``:
    the last Farkas vectors the search kept, which the caller may pass to the next, refined search; ``passed``
    (where a leaf survived) the regions it excluded before that leaf, with those passed to it, for the same.
    """

    excluded: bool
    sectors: tuple[int, ...] | None = None
    q: np.ndarray | None = None
    nodes: int = 0
    farkas: tuple[np.ndarray, ...] = ()  # the last Farkas vectors found (twist space), for the next refinement
    passed: PassedRegions | None = None  # what this search and those before it excluded, for the next refinement


ROLLING_POLYGON = 16  # tangents of the circle bounding a rolling contact's force in the sector relaxation
CLOSED_LEAF, SEPARATING_LEAF = -1, -2  # a sector relaxation's leaf mode that slides in no sector (RelaxationProof)


def relaxation_excluded(
    problem: Problem,
    sectors: list[np.ndarray],
    remaining: Callable[[], float] | None = None,
    covered: Callable[[tuple[int, ...]], bool] | None = None,
    twist: np.ndarray | None = None,
    farkas: Sequence[np.ndarray] = (),
    passed: PassedRegions | None = None,
    shape: TreeShape | None = None,
) -> RelaxationProof:
    """Whether the sector relaxation of the exact 3-D laws (:mod:`.wedge`) has no point, by the mode branch and bound.

    ``sectors``: per contact, the increasing angles ``theta_0 < ... < theta_S = theta_0 + 2 pi`` that split its
    tangent plane (each sector narrower than a half-turn). The relaxation's disjunction is a choice of mode per
    contact, each linear rows on the twist times a cone of forces: separating (``wn >= 0``, no force), rolling
    (``wn = 0``, no slip, ``-c_t`` in the 16-gon around the circle: its vertices' columns) or sliding in sector
    ``k`` (``wn = 0``, the slip between the sector's two boundary rays, ``-c_t`` in the hull of the arc's ends
    and the meeting points of the tangents at its ends and middle: the four vertices of the wedge's polygon of
    chord and tangents, which holds the arc). With the modes fixed the twist and the forces share no unknown,
    as in the pyramid's search: a pattern is excluded by a checked Farkas vector, by its twist rows (every row
    loosened by ``LP_FEASIBILITY``), or at a leaf by a HiGHS LP on its twist rows. A leaf that survives is
    returned (its sectors, and a twist of it): the caller refines them. A leaf whose modes (as
    :attr:`RelaxationProof.sectors` names them) ``covered`` accepts is passed over: the caller proves what it
    holds by other means. With ``twist`` (a motion's), a node whose rows leave that twist alone is passed over
    as a seed's is in :func:`prove_by_patterns` (its leaves hold no other motion): by the bounds on its closed
    rows' point, line or plane, and a leaf by :func:`_seed_alone` (an LP where the seed meets rows of its leaf
    as inequalities; measured: asked of every node whose twists are not bounded, it costs more than it saves). ``farkas``: vectors (an
    earlier search's :attr:`RelaxationProof.farkas`) checked on this search's columns and kept where they hold,
    so they exclude nodes before any fit (refined sectors' polygons lie inside the coarse ones': most still do).
    ``passed``: regions an earlier search excluded (:attr:`RelaxationProof.passed`; each leaf survived after the
    regions its search excluded in depth-first order), passed over where valid here (:class:`PassedRegions`):
    the search resumes about where the last stopped instead of proving its tree's start again. ``shape``: the
    tree's (:class:`TreeShape`; the default: contacts as numbered, arcs of :data:`RELAXATION_ARC`); it changes
    no verdict, only the search's cost.
    """
    layout, sector_of, sets = _sector_layout(problem, sectors, TreeShape(range(problem.n_contacts)) if shape is None else shape)
    width = layout.loads.shape[1] // problem.n_contacts

    def leaf(node: _Node) -> tuple[int, ...]:
        return tuple(SEPARATING_LEAF if mode.separating else sector_of.get(id(mode), CLOSED_LEAF) for mode in node.modes)

    skip = None if covered is None else lambda node: covered(leaf(node))
    rows = _Rows.of(layout, problem.g, width, PYRAMID_PATTERN_NODES, seed=twist, form=None, remaining=remaining, covered=skip, by_rank=True)
    rows.seed_rows = None if twist is None else _SeedRows.of(layout, twist)
    rows.passed = _PassedOver.of(sets, sectors, twist, passed)
    m = problem.n_contacts
    every = (1 << layout.loads.shape[1]) - 1
    root_columns = functools.reduce(lambda bits, mode: bits & ~mode.removes, layout.roots, every)  # no padding
    root = _Node(0, (1 << m) - 1, root_columns, layout.roots, 0)
    for y in farkas:
        rows.farkas.add(y, 0)  # checked on this layout's columns: kept only where it holds
    fit = _fitted_forces(rows, root.columns)
    start = _past_settled(rows, root)
    closed = fit is None or _search(rows, start, fit, _UNKNOWN, rows.passed.meeting(rows.passed.regions, rows.passed.node_bits(start)))
    nodes, kept = rows.proof.nodes, tuple(rows.farkas.vectors)
    if closed:
        return RelaxationProof(True, nodes=nodes, farkas=kept)
    survivor, q = rows.survivor, rows.survivor_twist
    if survivor is None or q is None:
        return RelaxationProof(False, nodes=nodes, farkas=kept)  # out of nodes or time, or an LP that did not answer
    found = PassedRegions(tuple(np.array(bounds, dtype=float) for bounds in sectors), twist, tuple(rows.passed.found))
    return RelaxationProof(False, leaf(survivor), q, nodes, kept, found)


@dataclass
class _PassedOver:
    """The regions a sector relaxation's search passes over (:class:`PassedRegions`), as bits of its layout: per
    contact a field (``fields``) of a bit for separating, one for rolling, then one per sector; each mode's own
    set so (``bits``, by the mode's ``id``); and, in angles, what the next search may pass over (``found``)."""

    sets: list[dict[int, SlipSet]]  # per contact, by the mode's ``id``
    bits: dict[int, int]
    fields: list[int]
    regions: list[int]
    found: list[tuple[SlipSet, ...]]

    @classmethod
    def of(
        cls, sets: list[dict[int, SlipSet]], sectors: list[np.ndarray], twist: np.ndarray | None, passed: PassedRegions | None
    ) -> _PassedOver:
        """``sets``: per contact, each of its modes' (:func:`_sector_layout`); ``passed``: kept where valid."""
        angles = [np.asarray(bounds, dtype=float) for bounds in sectors]
        widths = [1 + a.size for a in angles]  # separating, rolling, each sector
        offsets = [sum(widths[:i]) for i in range(len(widths))]
        fields = [((1 << width) - 1) << offset for width, offset in zip(widths, offsets, strict=True)]

        def region_bits(region: Sequence[SlipSet]) -> int:
            return sum(_slip_bits(slips, a, offset) for slips, a, offset in zip(region, angles, offsets, strict=True))

        bits = {key: _slip_bits(slips, angles[i], offsets[i]) for i, own in enumerate(sets) for key, slips in own.items()}
        found = [] if passed is None or not _refines(angles, twist, passed) else list(passed.regions)
        return cls(sets, bits, fields, [region_bits(region) for region in found], found)

    def node_bits(self, node: _Node) -> int:
        return sum(self.bits[id(mode)] for mode in node.modes)

    def meeting(self, regions: list[int], bits: int) -> list[int]:
        """The ``regions`` that hold part of the set ``bits`` (every contact's field meets it)."""
        return [region for region in regions if all(region & bits & field for field in self.fields)]

    def note(self, node: _Node, contact: int, mode: _Mode) -> None:
        """Keep, as a region excluded, the node's children before ``mode`` (a leaf survived below it), the search
        having passed over or excluded each of them: contiguous sets (rolling, then arcs in angle order)."""
        children = node.modes[contact].children
        before = children[: next(k for k, child in enumerate(children) if child is mode)]
        union = _union([self.sets[contact][id(child)] for child in before])
        if union is not None:
            own = [self.sets[j][id(other)] for j, other in enumerate(node.modes)]
            self.found.append((*own[:contact], union, *own[contact + 1 :]))


def _refines(angles: list[np.ndarray], twist: np.ndarray | None, passed: PassedRegions) -> bool:
    """Whether ``angles`` keep every boundary of the sectors ``passed`` was found with, and its twist is ``twist``."""
    if len(angles) != len(passed.sectors) or (twist is None) != (passed.twist is None):
        return False
    if twist is not None and passed.twist is not None and not np.array_equal(twist, passed.twist):
        return False
    kept = (
        bool(np.isin(old, new).all()) and old[0] == new[0] and old[-1] == new[-1] for old, new in zip(passed.sectors, angles, strict=True)
    )
    return all(kept)


def _slip_bits(slips: SlipSet, angles: np.ndarray, offset: int) -> int:
    """A contact's set of modes as bits of its field at ``offset`` (see :class:`_PassedOver`): the sectors wholly
    inside its angles."""
    inside = (slips.low <= angles[:-1]) & (angles[1:] <= slips.high)
    return (int(slips.separating) | int(slips.rolling) << 1 | mask_bits(inside) << 2) << offset


def _union(sets: list[SlipSet]) -> SlipSet | None:
    """The union of sets of a contact's modes whose slip angles are contiguous; None for none, or a gap."""
    if not sets:
        return None
    sliding = sorted((slips.low, slips.high) for slips in sets if slips.low <= slips.high)
    if any(high != low for (_, high), (low, _) in zip(sliding, sliding[1:], strict=False)):
        return None  # not one interval: no region (passing over less is sound)
    low, high = (sliding[0][0], sliding[-1][1]) if sliding else _NO_SLIP
    return SlipSet(any(slips.separating for slips in sets), any(slips.rolling for slips in sets), low, high)


def _relaxed_twist(rows: _Rows, node: _Node) -> tuple[str, np.ndarray]:
    """The LP status of a leaf's twist rows, each loosened by ``LP_FEASIBILITY`` (as the nodes' are: closed rows
    that depend on each other, such as four coplanar supports' gaps, disagree in round-off, and HiGHS then
    answers no status), and, when ``optimal``, a twist meeting them."""
    equal, at_least = rows.row_mask(node.equal), rows.row_mask(node.at_least)
    E, e, A, a = rows.bank[equal], rows.rhs[equal], rows.bank[at_least], rows.rhs[at_least]
    rows.proof.lps += 1
    lower = np.concatenate([e - LP_FEASIBILITY, a - LP_FEASIBILITY])
    upper = np.concatenate([e + LP_FEASIBILITY, np.full(a.size, np.inf)])
    lp = solve_lp(np.zeros(rows.g.size), np.vstack([E, A]), lower, upper, simplex_first=True)  # most leaves are infeasible
    return lp.status, lp.x


@dataclass(frozen=True)
class _SeedRows:
    """Which bank rows the sector relaxation's seed twist meets (bits), each to ``LP_FEASIBILITY`` relative to
    its value: ``on`` its plane, ``above`` it as an inequality; and :func:`_seed_alone`'s verdicts by rows."""

    on: int
    above: int
    verdicts: dict[tuple[int, int], bool] = field(default_factory=dict)

    @classmethod
    def of(cls, layout: _Layout, q: np.ndarray) -> _SeedRows:
        values = layout.bank @ q - layout.rhs
        slack = LP_FEASIBILITY * (1.0 + np.abs(layout.rhs))
        return cls(mask_bits(np.abs(values) <= slack), mask_bits(values >= -slack))


def _seed_alone(rows: _Rows, node: _Node) -> bool:
    """Whether the seed's twist (the sector relaxation's, ``rows.seed_rows``) is the only twist meeting the
    node's rows: it meets them, and no direction leaves it (the rows it meets with equality have full rank, and an
    LP finds no direction into the others). The rows of every leaf below hold the node's: none holds another twist."""
    seed = rows.seed_rows
    if seed is None or node.equal & ~seed.on or node.at_least & ~seed.above:
        return False
    key = (node.equal, node.at_least)
    if key not in seed.verdicts:
        seed.verdicts[key] = _no_direction(rows, node.equal, node.at_least & seed.on)
    return seed.verdicts[key]


def _no_direction(rows: _Rows, equal: int, active: int) -> bool:
    """Whether no direction ``d != 0`` has ``E d = 0`` and ``A d >= 0`` (``E``: the bank rows ``equal``, ``A``:
    ``active``, bits): ``[E; A]`` of full column rank (relative ``MOTION_RANK``; else no answer, False), and no
    ``A d`` can be made nonzero, so an LP's optimum of ``sum A d`` with ``0 <= A d <= 1`` is 0 (else at least 1)."""
    E, A = rows.bank[rows.row_mask(equal)], rows.bank[rows.row_mask(active)]
    tight = np.vstack([E, A])
    if tight.shape[0] < rows.g.size:
        return False
    sigma = np.linalg.svd(tight, compute_uv=False)
    if sigma[-1] <= MOTION_RANK * sigma[0]:
        return False  # a direction that meets every tight row with equality (conservative: no LP asked)
    if not active:
        return True
    rows.proof.lps += 1
    lp = solve_lp(-A.sum(axis=0), tight, np.zeros(tight.shape[0]), np.concatenate([np.zeros(E.shape[0]), np.ones(A.shape[0])]))
    return lp.status == "optimal" and -lp.objective < 0.5


def _sector_layout(
    problem: Problem, sectors: list[np.ndarray], shape: TreeShape
) -> tuple[_Layout, dict[int, int], list[dict[int, SlipSet]]]:
    """The sector relaxation's rows and columns (see :func:`relaxation_excluded`), and the sector each leaf mode
    slides in (by the mode's ``id``), per contact the set of modes each of its modes holds; the tree's
    ``shape``. ``bank``: the normal rows (``i``), the two tangent rows (``m + i``,
    ``2 m + i``), then per contact and boundary angle ``theta`` the rows ``a(theta) x u >= 0`` and its negation,
    with ``u = Jt q - bt``. ``loads``: per contact a block of columns (the widest contact's count; the others
    padded with columns no mode keeps): a unit normal force with ``-c_t`` at each vertex of the rolling 16-gon,
    at the circle's point on each boundary ray, and at the two tangent points of each sector."""
    m, n = problem.n_contacts, problem.n_dof
    Jn, Jt, bn, bt, mu = problem.Jn, problem.Jt, problem.bn, problem.bt, problem.mu
    width = ROLLING_POLYGON + 3 * max(len(bounds) - 1 for bounds in sectors)
    loads = np.zeros((n, m * width))
    bank, rhs = [Jn, Jt[:, 0], Jt[:, 1]], [bn, bt[:, 0], bt[:, 1]]
    first_row, roots, sector_of, sets = 3 * m, [], dict[int, int](), list[dict[int, SlipSet]]()
    for i, bounds in enumerate(sectors):
        angles = np.asarray(bounds, dtype=float)
        cos, sin = np.cos(angles), np.sin(angles)
        crossing = cos[:, None] * Jt[i, 1] - sin[:, None] * Jt[i, 0]  # a(theta) x u, per boundary
        values = cos * bt[i, 1] - sin * bt[i, 0]
        bank += [crossing, -crossing]
        rhs += [values, -values]
        tangents = _friction_points(float(mu[i]), angles)
        loads[:, i * width : i * width + len(tangents)] = Jn[i][:, None] - Jt[i].T @ tangents.T
        root, contact_sets = _sector_tree(i, m, width, angles, first_row, bool(mu[i] > 0.0), sector_of, shape.widest_arc)
        roots.append(root)
        sets.append(contact_sets)
        first_row += 2 * len(angles)
    rounds = max(_tree_depth(root) for root in roots)
    levels = tuple(int(i) for _ in range(rounds) for i in shape.order)
    return _Layout(np.vstack(bank), np.concatenate(rhs), loads, tuple(roots), levels), sector_of, sets


def _friction_points(mu: float, angles: np.ndarray) -> np.ndarray:
    """``-c_t`` per unit normal force at each column of a contact (:func:`_sector_layout`): the rolling 16-gon's
    vertices, the circle's point on each boundary ray but the last (the first's), each sector's two tangent points."""
    corners = 2.0 * np.pi * (np.arange(ROLLING_POLYGON) + 0.5) / ROLLING_POLYGON
    lo, hi = angles[:-1], angles[1:]
    quarter = 0.25 * (hi - lo)  # the tangents at lo and mid meet at angle lo + quarter, mu / cos(quarter) out
    points = [
        (mu / np.cos(np.pi / ROLLING_POLYGON), corners),
        (mu * np.ones(lo.size), lo),
        (np.repeat(mu / np.cos(quarter), 2), np.stack([lo + quarter, hi - quarter], axis=1).ravel()),
    ]
    return np.concatenate([np.stack([r * np.cos(a), r * np.sin(a)], axis=1) for r, a in points])


def _sector_tree(
    i: int, m: int, width: int, angles: np.ndarray, first_row: int, frictional: bool, sector_of: dict[int, int], widest_arc: float
) -> tuple[_Mode, dict[int, SlipSet]]:
    """Contact ``i``'s modes in the sector relaxation (rows and columns as in :func:`_sector_layout`): separating,
    or closed; closed and frictional: rolling, or sliding in an arc of sectors of at most ``widest_arc`` [rad]
    (its two boundary rows; the columns of its sectors' polygons), halved down to one sector; and the set of
    modes each holds (by the mode's ``id``)."""
    count = len(angles) - 1
    none = np.zeros(width, dtype=bool)
    real = none.copy()
    real[: ROLLING_POLYGON + 3 * count] = True
    whole = float(angles[0]), float(angles[-1])
    sets = dict[int, SlipSet]()

    def noted(mode: _Mode, slip_set: SlipSet) -> _Mode:
        sets[id(mode)] = slip_set
        return mode

    separating = noted(_mode(i, [], [], none, separating=True), SlipSet(True, False, *_NO_SLIP))
    if not frictional:  # every column is the normal: one is kept
        closed = noted(_mode(i, [i], [], np.arange(width) == 0), SlipSet(False, True, *whole))
        return noted(_mode(i, [], [], real, (closed, separating)), SlipSet(True, True, *whole)), sets
    rolling_columns = none.copy()
    rolling_columns[:ROLLING_POLYGON] = True

    def piece(first: int, last: int) -> np.ndarray:
        keep = none.copy()
        keep[ROLLING_POLYGON + (np.arange(first, last + 2) % count)] = True  # the circle's points on its rays
        keep[ROLLING_POLYGON + count + 2 * first : ROLLING_POLYGON + count + 2 * last + 2] = True  # tangent points
        return keep

    def arc(first: int, last: int) -> _Mode:
        rows = [first_row + first, first_row + len(angles) + last + 1]  # a(lo) x u >= 0, u x a(hi) >= 0
        slips = SlipSet(False, False, float(angles[first]), float(angles[last + 1]))
        if first == last:
            leaf = _mode(i, [i], rows, piece(first, last))
            sector_of[id(leaf)] = first
            return noted(leaf, slips)
        middle = (first + last) // 2
        return noted(_mode(i, [i], rows, piece(first, last), (arc(first, middle), arc(middle + 1, last))), slips)

    groups, start = [], 0
    for k in range(1, count + 1):  # arcs of at most widest_arc (one sector may be wider, never a half-turn)
        if k == count or angles[k + 1] - angles[start] > widest_arc:
            groups.append(arc(start, k - 1))
            start = k
    rolling = noted(_mode(i, [i, m + i, 2 * m + i], [], rolling_columns), SlipSet(False, True, *_NO_SLIP))
    closed = noted(_mode(i, [i], [], real, (rolling, *groups)), SlipSet(False, True, *whole))
    return noted(_mode(i, [], [], real, (closed, separating)), SlipSet(True, True, *whole)), sets


def prove_by_patterns(
    form: LCPForm,
    seed_x: np.ndarray | None,
    max_motions: int = 16,
    remaining: Callable[[], float] | None = None,
    reuse: bool = True,
    stop_at: Callable[[RawMotion], bool] | None = None,
    hint_x: np.ndarray | None = None,
) -> PatternProof:
    """Every motion of the polyhedral laws ``form`` (planar, two edges per contact, or a 3-D pyramid): whether
    each has the twist of ``seed_x`` (a point ``[q, cn, beta, lam]`` of it), or of a seed found on the way, or,
    without one, whether no motion exists; else every motion listed (at most ``max_motions``); see the module
    docstring. ``remaining``: seconds left to the caller (the search gives up, undecided, once none are).
    ``reuse``: a node's twists narrowed from its parent's line or polygon, and balancing fits of earlier nodes
    tried before a new one (False: each node's twists from all its rows, a new fit wherever the parent's uses a
    column taken away; the same proof, slower, for cross-checks). ``stop_at``: stop at the first motion a leaf
    holds that it accepts (``FOUND``, that motion alone, nothing proven about others; a 3-D continuum offers
    one of its extremes); a closed tree proves as without it (``NONE`` without ``seed_x``). ``hint_x``: without
    a seed, a point ``[q, cn, beta, lam]`` (no law checked: where Lemke's path ended) whose contacts and modes
    are searched first, as a seed's are; it only orders the tree."""
    problem, n_q = form.problem, form.n_q
    planar = problem.dimension == 2
    if not planar and form.n_edges < 3:  # frictionless 3-D (no edges): its normals are no pyramid's columns
        return PatternProof(PatternVerdict.UNDECIDED, seed_x)
    guide = seed_x if seed_x is not None else hint_x  # what orders the tree
    order = _order(problem, guide, n_q)
    if not planar and stop_at is None and guide is not None:
        order = _pinning_first(problem, guide[:n_q], order[::-1])  # a proof visits every pattern (measured)
    layout = _planar_layout(problem, order) if planar else _pyramid_layout(form, [order])
    roots = layout.roots if planar or guide is None else _seed_modes_first(layout, form, guide)
    seed = None if seed_x is None else seed_x[:n_q]
    budget = PATTERN_NODES if planar else PYRAMID_PATTERN_NODES
    width = 2 if planar else form.n_edges
    rows = _Rows.of(
        layout, problem.g, width, budget, seed=seed, form=form, max_motions=max_motions, remaining=remaining, reuse=reuse, stop_at=stop_at
    )
    rows.proof.seed = seed_x
    m = problem.n_contacts
    root = _Node(0, (1 << m) - 1, (1 << layout.loads.shape[1]) - 1, roots, 0)
    fit = _fitted_forces(rows, root.columns)
    if fit is not None and guide is None and not planar:
        rows.levels = _most_loaded_first(rows.levels, fit, m)
    rows.proof.equilibrium = False if fit is None else _balances(rows, fit.forces)
    closed = fit is None or _search(rows, _past_settled(rows, root), fit, _UNKNOWN)
    rows.proof.verdict = _verdict(rows, closed)
    return rows.proof


def _pinning_first(problem: Problem, q: np.ndarray, order: list[int]) -> list[int]:
    """``order`` (a proof's: least loaded first) with the contacts twist ``q`` rolls at first, then those it
    slides at, then those it opens: closed rows pin the twists to a plane, a line or a point sooner, which bounds
    them and prunes modes (measured on the bench grasps' seeded proofs: 7 % fewer nodes than by load alone)."""
    gap = problem.Jn @ q - problem.bn
    slip = np.linalg.norm(np.einsum("mtn,n->mt", problem.Jt, q) - problem.bt, axis=1)
    rank = np.where(gap > ZERO, 2, np.where(slip > ZERO, 1, 0))
    return sorted(order, key=lambda i: int(rank[i]))


def _most_loaded_first(levels: tuple[int, ...], fit: _Fit, m: int) -> tuple[int, ...]:
    """Without a seed or a hint, the levels at each depth take the contacts the root's fit loads most first, as
    :func:`_order` takes a seed's: the first motion, which prunes the nodes after it, is met sooner (measured on
    the bench grasps' seedless searches: 12-20 % fewer nodes than as numbered)."""
    load = fit.forces.reshape(m, -1).sum(axis=1)
    order = [int(i) for i in np.argsort(-load, kind="stable")]
    return tuple(i for _ in range(len(levels) // m) for i in order)


def _seed_modes_first(layout: _Layout, form: LCPForm, seed_x: np.ndarray) -> tuple[_Mode, ...]:
    """Each contact's tree with the seed's slip set first among siblings: the first whose rows the seed's twist
    meets (to ``ZERO`` per unit row) and whose columns hold the seed's edge forces (closed stays before
    separating: see :func:`_search`)."""
    q, _, beta, _ = form.split(seed_x)
    slack = layout.bank @ q - layout.rhs
    tolerance = ZERO * (np.linalg.norm(layout.bank, axis=1) + 1.0)
    meets, above = mask_bits(np.abs(slack) <= tolerance), mask_bits(slack >= -tolerance)
    loaded = mask_bits(beta > ZERO)  # the load columns the seed's forces use

    def holds(mode: _Mode) -> bool:
        return not (mode.equal_bits & ~meets or mode.at_least_bits & ~above or loaded & mode.removes)

    def reorder(mode: _Mode) -> _Mode:
        children = tuple(reorder(child) for child in mode.children)
        if not any(child.separating for child in children):
            children = tuple(sorted(children, key=lambda child: not holds(child)))
        if all(new is old for new, old in zip(children, mode.children, strict=True)):
            return mode  # the shared tree's own (nothing moved below it)
        return dataclasses.replace(mode, children=children)

    return tuple(reorder(root) for root in layout.roots)


def _verdict(rows: _Rows, closed: bool) -> PatternVerdict:
    """The search's verdict; a closed tree with other motions than the seed's lists them all, the seed's first."""
    seed_x = rows.proof.seed
    if not closed and rows.proof.verdict is PatternVerdict.FOUND:
        return PatternVerdict.FOUND  # stop_at accepted a motion (see _accepted)
    if not closed:
        return PatternVerdict.UNDECIDED
    if not rows.found:
        return PatternVerdict.NONE if seed_x is None else PatternVerdict.UNIQUE
    found = list(rows.found)
    if seed_x is not None and not any(_on_continuum(rows, f, rows.seed) for f in found):  # unless a continuum has it
        found.insert(0, _Found(_seed_motion(rows), np.zeros(0, dtype=bool)))
    if len(found) > rows.max_motions:
        return PatternVerdict.UNDECIDED  # the SCIP search lists as many as asked and says the list is incomplete
    rows.proof.motions = tuple(f.motion for f in found)
    return PatternVerdict.ENUMERATED


def _accepted(rows: _Rows, motion: RawMotion) -> bool:
    """Whether ``stop_at`` takes ``motion`` (a leaf's): then it is the proof's one motion and the search stops."""
    if rows.stop_at is None or not rows.stop_at(motion):
        return False
    rows.proof.motions, rows.proof.verdict = (motion,), PatternVerdict.FOUND
    return True


def _seed_motion(rows: _Rows) -> RawMotion:
    """The seed (adopted or given) as a motion."""
    seed_x = rows.proof.seed
    assert seed_x is not None
    return RawMotion(seed_x[: rows.lcp.n_q], rows.lcp.forces(seed_x))


def _order(problem: Problem, seed_x: np.ndarray | None, n_q: int) -> list[int]:
    """The seed's loaded contacts first, most loaded first: their modes pin the twist to the seed's soonest (a
    proof, which visits every pattern, reverses it: :func:`prove_by_patterns`)."""
    m = problem.n_contacts
    if seed_x is None:
        return list(range(m))
    return [int(i) for i in np.argsort(-seed_x[n_q : n_q + m], kind="stable")]


def _search(rows: _Rows, node: _Node, fit: _Fit, twists: _Twists, passed: list[int] | None = None) -> bool:
    """True when every mode assignment below ``node`` is pruned, or its motions listed (``rows.found``).

    ``fit``: forces on the node's columns with ``|G fit + g|`` within the margin; ``twists``: what the node's
    twists are known to be; ``passed``: the regions excluded by earlier searches that hold part of the node
    (bits, :class:`_PassedOver`; the sector relaxation's).
    """
    leaf = len(rows.levels)
    if node.depth == leaf:
        return False  # a leaf that survived: another motion may exist
    contact = rows.levels[node.depth]
    modes = _possible_modes(rows, node.modes[contact].children, twists.ball)
    excluded = rows.farkas.excludes(node.columns, rows.outside[contact], modes)
    blocked = False  # a closed sibling's Farkas vector also holds for separating, which keeps fewer columns
    over = rows.passed
    node_bits = over.node_bits(node) & ~over.fields[contact] if over is not None and passed else 0
    for mode, known_empty in zip(modes, excluded, strict=True):
        rows.proof.nodes += 1
        if rows.proof.nodes > rows.budget or _out_of_time(rows):
            return False
        if known_empty or (mode.separating and blocked):
            blocked |= not mode.separating
            continue  # no equilibrium below this node
        child_passed = None
        if over is not None and passed:
            bits = node_bits | over.bits[id(mode)]
            if any(not bits & ~region for region in passed):
                continue  # an earlier search excluded it
            child_passed = over.meeting(passed, bits)
        child = node.child(contact, mode, rows.levels)
        child_twists = _child_twists(rows, node, child, mode, twists)
        if child_twists.pruned:
            continue  # before any fit, known or new: the twists cost less
        child_fit = _known_forces(rows, child.columns, fit)
        if child_fit is None:
            child_fit = _fitted_forces(rows, child.columns)
        if child_fit is None:
            blocked |= not mode.separating
            continue  # no equilibrium below this node
        if child.depth == leaf and _seed_alone(rows, child):
            continue  # the seed's twist is the only one it holds (the sector relaxation's)
        if child.depth == leaf and rows.form is None:  # the sector relaxation: a leaf with a twist is a point of it
            if rows.covered is not None and rows.covered(child):
                continue  # before its LP: most covered leaves' rows meet the motion's twist, and the LP would pass
            status, q = _relaxed_twist(rows, child)
            if status == "infeasible":
                continue
            rows.survivor, rows.survivor_twist = child, (q if status == "optimal" else None)
            return _passed_before(rows, node, contact, mode)
        if child.depth == leaf:
            if child_twists is twists:  # every row counted: a tighter ball, perhaps the seed's
                child_twists = _twist(rows, child)
                if child_twists.pruned:
                    continue
            if child_twists.point and child_twists.ball is not None and _adopted(rows, child_twists.ball.center, child_fit.forces):
                if _accepted(rows, _seed_motion(rows)):
                    return False  # stopped at it
                continue
            count = len(rows.found)  # a motion listed at this leaf is offered to stop_at
            if child_twists.point and child_twists.ball is not None:
                listed = _record_point(rows, child_twists.ball.center, child_fit.forces, rows.columns(child.columns))
            else:
                listed = _record_polyhedron(rows, child, child_fit.forces)
            if not listed:
                return False  # too close to call, or too many motions
            if len(rows.found) > count and _accepted(rows, rows.found[-1].motion):
                return False  # stopped at it
            continue
        if not _search(rows, child, child_fit, child_twists, child_passed):
            return _passed_before(rows, node, contact, mode)
    return True


def _passed_before(rows: _Rows, node: _Node, contact: int, mode: _Mode) -> bool:
    """False (the search stops); where a sector relaxation's leaf survived below ``mode``, the node's children
    before it noted as excluded (:meth:`_PassedOver.note`)."""
    if rows.passed is not None and rows.survivor is not None:
        rows.passed.note(node, contact, mode)
    return False


def _out_of_time(rows: _Rows) -> bool:
    """Whether the caller's clock has run out (read every :data:`CLOCK_NODES` nodes)."""
    return rows.remaining is not None and rows.proof.nodes % CLOCK_NODES == 0 and rows.remaining() <= 0.0


def _past_settled(rows: _Rows, node: _Node) -> _Node:
    """``node`` moved past the levels whose contact's set is one mode already (nothing to split)."""
    depth = _settled_depth(rows.levels, node.modes, node.depth)
    return node if depth == node.depth else _Node(node.equal, node.at_least, node.columns, node.modes, depth, node.closed_rows)


def _child_twists(rows: _Rows, node: _Node, child: _Node, mode: _Mode, parent: _Twists) -> _Twists:
    """The child's twists: the parent's when its rows are the same (a separating contact, as a free one) or
    already pin one twist (the child's lie in the same ball, and its modes were filtered against it). A child
    that keeps its parent's closed rows and adds inequalities narrows the parent's line or polygon by them
    (:func:`_narrowed`); others are worked out from their rows (:func:`_twist`)."""
    if not (mode.separating or parent.point):
        if rows.reuse and parent.shape is not None and child.equal == node.equal:
            own = _narrowed(rows, parent, parent.shape, child.at_least & ~node.at_least)
        else:
            own = _twist(rows, child)
        if own.ball is None and not own.pruned and parent.ball is not None:
            return _Twists(False, parent.ball, shape=own.shape)  # the child's twists are among the parent's
        return own
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
    """The point ``[q, cn, beta, lam]`` of twist ``q`` and forces ``fit``, when it satisfies every law of the form.

    ``fit`` holds a unit normal force on each edge (``K`` per contact): ``cn`` their sum, ``beta = mu fit``; the
    slip speed ``lam`` is the least the edges accept, ``max(0, max_k -d_k.u)`` (in 2-D, ``|s|``)."""
    form = rows.lcp
    m, K = form.edges.shape[:2]
    mu = form.problem.mu
    per_edge = fit.reshape(m, K)
    slip_along = (form.W[m : m + m * K, : q.size] @ q - form.r[m : m + m * K]).reshape(m, K)
    lam = np.maximum(0.0, np.max(-slip_along, axis=1))
    x = np.concatenate([q, per_edge.sum(axis=1), (mu[:, None] * per_edge).ravel(), lam])
    # Round-off (a 1e-16 edge force, a rolling contact's 1e-16 slip) to exact zeros, as Lemke's pivots leave them:
    # the search reads a point's pattern from which of each pair is nearer zero.
    pairs_part = x[q.size :]  # a view: forces and slip speeds, all >= 0
    pairs_part[pairs_part <= ZERO] = 0.0
    return x if satisfies_form(rows.lcp, x) else None


_PARALLEL = 1e-13  # sine of the angle below which two twist rows' lines in a plane are parallel (round-off)
_SKEW = 1e-9  # sine above which two such lines meet at a vertex computed well; between the two, too close to call
ROUNDOFF_SLACK = 1e-12  # relative leniency of a computed polygon vertex on its rows, and of its bounding radius
SLIP_ARCS = 4  # arcs of slip sectors a closed 3-D contact's first split gives (with rolling); measured: fewer
# nodes than halves (2) or thirds (3) on the bench grasps at 8 and 32 edges, 6 and 8 more
CLOCK_NODES = 256  # nodes between two looks at the caller's clock (~10 ms)
FARKAS_KEPT = 32  # Farkas vectors tried before a new non-negative fit (each check: one integer operation)
FITS_KEPT = 16  # balancing fits tried before a new non-negative fit (each check: one integer operation)

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
        rows.found.append(_Found(RawMotion(q, rows.lcp.forces(x)), columns))
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
    """A leaf whose rows leave a polyhedron of twists: its extent along each twist entry, by 2 n LPs on one warm
    HiGHS model (in 3-D, where the equalities leave a line, its ends in closed form). Empty, or every extreme
    within ``SAME_TWIST / 2`` of the seed: nothing new. One extreme: a single motion there. Else a continuum: its
    extremes, its free directions, and a point inside it (every inequality as slack as it can be), each with the
    leaf's forces and checked on every law of the form. False when a check or an LP fails (too close to call) or
    there are too many motions."""
    equal, at_least = rows.row_mask(node.equal), rows.row_mask(node.at_least)
    E, e = rows.bank[equal], rows.rhs[equal]
    A, a = rows.bank[at_least], rows.rhs[at_least]
    # In 3-D the extremes' order never matters below, so a line's ends are read off without the LPs.
    extents = line_axis_extents(E, e, A, a) if rows.width > 2 else None
    if extents is None:
        extents = _axis_extents_by_lps(rows, (E, e, A, a))
    if extents is None or extents.empty:
        return extents is not None
    extremes, free = list(extents.extremes), list(extents.free)
    seed = rows.seed
    if not free and seed is not None and all(np.max(np.abs(p - seed)) <= 0.5 * SAME_TWIST for p in extremes):
        return True  # the seed's twist alone
    if not free and len(extremes) == 1:
        return _record_point(rows, extremes[0], fit, rows.columns(node.columns))
    if rows.width > 2 and rows.stop_at is not None and extremes:
        return _record_point(rows, extremes[0], fit, rows.columns(node.columns))  # one motion of the continuum
    if rows.width > 2:
        # 3-D: a pyramid's continua come in families whose faces (a contact rolling at the end of its slip, on
        # the same edge) are continua of other patterns; SCIP lists the family once (its cut leaves each listed
        # polyhedron), this search would list each face. Until faces are merged, SCIP lists them.
        return False
    return _record_continuum(rows, (E, e, A, a), extremes, tuple(free), fit, rows.columns(node.columns))


def _axis_extents_by_lps(rows: _Rows, region: _Region) -> AxisExtents | None:
    """The least and largest value of each twist entry over a leaf's polyhedron: 2 n LPs on one warm HiGHS model
    (None where one ends without an answer)."""
    E, e, A, a = region
    n = rows.g.size
    model = WarmLP(np.vstack([E, A]), np.concatenate([e, a]), np.concatenate([e, np.full(a.size, np.inf)]))
    extremes: list[np.ndarray] = []
    free: list[int] = []
    for j in range(n):
        for maximize in (False, True):
            rows.proof.lps += 1
            lp = model.optimise(np.eye(1, n, j)[0], maximize)
            if lp.status == "infeasible":
                return AxisExtents(empty=True)
            if lp.status == "unbounded":
                free.append((j + 1) if maximize else -(j + 1))
            elif lp.status != "optimal":
                return None
            elif not any(np.max(np.abs(lp.x - p)) <= SAME_TWIST for p in extremes):
                extremes.append(lp.x)
    return AxisExtents(empty=False, extremes=tuple(extremes), free=tuple(free))


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
    motion = RawMotion(inside, rows.lcp.forces(x), tuple(extremes), bool(free), free, extremes_share_forces=True)
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
    problem = rows.lcp.problem
    return bool(inside) and contact_modes(problem, q) == contact_modes(problem, found.motion.q)


def _same_continuum(motion: RawMotion, other: RawMotion) -> bool:
    """Two continua with the same free directions and the same extremes (within ``SAME_TWIST``)."""
    if not other.continuum or other.free_axes != motion.free_axes or len(other.extremes) != len(motion.extremes):
        return False
    return all(any(np.max(np.abs(p - r)) <= SAME_TWIST for r in other.extremes) for p in motion.extremes)


def _possible_modes(rows: _Rows, modes: tuple[_Mode, ...], ball: _Ball | None) -> tuple[_Mode, ...]:
    """The ``modes`` whose twist rows some point of ``ball`` meets (each loosened by ``LP_FEASIBILITY``): all
    of them without one. Separating is always kept (its gap row was checked as the parent's)."""
    if ball is None:
        return modes
    filter_ = rows.filters.get(id(modes))
    if filter_ is None:
        filter_ = rows.filters[id(modes)] = _ModeFilter.of(rows, modes)
    slack = (filter_.bank @ ball.center - filter_.rhs).tolist()
    radius = ball.radius
    missed = below = 0  # the rows no point of the ball meets as equalities, and as inequalities (bits of the union)
    for j, (value, norm) in enumerate(zip(slack, filter_.norms, strict=True)):  # a few rows: floats, not arrays
        reach = norm * radius + LP_FEASIBILITY
        if not abs(value) <= reach:
            missed |= 1 << j
            if not value >= -reach:
                below |= 1 << j
    return tuple(
        mode
        for mode, equal, at_least in zip(modes, filter_.equal, filter_.at_least, strict=True)
        if mode.separating or not (equal & missed or at_least & below)
    )


@dataclass(frozen=True, slots=True)
class _ModeFilter:
    """The bank rows of a node's modes (``bank``, ``rhs``, ``norms``: their union), and each mode's among them
    (bits of the union's positions)."""

    bank: np.ndarray
    rhs: np.ndarray
    norms: list[float]
    equal: tuple[int, ...]
    at_least: tuple[int, ...]

    @classmethod
    def of(cls, rows: _Rows, modes: tuple[_Mode, ...]) -> _ModeFilter:
        # From the modes' bit sets: iterating their index arrays reads numpy scalars one by one (~20x slower).
        union = _indices(functools.reduce(lambda bits, mode: bits | mode.equal_bits | mode.at_least_bits, modes, 0))
        where = {r: j for j, r in enumerate(union)}
        equal = tuple(sum(1 << where[r] for r in _indices(mode.equal_bits)) for mode in modes)
        at_least = tuple(sum(1 << where[r] for r in _indices(mode.at_least_bits)) for mode in modes)
        return cls(rows.bank[union], rows.rhs[union], rows.norms[union].tolist(), equal, at_least)


def _margin(rows: _Rows) -> float:
    """How far from the load a balancing fit may be (``LP_FEASIBILITY`` per row) [-]."""
    return math.sqrt(rows.g.size) * LP_FEASIBILITY


def _balances(rows: _Rows, fit: np.ndarray) -> bool | None:
    """True when ``fit`` balances the load within the margin; None when it only failed to be excluded."""
    return True if float(np.linalg.norm(rows.loads @ fit + rows.g)) <= _margin(rows) else None


@dataclass(slots=True)  # made per node: not frozen, whose __init__ costs 3x; no one writes one
class _Fit:
    """Non-negative forces on the load columns (``forces``), and which columns they use (``support``, bits)."""

    forces: np.ndarray
    support: int


def _known_forces(rows: _Rows, columns: int, fit: _Fit) -> _Fit | None:
    """Forces on ``columns`` (bits) known without a new fit: the parent's ``fit`` when it uses none of the columns
    taken away, else a balancing fit found at an earlier node (``rows.fits``) that uses only ``columns`` (forces
    balancing the load on fewer columns balance it on more); None when there is none."""
    if not fit.support & ~columns:
        return fit
    return rows.fits.usable(columns) if rows.reuse else None


def _fitted_forces(rows: _Rows, columns: int) -> _Fit | None:
    """Non-negative forces on ``columns`` (bits) by a non-negative least-squares fit, balancing the load within
    the margin, or None with a checked Farkas vector (kept in ``rows.farkas``: it may exclude the next nodes'
    columns too); a fit that does neither is returned (the node is not excluded). One compiled call
    (:func:`~..numerics.nnls.fit_or_farkas`) makes the fit, the check and the bit sets."""
    rows.proof.fits += 1
    lam = np.empty(rows.loads.shape[1])
    farkas, bits = rows.farkas.work, rows.farkas.bits
    outcome = fit_or_farkas(rows.loads, column_words(columns, lam.size), rows.target, rows.farkas.margin, FORCE_CEILING, lam, farkas, bits)
    found = int.from_bytes(bits.tobytes(), "little")
    if outcome == FIT_EXCLUDED:
        rows.farkas.keep(farkas.copy(), found)
        return None
    fit = _Fit(lam, found)
    if outcome == FIT_BALANCES:
        rows.fits.add(fit)
    return fit


@dataclass
class _Fits:
    """The last balancing fits found (:data:`FITS_KEPT`, newest first)."""

    kept: list[_Fit] = field(default_factory=list)

    def add(self, fit: _Fit) -> None:
        self.kept.insert(0, fit)
        del self.kept[FITS_KEPT:]

    def usable(self, columns: int) -> _Fit | None:
        """A kept fit that uses only ``columns`` (bits), or None."""
        others = ~columns
        for fit in self.kept:
            if not fit.support & others:
                return fit
        return None


@dataclass
class _FarkasVectors:
    """The last Farkas vectors found, each a certificate that no forces on some load columns balance the load.

    For ``lam >= 0``: ``y.(G lam + g) <= max(G^T y) sum(lam) + g.y``, while ``|G lam + g| <= margin`` needs it
    ``>= -margin |y|``; so with ``reserve = -g.y - margin |y|``, ``reserve > max(G_S^T y, 0) FORCE_CEILING``
    excludes every balancing ``lam`` on the columns ``S`` whose sum is below :data:`FORCE_CEILING`. A vector is
    kept as the columns it cannot exclude (``blockers``, bits: ``(G^T y)_j FORCE_CEILING >= reserve``, and it is
    kept only with ``reserve > 0``): it excludes ``S`` exactly when ``S`` holds none of them. One vector often
    excludes a node's siblings and cousins: each is tried on a node's children at once, before any fit."""

    loads: np.ndarray
    g: np.ndarray
    margin: float
    blockers: list[int] = field(default_factory=list)  # newest last
    vectors: list[np.ndarray] = field(default_factory=list)  # the vectors themselves, as ``blockers``
    count: int = 0
    work: np.ndarray = field(init=False)  # a fit's residual (as ``g``), filled by each fit
    bits: np.ndarray = field(init=False)  # a fit's bit set over the load columns, int64 words, filled by each fit

    def __post_init__(self) -> None:
        self.work = np.empty(self.g.size)
        self.bits = np.empty((self.loads.shape[1] + 63) // 64, dtype=np.int64)

    def add(self, y: np.ndarray, columns: int) -> bool:
        """Keep ``y`` when it excludes ``columns`` (bits; then True)."""
        reserve = -float(self.g @ y) - self.margin * math.sqrt(float(y @ y))  # np.linalg.norm's arithmetic, less its overhead
        if not reserve > 0.0:
            return False
        blockers = mask_bits(self.loads.T @ y * FORCE_CEILING >= reserve)
        if blockers & columns:
            return False
        self.keep(y, blockers)
        return True

    def keep(self, y: np.ndarray, blockers: int) -> None:
        """Keep ``y``, a checked Farkas vector, as the columns it cannot exclude (``blockers``, bits), in place of the oldest
        when :data:`FARKAS_KEPT` are kept."""
        if len(self.blockers) < FARKAS_KEPT:
            self.blockers.append(blockers)
            self.vectors.append(y)
        else:
            self.blockers[self.count % FARKAS_KEPT] = blockers
            self.vectors[self.count % FARKAS_KEPT] = y
        self.count += 1

    def excludes(self, columns: int, outside: int, modes: tuple[_Mode, ...]) -> list[bool]:
        """For each of ``modes`` (of one contact; ``outside``: every column not in its block, bits): whether a kept
        vector excludes ``columns`` (bits) narrowed to the mode's."""
        inside = []  # the blockers the node's columns hold that a mode's narrowing may remove
        for blockers in self.blockers:
            left = blockers & columns
            if not left:
                return [True] * len(modes)  # a vector excludes the node itself
            if not left & outside:
                inside.append(left)
        if not inside:
            return [False] * len(modes)
        return [any(not left & ~mode.removes for left in inside) for mode in modes]


@dataclass(slots=True)  # made per node: not frozen, whose __init__ costs 3x; no one writes one
class _Twists:
    """What a node's twists are known to be: ``pruned`` (empty, or the seed's); else within ``ball`` (2-norm,
    for filtering modes) when known, and ``point`` when the closed rows leave one twist (a leaf there is another
    motion); ``shape``: where on its closed rows' line or plane they lie, which a child narrows."""

    pruned: bool
    ball: _Ball | None = None
    point: bool = False
    spread: np.ndarray | None = None  # of a point: how far, per entry, a loosened twist may lie from it
    shape: _Shape | None = None


@dataclass(slots=True)  # made per node: not frozen, whose __init__ costs 3x; no one writes one
class _Shape:
    """A node's loosened twists on what its closed rows leave (``closed``): ``q0 + t direction`` with ``t`` in
    ``interval`` (a line), or ``q0 + x plane`` with ``x`` in the hull of ``vertices`` (a plane, (V, 2)), each
    within the closed set's ``radius`` off it."""

    closed: _ClosedSet
    interval: tuple[float, float] | None = None
    vertices: _Vertices | None = None


_Vertices = list[tuple[float, float]]  # a polygon's points in a plane (few: plain floats cost less than arrays)


_PRUNED, _UNKNOWN = _Twists(True), _Twists(False)


def _twist(rows: _Rows, node: _Node) -> _Twists:
    """The node's twists, loosened by ``LP_FEASIBILITY`` per row, bounded by the closed rows ``E q = e``.

    What the closed rows leave is worked out once per set of closed rows (:func:`_closed_set`; the two sliding
    children of a node, and many nodes of the tree, share it); the node's inequality rows are then read off it.
    """
    n = rows.g.size
    k = node.closed_rows
    widest = 2 if rows.width > 2 else 1  # 3-D: a plane of twists is bounded exactly (planar: a line at most)
    if k < n - widest or k == 0:
        return _UNKNOWN
    closed = rows.closed_sets.get(node.equal)
    if closed is None:
        closed = rows.closed_sets[node.equal] = _closed_set(rows, _indices(node.equal), k)
    if isinstance(closed, _Twists):
        return closed
    if closed.free > widest:
        return _UNKNOWN  # rows of deficient rank leave more than a plane
    plane = closed.free == 2
    if closed.free == 1:
        interval = _interval(rows, closed, (-math.inf, math.inf), node.at_least)
        return _PRUNED if interval is None else _line(rows, closed, *interval)
    if plane:
        return _on_plane(rows, closed, node.at_least)
    if (closed.reserve[closed.read(rows, node.at_least)] < 0.0).any():
        return _PRUNED  # an open gap or slip sign fails on the whole set
    if _near_seed(rows, closed.q0, closed.q0, closed.spread):
        return _PRUNED
    return _Twists(False, _Ball(closed.q0, closed.radius), point=True, spread=closed.spread)


def _narrowed(rows: _Rows, parent: _Twists, shape: _Shape, new_rows: int) -> _Twists:
    """A node's twists from its ``parent``'s (their ``shape``: the same closed rows) and its inequality rows not
    in the parent's (``new_rows``, bits): the parent's line or polygon cut by each; the parent's own when none
    cuts it."""
    closed = shape.closed
    if shape.interval is not None:
        interval = _interval(rows, closed, shape.interval, new_rows)
        if interval is None:
            return _PRUNED
        return parent if interval == shape.interval else _line(rows, closed, *interval)
    reserve, rates = closed.reserve, closed.rates
    vertices = shape.vertices
    assert vertices is not None
    for j in closed.read(rows, new_rows):
        vertices = _cut(vertices, (rates.item(j, 0), rates.item(j, 1)), reserve.item(j))
        if not vertices:
            return _PRUNED
    return parent if vertices is shape.vertices else _polygon(rows, closed, vertices)


def _interval(rows: _Rows, closed: _ClosedSet, interval: tuple[float, float], at_least: int) -> tuple[float, float] | None:
    """The part of ``interval`` of the closed set's line ``q0 + t d`` where the rows ``at_least`` (bits) hold,
    ``rate t + reserve >= 0`` each; None when it is empty."""
    low, high = interval
    reserve, rates = closed.reserve, closed.rates
    for j in closed.read(rows, at_least):
        rate, slack = rates.item(j, 0), reserve.item(j)
        if rate > 0.0:
            low = max(low, -slack / rate)
        elif rate < 0.0:
            high = min(high, -slack / rate)
        elif slack < 0.0:
            return None
    return None if low > high else (low, high)


def _indices(bits: int) -> list[int]:
    """The positions of a bit set's bits, ascending (few: a node's new rows, a node's modes' rows)."""
    index = []
    while bits:
        low = bits & -bits
        index.append(low.bit_length() - 1)
        bits ^= low
    return index


@dataclass(slots=True)  # its rows' slacks and rates are filled as nodes read them (:meth:`read`)
class _ClosedSet:
    """The twists the closed rows leave: ``q0`` (a point, or a point of the line or plane ``q0 + x directions``), within
    ``radius`` (2-norm) and ``spread`` (per entry) of the loosened and the ``ZERO``-exact sets; for the bank rows read so
    far, each row's best slack at ``q0`` (``reserve``) and its rates along the line or the plane (``rates``)."""

    q0: np.ndarray
    radius: float
    spread: np.ndarray
    inverse: np.ndarray  # (n, r): the closed rows' pseudo-inverse (truncated to the ranks kept)
    directions: np.ndarray  # (free, n), C-contiguous: orthonormal directions of a line or a plane (the last rows of E's full vt)
    free: int  # the dimension of what the closed rows leave: 0 a point, 1 a line, 2 a plane (more: not bounded here)
    reserve: np.ndarray  # (bank rows,): filled at the rows read (``known``), never read elsewhere
    rates: np.ndarray  # (bank rows, 2): the same, along ``directions``
    known: int = 0  # the bank rows filled so far (bits)

    @property
    def direction(self) -> np.ndarray:
        """A line's direction."""
        return self.directions[-1]

    def read(self, rows: _Rows, bits: int) -> list[int]:
        """The bank rows ``bits`` (ascending), with ``reserve`` and ``rates`` filled at those not read before: a node
        reads a few of the bank's hundreds of rows (measured: ~10 per closed set on the bench grasps' relaxations, of
        126-1048), so each is worked out when first read, not for the whole bank."""
        index = _indices(bits)
        missing = bits & ~self.known
        if missing:
            chosen = np.array(index if missing == bits else _indices(missing), dtype=np.int64)
            row_bounds(rows.bank, rows.rhs, self.inverse, self.q0, self.directions, chosen, LP_FEASIBILITY, self.reserve, self.rates)
            self.known |= missing
        return index


def _closed_set(rows: _Rows, equal: list[int], k: int) -> _ClosedSet | _Twists:
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

    With ``rows.by_rank``, rows of deficient rank (four coplanar supports' gaps: three independent rows) are
    read by their ``r`` singular values above ``MOTION_RANK``: with ``E+`` truncated to them the bounds above
    hold as written (``U_r^T (E q - e) = S_r V_r^T (q - q0)`` exactly), and the twists lie near ``q0`` plus
    the span of the other ``n - r`` right singular vectors; the residual then proves nothing (the rows the
    small singular values join may disagree in round-off), so no set is pruned for it.
    """
    n = rows.g.size
    E, e = rows.bank[equal], rows.rhs[equal]  # ``equal``: the closed bank rows, ascending
    sigma, basis, pseudo_inverse, q0, spread = np.empty(n), np.empty((n, n)), np.empty((n, k)), np.empty(n), np.empty(n)
    # spread: as far as a twist meeting the rows as the seed does may lie, per entry
    r, square = closed_rows(E, e, rows.by_rank, MOTION_RANK, JACOBI_ORTHOGONAL, ZERO, sigma, basis, pseudo_inverse, q0, spread)
    if r == 0:
        return _UNKNOWN  # no singular value above MOTION_RANK (with by_rank), or the closed rows' rank is deficient
    if r == min(k, n) and square > k * LP_FEASIBILITY**2:
        return _PRUNED
    radius = math.sqrt(k) * LP_FEASIBILITY / float(sigma[r - 1])
    free = n - r
    directions = basis[r:n] if free <= 2 else basis[:0]  # a line's or a plane's (the last right singular vectors)
    R = rows.bank.shape[0]
    return _ClosedSet(q0, radius, spread, pseudo_inverse, directions, free, np.empty(R), np.empty((R, 2)))


def _line(rows: _Rows, closed: _ClosedSet, low: float, high: float) -> _Twists:
    """The twists ``q0 + t d`` with ``low <= t <= high`` (within the closed set's ``spread`` per entry)."""
    if low > high:
        return _PRUNED
    shape = _Shape(closed, interval=(low, high))
    if not (math.isfinite(low) and math.isfinite(high)):
        return _Twists(False, shape=shape)
    direction = closed.directions[0]
    ends = closed.q0 + low * direction, closed.q0 + high * direction
    if _near_seed(rows, *ends, closed.spread):
        return _PRUNED
    return _Twists(False, _Ball(0.5 * (ends[0] + ends[1]), 0.5 * (high - low) + closed.radius), shape=shape)


def _on_plane(rows: _Rows, closed: _ClosedSet, at_least: int) -> _Twists:
    """Twists ``q0 + P^T x`` (``P``: the closed set's plane, ``x`` in R^2) with ``rate x + reserve >= 0`` for each of
    the inequality rows ``at_least`` (bits): a polygon, decided exactly in the plane.

    It is bounded when its rows' normals leave no angle of ``pi`` or more between neighbours (they positively
    span the plane); then it is the hull of its vertices, the intersections of two of its lines that meet every
    row (with round-off's leniency): none means it is empty. Lines closer to parallel than :data:`_PARALLEL`
    meet far away or not at all; between that and :data:`_SKEW` a vertex is too close to call (no bound given).
    """
    count = at_least.bit_count()
    vertices = np.empty((count * (count - 1) // 2, 2))
    closed.read(rows, at_least)
    found = polygon_vertices(closed.rates, closed.reserve, rows.row_mask(at_least), _PARALLEL, _SKEW, ROUNDOFF_SLACK, vertices)
    if found == UNBOUNDED:
        return _UNKNOWN  # unbounded (or too close to call)
    if found == 0:
        return _PRUNED
    return _polygon(rows, closed, [(x, y) for x, y in vertices[:found].tolist()])


def _cut(vertices: _Vertices, rate: tuple[float, float], reserve: float) -> _Vertices:
    """The points whose hull is the hull of ``vertices`` cut by ``rate.x + reserve >= 0``: the vertices that meet
    it (with round-off's leniency, as :func:`_on_plane`'s), and the two ends of the cut, the outermost points where
    a segment between a vertex above the line and one below crosses it (every edge of the hull is such a segment,
    so the cut's ends are among them, whatever order the vertices come in). ``vertices`` itself when none is
    below the line."""
    a, b = rate
    values = [a * x + b * y + reserve for x, y in vertices]
    if min(values) >= 0.0:
        return vertices
    size = math.hypot(a, b)
    kept, above, below = [], [], []  # in the vertices' order, one pass
    for v, value in zip(vertices, values, strict=True):
        if value > 0.0:
            above.append((v, value))
        elif value < 0.0:
            below.append((v, value))
        if value >= -ROUNDOFF_SLACK * (size * math.hypot(*v) + abs(reserve)):
            kept.append(v)
    if not above:
        return kept
    crossings = [(x + t * (u - x), y + t * (w - y)) for (x, y), va in above for (u, w), vb in below for t in (va / (va - vb),)]
    along = [b * x - a * y for x, y in crossings]  # position along the line
    return [*kept, crossings[along.index(min(along))], crossings[along.index(max(along))]]


def _polygon(rows: _Rows, closed: _ClosedSet, vertices: _Vertices) -> _Twists:
    """The twists over the hull of ``vertices`` (in the closed set's plane): the seed's (pruned), or a ball."""
    center = np.empty(closed.q0.size)
    seed = _NO_SEED if rows.seed is None else rows.seed
    reach = polygon_ball(closed.q0, closed.directions, np.array(vertices), seed, closed.spread, SAME_TWIST, DISTINCT_TWIST, center)
    if reach == NEAR_SEED:
        return _PRUNED
    return _Twists(False, _Ball(center, reach * (1.0 + ROUNDOFF_SLACK) + closed.radius), shape=_Shape(closed, vertices=vertices))


_NO_SEED = np.zeros(0)  # polygon_ball's seed where the search has none


def _near_seed(rows: _Rows, first: np.ndarray, second: np.ndarray, spread: np.ndarray) -> bool:
    """Whether the segment ``first``-``second`` lies within ``SAME_TWIST / 2`` of the seed, and within
    ``DISTINCT_TWIST / 2`` with ``spread`` added to each entry."""
    if rows.seed is None:
        return False
    offset = np.maximum(np.abs(first - rows.seed), np.abs(second - rows.seed))
    return bool(offset.max() <= 0.5 * SAME_TWIST and (offset + spread).max() <= 0.5 * DISTINCT_TWIST)
