"""The certified decision of many planar one-body problems of one shape at once (a sweep's chunk).

Why batched: on a small planar scene the certified solve is ~100 numpy calls on arrays of a few entries, so its
time is Python's per-call overhead, not arithmetic. A sweep's points share their shape (one body, the same
contacts, the same frictional ones), so every array of :mod:`.arrangement`'s vertex certificate gains a leading
point axis and one numpy call serves the whole chunk.

What is decided here, per point, is only the certified solve's usual answer on such scenes, and only by the same
proof: Lemke's point (the same compiled kernel on the same numbers as :func:`~.cheap.seed_point`, then checked on
every law of the form to ``ZERO``), not kinematically unique (at most three closed contacts, so
:func:`~.cheap.kinematically_unique` has no bound), and the vertex certificate's claim 2 (:mod:`.arrangement`: every
vertex not excluded is the seed's, and every ray leaving them has its loads excluded by a checked Farkas
direction), with the same tolerances. Then the motion's forces are unique by the plane's rank test (the first test
of :func:`~..numerics.forces.indeterminate_forces`). Anything else (no seed, a kinematic bound to try, vertices near
another twist, a ray not excluded, forces that may vary) leaves the point undecided, and the caller solves it alone.

Rounding. The twist and forces are Lemke's, bit for bit. The seed's check, the closed count and the rank test sum
their products in another order than the per-point code, so a value within ``BATCH_TIE`` of one of their thresholds
(either side) leaves the point undecided: its side could differ there. The vertex certificate's comparisons are not
guarded: its margins are a proof under any rounding of its 3x3 solves within ``ARRANGEMENT_ROUNDOFF``, so a point it
proves here has Lemke's twist as its only motion; were one of the per-point certificate's own comparisons to land
the other way at a tie, that solve goes on to the branch and bound, which proves the same answer (a sweep's record
does not say which certificate proved it). The cross-checks of ``tests/test_sweep_batch.py`` compare the records.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...laws.stacked import StackedLaws
from ...model.kinematics import cross
from ...tolerances import (
    ARRANGEMENT_ROUNDOFF,
    BATCH_TIE,
    FORCE_CEILING,
    FORCE_RANK,
    LP_FEASIBILITY,
    MODE_SPEED,
    MOVING,
    PIVOT,
    ZERO,
)
from ..numerics.lcp import PIVOTS_PER_ROW, PLANAR_EDGES, split_lcp_points
from ..numerics.lemke import SOLUTION
from .arrangement import CLAIM_LOOSENESS, CLAIM_REACH, EDGE_BITS, triple_columns

__all__ = ["BatchedMotions", "certify_batch"]

_LOOSENESS = CLAIM_LOOSENESS[:, None, None, None]  # the vertex certificate's claims, with a point axis
_WITHIN = CLAIM_REACH[:, None, None]


@dataclass(frozen=True)
class BatchedMotions:
    """Per point: ``decided`` (N,) the proof went through; there ``q`` (N, 3) is the only motion's scene-relative
    twist (Lemke's, bit for bit), ``c`` (N, m, 2) its contact-frame forces (tangent, normal) and ``indeterminate``
    (N,) whether other forces balance it too (then ``c`` is one of them, as the per-point solve reports)."""

    decided: np.ndarray
    q: np.ndarray
    c: np.ndarray
    indeterminate: np.ndarray


def certify_batch(laws: StackedLaws) -> BatchedMotions:
    """Decide what can be decided of every point of ``laws`` (every point with the same frictional contacts)."""
    q, cn, beta, lam, seeded = _seeds(laws)
    decided = seeded & _form_holds(laws, q, cn, beta, lam) & _few_closed(laws, q)
    if decided.any():
        decided &= _vertex_proof(laws, q, decided)
    unique = indeterminate = np.zeros(decided.size, dtype=bool)
    c = np.stack([beta[..., 0] - beta[..., 1], cn], axis=-1)  # as LCPForm.forces: the edges +1 and -1
    if decided.any():
        unique, indeterminate = _force_claims(laws, q, c)
    return BatchedMotions(decided & (unique | indeterminate), q, c, indeterminate)


def _seeds(laws: StackedLaws) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Lemke's point of each problem by the kernel :func:`~.cheap.seed_point` runs, on the same contiguous numbers."""
    N, m = laws.mu.shape
    J, b, mu, g = (np.ascontiguousarray(a, dtype=float) for a in (laws.J, laws.b, laws.mu, laws.g))
    frictional = np.flatnonzero(mu[0] > 0.0)
    f = frictional.size
    statuses, z = split_lcp_points(J, b, mu, g, frictional, PLANAR_EDGES, PIVOT, PIVOTS_PER_ROW)
    seeded = statuses == SOLUTION
    q = z[:, :3] - z[:, 3:6]
    cn = z[:, 6 : 6 + m].copy()
    beta, lam = np.zeros((N, m, 2)), np.zeros((N, m))
    beta[:, frictional] = z[:, 6 + m : 6 + m + 2 * f].reshape(N, f, 2)
    lam[:, frictional] = z[:, 6 + m + 2 * f :]
    slip = _rows(laws.J[..., 0, :], q) - laws.b[..., 0]
    frictionless = mu[0] <= 0.0
    lam[:, frictionless] = np.abs(slip[:, frictionless])  # the least slip speed its edges accept (cheap._form_point)
    return q, cn, beta, lam, seeded


def _rows(A: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``A q`` for rows ``A`` (N, m, 3) and twists ``q`` (N, 3)."""
    return A[..., 0] * q[:, None, 0] + A[..., 1] * q[:, None, 1] + A[..., 2] * q[:, None, 2]


def _clear(values: np.ndarray, threshold: float) -> np.ndarray:
    """Whether ``values`` are clear of ``threshold`` (outside a factor ``BATCH_TIE`` of it): their side of it cannot
    depend on rounding. Per point (the last axes reduced)."""
    size = np.abs(values)
    near = (size > threshold / BATCH_TIE) & (size <= threshold * BATCH_TIE)
    return ~near.reshape(near.shape[0], -1).any(axis=1)


def _form_holds(laws: StackedLaws, q: np.ndarray, cn: np.ndarray, beta: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """:func:`~.cheap.satisfies_form` per point: equilibrium, signs and complementarity to ``ZERO``, clear of it."""
    Jt, Jn = laws.J[..., 0, :], laws.J[..., 1, :]
    tangential = beta[..., 0] - beta[..., 1]
    equilibrium = (cn[..., None] * Jn + tangential[..., None] * Jt).sum(axis=1) + laws.g
    slip = _rows(Jt, q) - laws.b[..., 0]
    w = np.concatenate(
        (
            _rows(Jn, q) - laws.b[..., 1],
            (np.stack([slip, -slip], axis=-1) + lam[..., None]).reshape(q.shape[0], -1),
            laws.mu * cn - beta.sum(axis=2),
        ),
        axis=1,
    )
    pairs = np.concatenate((cn, beta.reshape(q.shape[0], -1), lam), axis=1)
    signs = np.minimum(pairs.min(axis=1, initial=0.0), w.min(axis=1, initial=0.0))
    complementarity = np.minimum(np.abs(pairs), np.abs(w))
    holds = (np.abs(equilibrium).max(axis=1) <= ZERO) & (signs >= -ZERO) & (complementarity.max(axis=1) <= ZERO)
    clear = _clear(equilibrium, ZERO) & _clear(np.minimum(pairs, 0.0), ZERO) & _clear(np.minimum(w, 0.0), ZERO)
    return holds & clear & _clear(complementarity, ZERO)


def _few_closed(laws: StackedLaws, q: np.ndarray) -> np.ndarray:
    """At most three contacts closed at ``q`` (to ``MODE_SPEED``): then no Gordan bound exists (more rows than the
    twist's three are needed) and the certified solve goes on to the vertex certificate, as here."""
    gap = _rows(laws.J[..., 1, :], q) - laws.b[..., 1]
    return ((np.abs(gap) <= MODE_SPEED).sum(axis=1) <= 3) & _clear(gap, MODE_SPEED)


@dataclass(frozen=True)
class _Planes:
    """Every point's arrangement (:mod:`.arrangement`'s ``_Planes`` with a leading axis): ``normals`` (N, P, 3),
    ``rhs`` (N, P), ``crosses`` (N, P * P, 3), ``triple`` (N, P, P * P), ``loads`` (N, 3, 2 m), ``longest``,
    ``offset``, ``dependent`` (N,), ``m`` contacts and ``frictional`` (f,)."""

    normals: np.ndarray
    rhs: np.ndarray
    crosses: np.ndarray
    triple: np.ndarray
    loads: np.ndarray
    longest: np.ndarray
    offset: np.ndarray
    dependent: np.ndarray
    m: int
    frictional: np.ndarray


def _planes(laws: StackedLaws, points: np.ndarray) -> _Planes:
    """The arrangement of each of ``points`` (indices into the stack)."""
    frictional = np.flatnonzero(laws.mu[0] > 0.0)
    J, b, mu = laws.J[points], laws.b[points], laws.mu[points]
    Jt, Jn = J[..., 0, :], J[..., 1, :]
    normals = np.concatenate((Jn, Jt[:, frictional]), axis=1)
    N, P = normals.shape[:2]
    crosses = cross(normals[:, :, None, :], normals[:, None, :, :]).reshape(N, P * P, 3)
    triple = np.matmul(normals, crosses.transpose(0, 2, 1))
    longest = np.sqrt((normals * normals).sum(axis=2).max(axis=1))
    rhs = np.concatenate((b[..., 1], b[:, frictional, 0]), axis=1)
    friction = mu[..., None] * Jt
    loads = np.empty((N, 3, 2 * Jn.shape[1]))
    loads[:, :, 0::2] = (Jn + friction).transpose(0, 2, 1)
    loads[:, :, 1::2] = (Jn - friction).transpose(0, 2, 1)
    dependent = ARRANGEMENT_ROUNDOFF * longest**3
    return _Planes(normals, rhs, crosses, triple, loads, longest, np.abs(rhs).max(axis=1), dependent, Jn.shape[1], frictional)


@dataclass(frozen=True)
class _Exclusions:
    """Candidate Farkas directions per point and the loads each excludes (``blocked``, (N, D) bit masks; a direction
    that is no Farkas direction for that point, ``useful`` False, excludes nothing)."""

    blocked: np.ndarray
    useful: np.ndarray
    count: int

    @classmethod
    def of(cls, loads: np.ndarray, g: np.ndarray) -> _Exclusions:
        count = loads.shape[2]
        columns = loads.transpose(0, 2, 1)  # (N, 2m, 3)
        i, j = np.triu_indices(count, 1)
        normals = cross(columns[:, i], columns[:, j])
        square = (columns * columns).sum(axis=2)
        toward = (columns * -g[:, None, :]).sum(axis=2) / np.maximum(square, 1e-300)
        along = -g[:, None, :] - toward[..., None] * columns
        directions = np.concatenate((-g[:, None, :], along, normals, -normals), axis=1)
        margin = math.sqrt(3.0) * LP_FEASIBILITY
        reserve = (directions * -g[:, None, :]).sum(axis=2) - margin * np.sqrt((directions * directions).sum(axis=2))
        useful = reserve > 0.0
        blocked = np.matmul(directions, loads) * FORCE_CEILING < reserve[..., None]
        masks = _bit_masks(blocked, 2.0)
        return cls(np.where(useful, masks, np.uint64(0)), useful, count)

    def excludes(self, masks: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Whether a direction of point ``points[k]`` excludes the set of loads ``masks[k]`` (bit masks, (K,))."""
        free = masks[:, None] & ~self.blocked[points]
        return ((free == 0) & self.useful[points]).any(axis=1)

    def every_load(self) -> np.ndarray:
        every = np.uint64(2**self.count - 1)
        return (((every & ~self.blocked) == 0) & self.useful).any(axis=1)


def _bit_masks(flags: np.ndarray, base: float) -> np.ndarray:
    """``sum_k flags[..., k] base^k`` as 64-bit integers (exact in floats: at most 2^16 here)."""
    return np.matmul(flags.astype(float), base ** np.arange(flags.shape[-1], dtype=float)).astype(np.uint64)


def _load_masks(signs: np.ndarray, m: int, frictional: np.ndarray) -> np.ndarray:
    """Bit masks of the loads each sign vector's contacts may use (``signs`` (K, P), 0 on near planes): a closed
    contact's two bits 1 (``+t``, sliding +), 2 (``-t``) or 3 (both), contact ``i`` at ``4^i``."""
    slip = np.zeros((signs.shape[0], m), dtype=np.int8)
    slip[:, frictional] = signs[:, m:]
    return _bit_masks(EDGE_BITS[slip + 1] * (signs[:, :m] == 0), 4.0)


def _vertex_proof(laws: StackedLaws, q: np.ndarray, todo: np.ndarray) -> np.ndarray:
    """The vertex certificate's claim 2 per point: the seed's twist the only motion (see :mod:`.arrangement`)."""
    proven = np.zeros(todo.size, dtype=bool)
    points = np.flatnonzero(todo)
    planes = _planes(laws, points)
    excluded = _Exclusions.of(planes.loads, laws.g[points])
    N, P = planes.rhs.shape
    if P < 3:
        return proven
    triples, columns = triple_columns(P)
    det = planes.triple[:, triples[:, 0], columns[0]]  # (N, T)
    independent = np.abs(det) > planes.dependent[:, None]
    det = np.where(independent, det, 1.0)
    products = planes.triple[:, :, columns] / det[:, None, None, :]  # (N, P, 3, T)
    r = planes.rhs[:, triples]  # (N, T, 3)
    rows = products[:, :, 0] * r[:, None, :, 0] + products[:, :, 1] * r[:, None, :, 1] + products[:, :, 2] * r[:, None, :, 2]
    rows -= planes.rhs[:, :, None]
    adjugate = planes.crosses[:, columns]  # (N, 3, T, 3)
    w = (r[..., 0, None] * adjugate[:, 0] + r[..., 1, None] * adjugate[:, 1] + r[..., 2, None] * adjugate[:, 2]) / det[..., None]
    slack = ARRANGEMENT_ROUNDOFF * (planes.longest[:, None] * np.abs(w).sum(axis=2) + planes.offset[:, None])
    near = (LP_FEASIBILITY + slack[:, None, :]) * (1.0 + np.abs(products).sum(axis=2)) + slack[:, None, :]
    signs = ((rows > near).view(np.int8) - (rows < -near).view(np.int8)).transpose(0, 2, 1)  # (N, T, P)
    kept = independent & (signs[..., : planes.m] >= 0).all(axis=2)
    at, vertex = kept.nonzero()
    loose = ~excluded.excludes(_load_masks(signs[at, vertex], planes.m, planes.frictional), at)
    at, vertex = at[loose], vertex[loose]  # the held vertices (not excluded)
    spread = np.abs(adjugate[at, :, vertex]).sum(axis=1) / np.abs(det[at, vertex])[:, None]  # (H, 3)
    reach = np.abs(w[at, vertex] - q[points[at]]) + (_LOOSENESS[:, :, 0] + slack[at, vertex, None]) * spread  # (3, H, 3)
    far = ~(reach.max(axis=2) <= _WITHIN[:, :, 0]).all(axis=0)
    held = np.zeros(N, dtype=bool)
    held[at] = True
    decided = held & independent.any(axis=1) & ~excluded.every_load() & excluded.useful.any(axis=1)
    decided[at[far]] = False
    decided &= _rays_excluded(planes, excluded, signs[at, vertex], at)
    proven[points] = decided
    return proven


def _rays_excluded(planes: _Planes, excluded: _Exclusions, sign: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Per point, whether every ray leaving a held vertex (its signs ``sign`` (H, P), of point ``at``), along a line
    where two of its near planes meet and kept in loose ``Q0``, has its loads excluded (:mod:`.arrangement`'s
    ``_edges_excluded`` without ``apart``)."""
    N, P = planes.rhs.shape
    a, b = np.triu_indices(P, 1)
    lines = planes.crosses[:, a * P + b]  # (N, Q, 3)
    parallel = ~((lines * lines).sum(axis=2) > (planes.dependent**2 / planes.longest**2)[:, None])
    zero = sign == 0
    valid = zero[:, a] & zero[:, b] & ~parallel[at]  # (H, Q)
    held, line = valid.nonzero()
    along = planes.triple[at[held], :, a[line] * P + b[line]]  # (R, P): each plane's rate along the line
    along[np.abs(along) <= planes.dependent[at[held], None]] = 0.0
    gap_near = zero[held, : planes.m]
    proven = np.ones(N, dtype=bool)
    for direction in (along, -along):
        opening = ((direction[:, : planes.m] >= 0.0) | ~gap_near).all(axis=1)
        ray, vertex = direction[opening], held[opening]
        ray_signs = np.where(zero[vertex], np.sign(ray).astype(np.int8), sign[vertex])
        masks = _load_masks(ray_signs, planes.m, planes.frictional)
        proven[at[vertex[~excluded.excludes(masks, at[vertex])]]] = False
    return proven


def _force_claims(laws: StackedLaws, q: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per point, whether the forces at ``q`` are known unique, and whether known indeterminate (neither: undecided).

    Unique as :func:`~..numerics.forces.indeterminate_forces` first decides it in the plane: the closed contacts'
    force coordinates (a cone's tangent and normal; a frictionless or sliding contact's one tilted normal) with a
    wrench map of full column rank (every singular value above ``FORCE_RANK``). Indeterminate when that test fails and
    a step from Lemke's forces ``c`` (m, 2 per point) along the map's null space, kept in every cone, moves some force
    coordinate by more than ``BATCH_TIE`` times ``LP_FEASIBILITY``: the per-point decision (its segment through a
    balanced point, else an LP or the ranges of every component against ``LP_FEASIBILITY``) then says so too, since
    the set of consistent forces is that wide. Anything else is left undecided."""
    Jt, Jn = laws.J[..., 0, :], laws.J[..., 1, :]
    u_n = _rows(Jn, q) - laws.b[..., 1]
    u_t = _rows(Jt, q) - laws.b[..., 0]
    closed = ~(u_n > MOVING)
    frictional = laws.mu > 0.0
    sliding = closed & (np.abs(u_t) > MOVING) & frictional
    single = ~frictional | sliding
    tilt = np.where(sliding, -laws.mu * np.sign(u_t), 0.0)
    one = Jn + tilt[..., None] * Jt  # (N, m, 3): a frictionless or sliding contact's one force direction
    clear = _clear(u_n, MOVING) & _clear(u_t, MOVING)
    unique, indeterminate = np.zeros(clear.size, dtype=bool), np.zeros(clear.size, dtype=bool)
    m = Jn.shape[1]
    patterns = np.concatenate((closed, single), axis=1)
    for pattern in np.unique(patterns[clear], axis=0):
        members = np.flatnonzero(clear & (patterns == pattern).all(axis=1))
        contacts, alone = np.flatnonzero(pattern[:m]), pattern[m:]
        if not contacts.size:
            unique[members] = True  # no closed contact: no force at all
            continue
        layout = _ForceLayout.of(contacts, alone)
        wrenches = layout.wrenches({"t": Jt, "n": Jn, "one": one}, members)  # (k, 3, f) wrench maps
        sigma = np.linalg.svd(wrenches, compute_uv=False)
        settled = _clear(sigma, FORCE_RANK)
        full = (sigma > FORCE_RANK).all(axis=1) & (wrenches.shape[2] <= 3)
        unique[members] = full & settled
        loose = np.flatnonzero(~full & settled)  # forces that may vary: is a step along them wide?
        if loose.size:
            picked = members[loose]
            _, sigma, vt = np.linalg.svd(wrenches[loose])
            cone = _cones(contacts, alone, laws.mu[picked], layout.normal_at, layout.tangent_at)
            x = _coordinates(c[picked], contacts, layout.normal_at, layout.tangent_at, wrenches.shape[2])
            indeterminate[picked] = _wide(wrenches[loose], laws.g[picked], sigma, vt, x, cone)
    return unique, indeterminate


@dataclass(frozen=True)
class _ForceLayout:
    """The closed contacts' force coordinates in the per-point code's column order: each contact's tangent then normal
    coordinate, or its one tilted normal (``columns``: ``("t" | "n" | "one", contact)``), and where each contact's normal
    and tangent coordinates sit (``tangent_at`` -1 for a single coordinate)."""

    columns: tuple[tuple[str, int], ...]
    normal_at: list[int]
    tangent_at: list[int]

    @staticmethod
    def of(contacts: np.ndarray, alone: np.ndarray) -> _ForceLayout:
        columns: list[tuple[str, int]] = []
        normal_at: list[int] = []
        tangent_at: list[int] = []
        for i in contacts.tolist():  # in contact order, as the per-point columns
            if alone[i]:
                normal_at.append(len(columns))
                tangent_at.append(-1)
                columns.append(("one", i))
            else:
                tangent_at.append(len(columns))
                normal_at.append(len(columns) + 1)
                columns += [("t", i), ("n", i)]
        return _ForceLayout(tuple(columns), normal_at, tangent_at)

    def wrenches(self, rows: dict[str, np.ndarray], members: np.ndarray) -> np.ndarray:
        """The wrench map of ``members`` (k, 3, f): each coordinate's column from ``rows`` (N, m, 3) by its kind."""
        return np.stack([rows[kind][members, i] for kind, i in self.columns], axis=2)


def _wide(wrenches: np.ndarray, g: np.ndarray, sigma: np.ndarray, vt: np.ndarray, x: np.ndarray, cone: _Cones) -> np.ndarray:
    """Whether the forces ``x`` (k, f: each closed contact's coordinates, Lemke's) balance the load, lie in the cones,
    and a step from them along the null space of ``wrenches`` (k, 3, f), kept in every cone, moves some coordinate by
    more than ``BATCH_TIE * LP_FEASIBILITY``: then other forces balance the load too (indeterminate)."""
    k, _, f = wrenches.shape
    balanced = np.abs(np.matmul(wrenches, x[..., None])[..., 0] + g).max(axis=1) <= ZERO / BATCH_TIE
    room = cone.values(x)  # (k, C): each cone side's distance, >= 0 inside
    inside = (room >= -ZERO / BATCH_TIE).all(axis=1)
    room = np.maximum(room, 0.0)
    rank = (sigma > FORCE_RANK).sum(axis=1)
    basis = vt * (np.arange(f)[None, :] >= rank[:, None])[..., None]  # (k, f, f): the rows spanning the null space
    projection = np.matmul(basis.transpose(0, 2, 1), basis)  # (k, f, f): onto the null space
    wide = np.zeros(k, dtype=bool)
    for j in range(f):
        for side in (1.0, -1.0):
            step = side * projection[:, :, j]  # along which coordinate j moves by |projection[j, j]| per unit
            rate = cone.values(step)
            drift = np.abs(np.matmul(wrenches, step[..., None])[..., 0]).max(axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                reach = np.where(rate < 0.0, room / -rate, np.inf).min(axis=1)
                reach = np.minimum(reach, np.where(drift > 0.0, ZERO / drift, np.inf))
                width = np.where(projection[:, j, j] > 0.0, reach * projection[:, j, j], 0.0)  # inf: nothing limits it
            wide |= width > BATCH_TIE * LP_FEASIBILITY
    return balanced & inside & wide


@dataclass(frozen=True)
class _Cones:
    """The sides of the closed contacts' cones in force coordinates: side ``s`` is ``rho_s x[normal_s] + sign_s
    x[tangent_s] >= 0`` (a single coordinate's ``x >= 0``: ``sign`` 0; a cone's two edges: ``mu x_n -+ x_t``)."""

    normal: np.ndarray
    tangent: np.ndarray
    rho: np.ndarray  # (k, C)
    sign: np.ndarray

    def values(self, x: np.ndarray) -> np.ndarray:
        return self.rho * x[:, self.normal] + self.sign * x[:, self.tangent]


def _cones(contacts: np.ndarray, alone: np.ndarray, mu: np.ndarray, normal_at: list[int], tangent_at: list[int]) -> _Cones:
    """The cone sides of the closed ``contacts`` (a single coordinate: one side; a 2-D cone: its two edges)."""
    sides: list[tuple[int, int, np.ndarray, float]] = []  # (normal coordinate, tangent coordinate, rho, sign)
    for position, i in enumerate(contacts.tolist()):
        if alone[i]:
            sides.append((normal_at[position], 0, np.ones(mu.shape[0]), 0.0))
        else:
            sides += [(normal_at[position], tangent_at[position], mu[:, i], edge) for edge in (-1.0, 1.0)]
    normal, tangent, rho, sign = zip(*sides, strict=True)
    return _Cones(np.array(normal), np.array(tangent), np.stack(rho, axis=1), np.array(sign))


def _coordinates(c: np.ndarray, contacts: np.ndarray, normal_at: list[int], tangent_at: list[int], size: int) -> np.ndarray:
    """Contact-frame forces ``c`` (k, m, 2) as the closed contacts' force coordinates (k, f)."""
    x = np.zeros((c.shape[0], size))
    for position, i in enumerate(contacts.tolist()):
        x[:, normal_at[position]] = c[:, i, 1]
        if tangent_at[position] >= 0:
            x[:, tangent_at[position]] = c[:, i, 0]
    return x
