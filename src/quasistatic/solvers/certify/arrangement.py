"""A vertex certificate for one rigid body in the plane: the arrangement of the contacts' twist planes.

**The laws as a plane arrangement.** One planar body (twist ``q`` in R^3), the
polyhedral laws of :func:`~quasistatic.laws.polyhedral.polyhedral_form` (two
edges per contact). Contact ``i`` has a gap-rate plane ``wn_i = Jn_i q - bn_i = 0``
and, when it has friction, a slip plane ``s_i = Jt_i q - bt_i = 0``. A twist's
*sign vector* (the sign of every plane's row at it) fixes the force generators
each contact may use (:mod:`.patterns` lists the four modes of a contact):

    wn > 0             none (separating)
    wn = 0, s = 0      both cone edges n + mu t and n - mu t (rolling, or either sliding mode)
    wn = 0, s < 0      the edge n + mu t (sliding +)
    wn = 0, s > 0      the edge n - mu t (sliding -)

(a frictionless contact: its normal whenever ``wn = 0``). Twist and forces
share no unknown once the modes are fixed, so ``q`` is a motion exactly when
``wn(q) >= 0`` and ``-g`` lies in the cone of the generators ``G(q)``: the
union, per contact, of the generators of every mode ``q`` meets, which one
mode assignment (each contact's largest) attains.

**Faces.** The planes cut R^3 into faces (relatively open polyhedra of
constant sign vector). ``G`` is constant on a face and only grows when a face
is left for one in its boundary (a sign becomes 0), so the motions are a union
of faces, closed under taking boundary faces. When the planes' normals span
R^3 every face's closure is a pointed polyhedron; its vertices are vertices of
the arrangement (points on three planes with independent normals) and its
edges at a vertex are 1-faces of the arrangement (rays of the lines where two
planes through it meet). Hence:

1. no motion vertex means no motion (every motion face has a motion vertex);
2. one motion vertex ``v``, and no motion edge leaving it, means ``v`` is the
   only motion (a motion face of dimension >= 1 with ``v`` its only vertex is
   ``v`` plus a pointed cone, whose extreme rays are motion edges at ``v``);
3. several motion vertices and no motion edge leaving any of them mean that
   these vertices are the motions (a motion face of dimension >= 1 has a motion
   edge); a motion edge means a continuum: the listing is the branch and bound's,
   which runs unchanged.

**With the tolerances of the rest of certify/.** The claims are made for the
twists that meet every row to ``tau`` (``LP_FEASIBILITY``, what HiGHS and SCIP
meet; ``ZERO``, as the seed is checked; and 0) and forces that balance the load
to ``LP_FEASIBILITY`` per row with total below ``FORCE_CEILING``. Call such a
twist a *loose motion*: ``wn >= -tau``, and the loads allowed by every mode
whose rows it meets to ``tau`` (``G_tau(q)``, which only grows with ``tau``)
are not excluded. Fix ``tau`` and split R^3 into *cells* of constant loose
sign vector (0 where ``|row| <= tau``): each is a convex polyhedron, pointed,
so a nonempty cell's closure has a vertex ``x`` on three of its bounding planes
``row_p = +-tau`` with independent normals ``N_T`` (triple ``T``). The exact
vertex ``w_T`` (``N_T w = r_T``, computed to round-off ``delta_T``) is within
``(tau + delta_T) |N_T^-1|_1`` per entry of ``x``, so every plane ``p`` has
``|row_p(x) - row_p(w_T)| <= (tau + delta_T) |n_p N_T^-1|_1``. Call ``p`` *near*
``w_T`` when ``|row_p(w_T)|`` is at most ``tau`` plus that (plus round-off);
a plane that is not near has the same sign at ``x`` as at ``w_T`` and is not
within ``tau`` there. So the cell's loads are among ``G(sigma_T)``: the
generators of ``w_T``'s sign vector with every near plane set to 0 (a gap row
of ``w_T`` below ``-near`` puts no cell of loose ``Q0`` there). Therefore, at
``tau = LP_FEASIBILITY`` (the nearer planes of a smaller ``tau`` only shrink
the loads):

- every triple whose ``G(sigma_T)`` a checked Farkas vector excludes (as in
  :mod:`.patterns`: ``G^T y <= 0`` with the margins of ``LP_FEASIBILITY`` and
  ``FORCE_CEILING``) holds no loose motion near it; when every triple is
  excluded there is **no motion** (claim 1);
- when the triples left (not excluded) all have ``w_T`` within ``SAME_TWIST / 2``
  of the seed ``q*`` (Lemke's checked motion, or the held vertex's, checked
  the same way) and ``|w_T - q*| + (tau + delta) |N_T^-1|_1``
  within ``DISTINCT_TWIST / 2`` at ``tau = ZERO`` and within ``DISTINCT_TWIST``
  at ``tau = LP_FEASIBILITY`` (the box the SCIP search excludes around a
  motion, as :func:`~.cheap.kinematically_unique` bounds it; a cell's vertices
  each lie near a triple whose loads hold the cell's, so a held one), every cell whose
  vertices lie near them is bounded: an unbounded one has a recession direction
  ``d`` that keeps every near plane of ``w_T`` at its cell sign or on it; the
  face of ``d`` in the central arrangement of the near planes' normals is a
  pointed cone, one of whose extreme rays ``e`` (a line where two near planes
  meet, ``+-n_a x n_b``, kept only where no near gap row falls along it) has a
  sign vector with at least the zeros of the cell's, so ``G(e)`` holds the
  cell's loads. So when every such ray's loads are excluded, every loose motion
  lies in a bounded cell whose vertices are near ``q*``: the **only motion** is
  ``q*`` (claim 2).

- **several isolated motions** (claim 3 with the margins): group the held triples
  by twist (within ``DISTINCT_TWIST`` of a group's best computed one), give each
  group a checked motion ``q_k`` (the seed for its group, else the group's best
  computed vertex with least-squares forces, checked as Lemke's point is) with
  every triple of the group near ``q_k`` as above. A loose motion lies in a cell
  whose vertices are each near a held triple. An unbounded cell is held by a ray
  as above. A bounded cell whose vertices all lie near one group lies in that
  group's box. Otherwise the cell has an edge from a vertex ``x`` near a triple
  ``T`` of one group to a vertex ``x'`` near another group, at least ``L`` away
  (the least distance between two groups' triples less their loose boxes). The
  edge lies where two of the cell's bounding planes meet, both near ``w_T`` (``x``
  is on them), so along ``e = +-n_a x n_b``. A near plane ``p`` with cell sign 0
  keeps ``|row_p| <= tau`` over the edge, so ``|n_p . e| <= 2 tau / L`` per unit
  length; one with cell sign ``+`` keeps ``row_p >= tau`` from ``|row_p(x)| <=
  2 margin_p`` on, so ``n_p . e >= -2 margin_p / L``. Taking every rate within
  ``2 margin_p / L`` as 0 (it only adds loads), the ray's sign vector has at least
  the cell's zeros and no sign against the cell's, so ``G(e)`` holds the cell's
  loads. So when every such ray's loads are excluded, every loose motion lies in
  one group's box: the motions are the ``q_k``, **each listed** (as the branch and
  bound lists isolated motions: one twist per ``DISTINCT_TWIST`` box, the seed's
  first). A motion edge (a continuum) leaves a ray not excluded, and the branch
  and bound lists it as before; more groups than ``max_solutions`` too.

A sign of ``n_p . e`` within round-off is taken as 0, which only adds loads
(it can keep a ray from being excluded, never exclude one). Three normals whose
determinant is within round-off of 0 are taken as dependent, and two within
round-off of parallel as meeting in no line (:data:`ARRANGEMENT_ROUNDOFF`): the
one round-off assumption, as the branch and bound takes lines within round-off
of parallel as parallel. A seed with every vertex excluded, which the claims
say cannot be, proves nothing.

**Cheaply.** All triples at once: the triple products ``n_p . (n_a x n_b)``
of every plane with every pair are one table (two matrix products), from which
each triple's determinant, its inverse's columns and every plane's rate along
them are read off. Which loads a cone holds is read from a second table: for
a few hundred candidate Farkas directions (``-g``; ``-g`` less its part along
each load; the normals of the planes two loads span, both ways: the directions
the least-squares residual of ``-g`` from any cone of loads can take), the set
of loads each excludes, as a bit mask; a set of loads is excluded when one
direction's mask holds it (one bitwise test per pair). When no forces at all
balance the load (every load excluded) no twist is needed to say so; for either
"no motion", a vertex (or the least-squares twist of the gap rows) that keeps
every contact closed or opening to within round-off tells
:func:`~.diagnose.diagnose` that no kinematic certificate exists (none with
multipliers below :data:`~quasistatic.tolerances.KINEMATIC_MULTIPLIERS`, all
its LP accepts), so it skips that LP (:func:`~.diagnose.admits_no_multipliers`). Without
Lemke's point, the held vertex best computed becomes the seed when its twist
with non-negative least-squares forces on its loads satisfies every law of the
form (:func:`~.cheap.satisfies_form`, as Lemke's point is checked). Anything
else (a held triple far from its group's motion, groups too close, a ray not
excluded, normals that do not span R^3, more than :data:`ARRANGEMENT_CONTACTS`
contacts) proves nothing here, and the branch and bound runs as before.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from ...laws.polyhedral import LCPForm
from ...tolerances import ARRANGEMENT_CONTACTS, ARRANGEMENT_ROUNDOFF, DISTINCT_TWIST, FORCE_CEILING, LP_FEASIBILITY, ZERO
from ..numerics.optimize import nnls
from .arrangement_floats import CLAIMS, EDGE_BIT_VALUES, seed_is_only_motion
from .cheap import satisfies_form
from .diagnose import admits_no_multipliers

__all__ = [
    "VertexVerdict",
    "VertexProof",
    "prove_by_vertices",
    "motion_vertex",
    "VERTEX_PROOF",
    "NO_VERTEX_PROOF",
    "VERTEX_LISTING_PROOF",
    "EDGE_BITS",
    "CLAIM_LOOSENESS",
    "CLAIM_REACH",
    "triple_columns",
]

VERTEX_PROOF = (
    "the found twist is the only motion vertex of the contacts' twist planes and no motion edge leaves it "
    "(vertex certificate: 3x3 solves and checked Farkas vectors)"
)
VERTEX_LISTING_PROOF = (
    "every motion vertex of the contacts' twist planes listed, no motion edge leaving any of them "
    "(vertex certificate: 3x3 solves and checked Farkas vectors)"
)
NO_VERTEX_PROOF = "no vertex of the contacts' twist planes holds a motion (vertex certificate: 3x3 solves and checked Farkas vectors)"


class VertexVerdict(Enum):
    UNIQUE = "unique"  # every motion is the seed's twist
    NONE = "none"  # no motion at all
    ENUMERATED = "enumerated"  # several isolated motions, every one of them listed in ``motions``
    UNDECIDED = "undecided"  # not applicable, a continuum, or too close to call: the branch and bound decides


@dataclass(frozen=True)
class VertexProof:
    """The verdict; for ``NONE``, whether equilibrium exists with every load (True: a balancing fit, False: a
    checked Farkas vector, None: neither), as :class:`~.patterns.PatternProof` says it; the triples solved; for
    ``UNIQUE``, the only motion (the caller's seed, or without one the vertex's, checked on every law of the form);
    for ``ENUMERATED``, every motion, each checked the same way (the seed's first)."""

    verdict: VertexVerdict
    equilibrium: bool | None = None
    triples: int = 0
    seed: np.ndarray | None = None  # for ``UNIQUE``: the motion, a point ``[q, cn, beta, lam]`` of the form (checked)
    motions: tuple[np.ndarray, ...] = ()  # for ``ENUMERATED``: each motion as a point of the form (checked)
    admissible: bool = False  # for ``NONE``: a vertex keeps every contact closed or opening, to round-off (no kinematic certificate)


_UNDECIDED = VertexProof(VertexVerdict.UNDECIDED)


@dataclass(frozen=True)
class _Planes:
    """The arrangement: ``normals`` (P, 3) and ``rhs`` (P,), gap rows first (one per contact), then the slip rows
    of the frictional contacts (``frictional``: which contacts); ``crosses`` (P, P, 3): ``n_a x n_b``; ``triple``
    (P, P * P): ``n_p . (n_a x n_b)`` at column ``a P + b``; ``loads`` (3, 2 m): a unit normal force on each
    contact's edge ``+t`` (column ``2 i``) and ``-t`` (``2 i + 1``)."""

    normals: np.ndarray
    rhs: np.ndarray
    frictional: np.ndarray
    crosses: np.ndarray
    triple: np.ndarray
    loads: np.ndarray

    longest: float  # the longest normal's length
    largest_offset: float  # the largest |rhs|
    dependent: float  # three normals whose determinant is at most this are dependent: round-off of the longest's cube

    @property
    def flat_crosses(self) -> np.ndarray:
        """(P * P, 3): ``n_a x n_b`` at ``a P + b``."""
        return self.crosses.reshape(-1, 3)

    @property
    def m(self) -> int:
        return int(self.frictional.size)


def prove_by_vertices(form: LCPForm, seed_x: np.ndarray | None, max_solutions: int | None = None) -> VertexProof:
    """Whether the only motion of the planar laws ``form`` is the twist of ``seed_x`` (a point ``[q, cn, beta, lam]``
    every law of the form holds at, checked by the caller), or no motion exists, or the motions are isolated twists
    (at most ``max_solutions`` of them), each listed; see the module docstring. The seed's claim on a few planes is
    tried in Python floats first (:mod:`.arrangement_floats`); anything it does not prove runs here from the start."""
    triples = None if seed_x is None else seed_is_only_motion(form, seed_x[:3].tolist())
    if triples is not None and seed_x is not None:
        return VertexProof(VertexVerdict.UNIQUE, None, triples, seed_x)
    arrangement = _arrangement(form)
    if arrangement is None:
        return _UNDECIDED
    planes, excluded = arrangement
    vertices = _vertices(planes)
    if excluded.every_load():  # no forces balance the load at all, whatever the twist
        return _UNDECIDED if seed_x is not None else VertexProof(VertexVerdict.NONE, False, admissible=_admissible(planes, vertices))
    if vertices is None:
        return _UNDECIDED  # the normals do not span R^3: every motion lies on a line of motions
    held = (~excluded.excludes(_load_masks(planes, vertices.signs))).nonzero()[0]  # (methods: numpy's wrappers cost more here)
    if not held.size:
        if seed_x is not None:
            return _UNDECIDED  # a checked motion, yet every vertex excluded: too close to call
        return VertexProof(VertexVerdict.NONE, excluded.equilibrium(), vertices.count, admissible=_admissible(planes, vertices))
    seed_x = seed_x if seed_x is not None else _vertex_point(form, planes, vertices, held)
    if seed_x is not None and _near_seed(vertices, held, seed_x[:3]):  # one motion, if no edge leaves it
        if not _edges_excluded(planes, vertices, held, excluded):
            return _UNDECIDED
        return VertexProof(VertexVerdict.UNIQUE, None, vertices.count, seed_x)
    clusters = _clusters(vertices, held)
    if len(clusters) == 1:
        return _UNDECIDED  # one group, not near its motion: too close to call
    if max_solutions is not None and len(clusters) > max_solutions:
        return _UNDECIDED  # more motions than asked for: the branch and bound (and SCIP) say so
    motions = _listed(form, planes, vertices, clusters, seed_x)
    if motions is None or not _edges_excluded(planes, vertices, held, excluded, _apart(vertices, clusters)):
        return _UNDECIDED
    return VertexProof(VertexVerdict.ENUMERATED, None, vertices.count, motions[0], motions)


def motion_vertex(form: LCPForm) -> np.ndarray | None:
    """One motion of the planar laws ``form`` at a vertex of the arrangement, as a point ``[q, cn, beta, lam]``
    checked on every law of the form, or None (no vertex holds one that passes the check: the caller decides).

    For the fast path, which wants any motion: the vertices not excluded are tried best computed first (least
    ``|N_T^-1|_1``). No uniqueness is claimed; when the normals span R^3 every motion face has a motion vertex.
    """
    arrangement = _arrangement(form)
    if arrangement is None:
        return None
    planes, excluded = arrangement
    vertices = None if excluded.every_load() else _vertices(planes)
    if vertices is None:
        return None
    held = np.flatnonzero(~excluded.excludes(_load_masks(planes, vertices.signs)))
    for vertex in held[np.argsort(vertices.spread[held].max(axis=1), kind="stable")]:
        point = _vertex_point(form, planes, vertices, np.array([vertex]))
        if point is not None:
            return point
    return None


def _arrangement(form: LCPForm) -> tuple[_Planes, _Exclusions] | None:
    """The planes of ``form`` and the Farkas directions that exclude loads, or None where the vertex certificate does
    not apply: anything but one planar body with two edges a contact and 1 to ``ARRANGEMENT_CONTACTS`` contacts."""
    problem = form.problem
    if problem.dimension != 2 or form.n_q != 3 or form.n_edges != 2 or not 0 < problem.n_contacts <= ARRANGEMENT_CONTACTS:
        return None
    planes = _planes(problem.J, problem.b, problem.mu)
    return planes, _Exclusions.of(planes.loads, problem.g)


def _planes(J: np.ndarray, b: np.ndarray, mu: np.ndarray) -> _Planes:
    """The planes of the planar laws ``J`` (m, 2, 3), ``b`` (m, 2) (tangent row, then normal), friction ``mu``."""
    frictional = mu > 0.0
    Jt, Jn = J[:, 0], J[:, 1]
    normals = np.concatenate((Jn, Jt[frictional]))
    crosses = _all_crosses(normals)
    P = normals.shape[0]
    triple = normals @ crosses.reshape(P * P, 3).T
    longest = math.sqrt(float(np.einsum("pj,pj->p", normals, normals).max()))
    rhs = np.concatenate((b[:, 1], b[frictional, 0]))
    offset = float(np.abs(rhs).max())
    loads = _loads(Jn, mu[:, None] * Jt)
    return _Planes(normals, rhs, frictional, crosses, triple, loads, longest, offset, ARRANGEMENT_ROUNDOFF * longest**3)


def _all_crosses(vectors: np.ndarray) -> np.ndarray:
    """(k, k, 3): ``u_a x u_b`` for every pair of the rows ``u`` of ``vectors`` (k, 3), in two matrix products:
    ``u_a x v = S_a v`` with ``S_a = sum_j u_a[j] EPSILON[j]`` (the Levi-Civita symbol)."""
    k = vectors.shape[0]
    return np.ascontiguousarray(((vectors @ _EPSILON).reshape(k * 3, 3) @ vectors.T).reshape(k, 3, k).transpose(0, 2, 1))


def _loads(Jn: np.ndarray, friction: np.ndarray) -> np.ndarray:
    """(3, 2 m): the edges ``n + mu t`` and ``n - mu t`` of each contact, as patterns.py orders them."""
    loads = np.empty((3, 2 * Jn.shape[0]))
    loads[:, 0::2] = (Jn + friction).T
    loads[:, 1::2] = (Jn - friction).T
    return loads


def _levi_civita() -> np.ndarray:
    """(3, 9): row ``j``, column ``3 i + k``: the Levi-Civita symbol ``eps_ijk``, so ``(n @ E)[3 i + k]`` is ``[n]_x``."""
    epsilon = np.zeros((3, 3, 3))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        epsilon[j, i, k], epsilon[j, k, i] = 1.0, -1.0
    return epsilon.reshape(3, 9)


_EPSILON = _levi_civita()


@dataclass(frozen=True)
class _Vertices:
    """The vertices ``w`` (V, 3) of the independent triples whose gap rows are not below their margin; ``signs``
    (V, P): each plane's sign there, 0 where it is near (see the module docstring) at ``tau = LP_FEASIBILITY``;
    ``margin`` (V, P): how near a plane's row must be to 0 for that; ``spread`` (V, 3): ``|N_T^-1|_1`` per twist entry,
    and ``slack`` (V,) the triple's own round-off (of its rows at ``w``, and of the exact vertex's rows)."""

    w: np.ndarray
    signs: np.ndarray
    margin: np.ndarray
    spread: np.ndarray
    slack: np.ndarray
    count: int


@functools.cache
def triple_columns(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Every triple ``i < j < k`` of ``count`` indices, (T, 3), and the columns of :attr:`_Planes.triple` of its
    adjugate's rows ``n_j x n_k``, ``n_k x n_i``, ``n_i x n_j`` (3, T)."""
    triples = np.array(list(itertools.combinations(range(count), 3)), dtype=np.intp).reshape(-1, 3)
    i, j, k = triples.T
    return triples, np.stack([j * count + k, k * count + i, i * count + j])


def _vertices(planes: _Planes) -> _Vertices | None:
    """Every vertex of the arrangement (one per independent triple) in loose ``Q0``, or None when no triple is
    independent (the normals do not span R^3).

    With ``X_k`` the adjugate's rows (cross products of the other two normals), ``N_T^-1 = [X_0 X_1 X_2] / det``,
    so each plane's rate along ``N_T^-1``'s columns is a triple product ``n_p . X_k / det``, read off a table.
    The round-off of a vertex's rows, ``ARRANGEMENT_ROUNDOFF (|n| |w|_1 + |r|)`` at the longest normal and
    largest offset, is added to its margin, and to the margin's ``tau``."""
    rhs, m = planes.rhs, planes.m
    P = rhs.size
    if P < 3:
        return None
    triples, columns = triple_columns(P)
    det = planes.triple[triples[:, 0], columns[0]]
    independent = np.abs(det) > planes.dependent
    if not independent.all():
        if not independent.any():
            return None
        triples, columns, det = triples[independent], columns[:, independent], det[independent]
    products = planes.triple[:, columns] / det  # (P, 3, T): n_p . N_T^-1[:, k]
    r = rhs[triples].T  # (3, T)
    rows = np.einsum("pkt,kt->pt", products, r) - rhs[:, None]
    w = np.einsum("kt,ktj->tj", r, planes.flat_crosses[columns]) / det[:, None]
    slack = ARRANGEMENT_ROUNDOFF * (planes.longest * np.abs(w).sum(axis=1) + planes.largest_offset)
    near = (LP_FEASIBILITY + slack) * (1.0 + np.abs(products).sum(axis=1)) + slack
    signs = (rows > near).view(np.int8) - (rows < -near).view(np.int8)
    kept = (signs[:m] >= 0).all(axis=0)  # loose Q0
    spread = np.abs(planes.flat_crosses[columns[:, kept]]).sum(axis=0) / np.abs(det[kept, None])  # sum_k |N_T^-1[j, k]|
    return _Vertices(w[kept], signs[:, kept].T, near[:, kept].T, spread, slack[kept], int(det.size))


def _load_masks(planes: _Planes, signs: np.ndarray) -> np.ndarray:
    """Per sign vector (rows of ``signs``, 0 on every near plane), the loads its contacts may use, as bit masks
    (load ``k``, bit ``k``): a closed contact's two bits ``b = 1`` (``+t``, sliding +), ``2`` (``-t``) or ``3``."""
    m = planes.m
    if signs.shape[1] == 2 * m:  # every contact has friction
        slip = signs[:, m:]
    else:
        slip = np.zeros((signs.shape[0], m), dtype=np.int8)
        slip[:, planes.frictional] = signs[:, m:]
    bits = EDGE_BITS[slip + 1] * (signs[:, :m] == 0)  # integers throughout: no float round trip
    return bits @ _weights(m)


EDGE_BITS = np.array(EDGE_BIT_VALUES, dtype=np.uint64)  # by slip sign -1, 0, +1: the edge n + mu t, both, the edge n - mu t


@functools.cache
def _weights(m: int) -> np.ndarray:
    """``4^i`` for each of ``m`` contacts (exact in 64 bits up to 32 contacts)."""
    return np.uint64(4) ** np.arange(m, dtype=np.uint64)


@dataclass(frozen=True)
class _Exclusions:
    """Candidate Farkas directions ``y`` and, per direction, the loads it excludes (``blocked``, bit masks): ``y``
    excludes a set ``S`` of loads when ``-g.y - margin |y| > max(G_S^T y, 0) FORCE_CEILING`` (as
    :mod:`.patterns` checks its vectors), i.e. when ``S`` lies in the mask."""

    loads: np.ndarray
    g: np.ndarray
    blocked: np.ndarray

    @classmethod
    def of(cls, loads: np.ndarray, g: np.ndarray) -> _Exclusions:
        count = loads.shape[1]
        columns = loads.T
        i, j = _pairs(count)
        normals = _all_crosses(columns)[i, j]  # of the planes two loads span
        square = np.einsum("kj,kj->k", columns, columns)
        along = -g - ((columns @ -g) / np.maximum(square, 1e-300))[:, None] * columns  # -g less its part along a load
        directions = np.concatenate((-g[None, :], along, normals, -normals))
        reserve = directions @ -g - _margin(g) * np.sqrt(np.einsum("yj,yj->y", directions, directions))
        useful = reserve > 0.0
        blocked = (directions[useful] @ loads) * FORCE_CEILING < reserve[useful, None]
        return cls(loads, g, blocked @ _bits(count))

    def excludes(self, masks: np.ndarray) -> np.ndarray:
        """Whether a direction excludes each set of loads (bit masks)."""
        return ((masks[:, None] & ~self.blocked[None, :]) == 0).any(axis=1)

    def every_load(self) -> bool:
        """Whether a direction excludes every load at once: no forces at all balance the load."""
        every = np.uint64(2 ** self.loads.shape[1] - 1)
        return bool(((every & ~self.blocked) == 0).any())

    def equilibrium(self) -> bool | None:
        """With every load: False when excluded, True when a non-negative fit balances the load to the margin, None
        otherwise (the caller's LP decides), as the branch and bound's root says it."""
        if self.every_load():
            return False
        _, residual = nnls(self.loads, -self.g)
        return True if residual <= _margin(self.g) else None


@functools.cache
def _bits(count: int) -> np.ndarray:
    """``2^k`` for each of ``count`` loads, as 64-bit integers (a mask of booleans in one product)."""
    return np.uint64(1) << np.arange(count, dtype=np.uint64)


@functools.cache
def _pairs(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Every pair ``i < j`` of ``count`` indices."""
    return np.triu_indices(count, 1)


def _margin(g: np.ndarray) -> float:
    """How far from the load a balancing fit may be (``LP_FEASIBILITY`` per row) [-]."""
    return math.sqrt(g.size) * LP_FEASIBILITY


CLAIM_LOOSENESS = np.array([tau for tau, _ in CLAIMS])  # the tau of each claim on the twist
CLAIM_REACH = np.array([reach for _, reach in CLAIMS])  # and how near the seed it puts them
_LOOSENESS = CLAIM_LOOSENESS[:, None, None]


def _vertex_point(form: LCPForm, planes: _Planes, vertices: _Vertices, held: np.ndarray) -> np.ndarray | None:
    """Without Lemke's point: the held vertex best computed (least ``|N_T^-1|_1``), with non-negative forces on its
    loads (least squares), as a point ``[q, cn, beta, lam]`` of the form when every law of the form holds there
    (:func:`~.cheap.satisfies_form`, as Lemke's point is checked), else None."""
    best = held[np.argmin(vertices.spread[held].max(axis=1))]
    q = vertices.w[best]
    mask = int(_load_masks(planes, vertices.signs[best : best + 1])[0])
    allowed = np.array([(mask >> k) & 1 for k in range(planes.loads.shape[1])], dtype=bool)
    fit = np.zeros(allowed.size)
    fit[allowed], _ = nnls(planes.loads[:, allowed], -form.problem.g)
    m = planes.m
    per_edge = fit.reshape(m, 2)
    slip = form.problem.Jt[:, 0, :] @ q - form.problem.bt[:, 0]
    x = np.concatenate([q, per_edge.sum(axis=1), (form.problem.mu[:, None] * per_edge).ravel(), np.abs(slip)])
    pairs = x[3:]  # forces and slip speeds, all >= 0: round-off to exact zeros, as Lemke's pivots leave them
    pairs[pairs <= ZERO] = 0.0
    return x if satisfies_form(form, x) else None


def _admissible(planes: _Planes, vertices: _Vertices | None) -> bool:
    """Whether a computed vertex ``w``, or else the least-squares twist of the gap rows (where the normals do not span
    R^3 there are no vertices), meets every gap row near enough to rule out every kinematic certificate
    (:func:`~.diagnose.admits_no_multipliers`)."""
    if vertices is not None and vertices.w.shape[0] and _admits(planes, vertices.w):
        return True
    m = planes.m
    return _admits(planes, np.linalg.lstsq(planes.normals[:m], planes.rhs[:m])[0][None, :])


def _admits(planes: _Planes, twists: np.ndarray) -> bool:
    """:func:`~.diagnose.admits_no_multipliers` for the one of ``twists`` (V, 3) least below a gap row: each twist is
    a point of its own, whose gap rates are known to their evaluation's round-off ``ARRANGEMENT_ROUNDOFF (|n| |w|_1 +
    |r|)``, and may fall below 0 by round-off only."""
    m = planes.m
    normals, rhs = planes.normals[:m], planes.rhs[:m]
    gaps = normals @ twists.T - rhs[:, None]  # (m, V)
    error = ARRANGEMENT_ROUNDOFF * (planes.longest * np.abs(twists).sum(axis=1) + np.abs(rhs[:, None]))
    best = int(np.argmin((error - gaps).max(axis=0)))
    return admits_no_multipliers(gaps[:, best], twists[best], error[:, best])


def _near_seed(vertices: _Vertices, held: np.ndarray, q: np.ndarray) -> bool:
    """Whether every vertex not excluded is the seed's twist ``q``, with the loose twists near it: within
    ``SAME_TWIST / 2`` exactly, ``DISTINCT_TWIST / 2`` at ``tau = ZERO`` and ``DISTINCT_TWIST`` at ``LP_FEASIBILITY``."""
    offset = np.abs(vertices.w[held] - q)
    reach = offset + (_LOOSENESS + vertices.slack[held, None]) * vertices.spread[held]  # (3, H, 3)
    return bool((reach.max(axis=(1, 2)) <= CLAIM_REACH).all())


def _edges_excluded(planes: _Planes, vertices: _Vertices, held: np.ndarray, excluded: _Exclusions, apart: float | None = None) -> bool:
    """Whether every ray leaving the vertices ``held`` (each a sign vector, 0 on its near planes), along a line where
    two near planes meet and kept in loose ``Q0``, has its loads excluded. A rate along a plane within round-off of
    the longest normals' (``ARRANGEMENT_ROUNDOFF`` of their cube) is taken as 0: it only adds loads.

    With ``apart`` (several motions, their vertices at least this far apart): a rate along a near plane ``p`` below
    ``2 margin_p / apart`` per unit length is taken as 0 too, so that every edge of a loose cell from one motion's
    vertices to another's is held by a ray checked here (see the module docstring); ``apart <= 0`` proves nothing."""
    if apart is not None and apart <= 0.0:
        return False
    P, m = planes.rhs.size, planes.m
    signs = vertices.signs[held]
    masks = []
    for key, sign in _by_sign(signs):
        near = (sign == 0).nonzero()[0]
        i, j = _pairs(near.size)
        pair = near[i] * P + near[j]
        lines = planes.flat_crosses[pair]
        squares = np.einsum("lj,lj->l", lines, lines)
        kept = squares > planes.dependent**2 / planes.longest**2  # not parallel
        pair = pair[kept]
        along = planes.triple[near[:, None], pair].T  # (L, k): n_p . (n_a x n_b), p near
        zero: np.ndarray | float = planes.dependent
        if apart is not None:
            rate = 2.0 * vertices.margin[held[key]][:, near].max(axis=0) / apart  # (k,): per unit length
            zero = np.maximum(planes.dependent, np.sqrt(squares[kept])[:, None] * rate[None, :])
        along[np.abs(along) <= zero] = 0.0
        rays = np.concatenate((along, -along))
        rays = rays[(rays[:, near < m] >= 0.0).all(axis=1)]  # no near gap row falls along it
        ray_signs = sign[None, :].repeat(rays.shape[0], axis=0)
        ray_signs[:, near] = np.sign(rays)
        masks.append(_load_masks(planes, ray_signs))
    return bool(excluded.excludes(np.concatenate(masks)).all())


def _by_sign(signs: np.ndarray) -> list[tuple[list[int], np.ndarray]]:
    """The distinct rows of ``signs``, each with the indices of the rows equal to it."""
    groups: dict[bytes, tuple[list[int], np.ndarray]] = {}
    for k, row in enumerate(signs):
        groups.setdefault(row.tobytes(), ([], row))[0].append(k)
    return list(groups.values())


def _clusters(vertices: _Vertices, held: np.ndarray) -> list[np.ndarray]:
    """The vertices ``held`` grouped by twist, best computed (least ``|N_T^-1|_1``) first: each joins the first group
    whose first vertex is within ``DISTINCT_TWIST`` of it (each group is checked against its motion by
    :func:`_near_seed`, and the groups' separation by :func:`_apart`)."""
    order = held[np.argsort(vertices.spread[held].max(axis=1), kind="stable")]
    heads: list[np.ndarray] = []
    members: list[list[int]] = []
    for v in order.tolist():
        for head, group in zip(heads, members, strict=True):
            if np.max(np.abs(vertices.w[v] - head)) <= DISTINCT_TWIST:
                group.append(v)
                break
        else:
            heads.append(vertices.w[v])
            members.append([v])
    return [np.array(group, dtype=np.intp) for group in members]


def _listed(
    form: LCPForm, planes: _Planes, vertices: _Vertices, clusters: list[np.ndarray], seed_x: np.ndarray | None
) -> tuple[np.ndarray, ...] | None:
    """One checked motion per group of vertices, every group's vertices near it (:func:`_near_seed`), the seed's
    group first (with the seed itself), else None: too close to call."""
    points: list[np.ndarray] = []
    for cluster in clusters:
        if seed_x is not None and _near_seed(vertices, cluster, seed_x[:3]):
            points.insert(0, seed_x)
            seed_x = None
            continue
        point = _vertex_point(form, planes, vertices, cluster)
        if point is None or not _near_seed(vertices, cluster, point[:3]):
            return None
        points.append(point)
    return None if seed_x is not None else tuple(points)  # a seed in no group: too close to call


def _apart(vertices: _Vertices, clusters: list[np.ndarray]) -> float:
    """How far apart (Euclidean) any two loose cell vertices near two different groups at least are: the least
    distance between the groups' vertices, less each loose box's diagonal (``(tau + slack) |N_T^-1|_1`` per entry
    at ``tau = LP_FEASIBILITY``)."""
    radius = np.sqrt(3.0) * ((LP_FEASIBILITY + vertices.slack)[:, None] * vertices.spread).max(axis=1)
    least = math.inf
    for a, b in itertools.combinations(clusters, 2):
        distance = np.linalg.norm(vertices.w[a][:, None, :] - vertices.w[b][None, :, :], axis=2)
        least = min(least, float((distance - radius[a][:, None] - radius[b][None, :]).min()))
    return least
