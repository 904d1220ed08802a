"""Contact forces consistent with a given twist: the one place that law is written for polyhedral cones.

With the twist fixed, every contact's velocity is known and the laws on the
forces are linear (Trinkle & Hunter's force formulation at a known motion):
an open contact carries nothing, a sliding one pushes on the
maximum-dissipation face of its friction polygon, a rolling one anywhere in
its polygon, and together they balance the load. The set is a polytope; the
certified search reports each normal force's range over it
(:func:`indeterminate_forces`: whether some range is wide is usually proven
by one LP, and the ranges' two LPs per contact run when they are first
read), the exact-cone refinement picks its point of least
total normal force (:func:`least_normal_forces`). A :class:`ConsistentForces`
keeps the set with the motion, for the ranges of what else the forces
determine (a robot's joint torques, a mover's wrench) and whether limits on
them can be met, worked out only when they are read.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, partial

import numpy as np
import scipy.sparse as sp

from ...laws import ForceSet, ModeMasks, Problem, slips
from ...laws.polyhedral import ForcePolytope, aligned_edges, dense_force_matrix, force_polytope
from ...tolerances import FORCE_CEILING, FORCE_INTERIOR, FORCE_RANK, LP_FEASIBILITY, MOVING, ZERO
from ..result import Range
from .highs import solve_lp
from .optimize import nnls
from .ranges import Bounds, linear_ranges, null_space, ranges_are_wide, rows_feasible, rows_in_row_space, value_ranges
from .rank import DENSE_MAX, full_column_rank

__all__ = [
    "ForcesAtTwist",
    "ConsistentForces",
    "FrictionlessForces",
    "IndeterminateForces",
    "DeferredIndeterminacy",
    "forces_at_twist",
    "indeterminate_forces",
    "measured_forces_at_twist",
    "least_normal_forces",
    "farkas_excludes",
    "measured_masks",
]


@dataclass(frozen=True)
class ForcesAtTwist:
    """The forces consistent with one twist: ``{x >= 0 : A x = rhs}`` with ``x`` the polytope's columns.

    ``fixed`` marks the columns held at zero by the modes (they are also rows of ``A``).
    """

    polytope: ForcePolytope
    edges: np.ndarray
    A: sp.csr_matrix
    rhs: np.ndarray
    fixed: np.ndarray

    def contact_forces(self, x: np.ndarray) -> np.ndarray:
        """Contact-frame forces (m, d) of the columns ``x``: tangential from the edges, then normal."""
        p = self.polytope
        beta = x[p.beta].reshape(p.m, p.K)
        return np.column_stack([np.einsum("mk,mkt->mt", beta, self.edges), x[p.normal]])

    def consistent(self) -> ConsistentForces:
        """The same set, with the linear map :meth:`contact_forces` as a sparse matrix."""
        p = self.polytope
        m, K, t = self.edges.shape
        d = t + 1
        contact = np.repeat(np.arange(m), K * t)
        rows = contact * d + np.tile(np.arange(t), m * K)  # tangent entry t of contact i
        cols = p.beta.start + np.repeat(np.arange(m * K), t)
        rows = np.r_[rows, np.arange(m) * d + t]  # then each normal force
        cols = np.r_[cols, np.arange(m) + p.normal.start]
        values = np.r_[self.edges.ravel(), np.ones(m)]
        M = sp.csr_matrix((values, (rows, cols)), shape=(m * d, self.fixed.size))
        return ConsistentForces(self.A, self.rhs, M)

    @cached_property
    def _consistent(self) -> ConsistentForces:
        return self.consistent()

    def ranges(self, functionals: np.ndarray) -> list[Bounds]:
        """As :meth:`ConsistentForces.ranges` (a :class:`~quasistatic.laws.ForceSet`; the map is built when first read)."""
        return self._consistent.ranges(functionals)

    def feasible(self, functionals: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
        """As :meth:`ConsistentForces.feasible`."""
        return self._consistent.feasible(functionals, lower, upper)


@dataclass(frozen=True)
class ConsistentForces:
    """Every force distribution consistent with one motion: ``{x >= 0 : A x = rhs}``, contact-frame forces ``c = M x``.

    ``c`` is scene-relative, flattened (m d,), contact-major with the normal last, as a
    backend's forces. A :class:`~quasistatic.laws.ForceSet`.
    """

    A: sp.csr_matrix
    rhs: np.ndarray
    M: sp.csr_matrix

    def ranges(self, functionals: np.ndarray) -> list[Bounds]:
        """Range of each ``functionals[r] . c`` (functionals (r, m, d)) over the set; None for an unbounded side."""
        return linear_ranges(self.A, self.rhs, self._rows(functionals), np.zeros(self.A.shape[1]))

    def feasible(self, functionals: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
        """Whether some point of the set has ``lower <= functionals . c <= upper``."""
        return rows_feasible(self.A, self.rhs, self._rows(functionals), lower, upper, np.zeros(self.A.shape[1]))

    def _rows(self, functionals: np.ndarray) -> np.ndarray:
        return np.asarray((sp.csr_matrix(functionals.reshape(functionals.shape[0], -1)) @ self.M).toarray())


class FrictionlessForces:
    """The forces of a frictionless motion: normal forces ``c >= 0`` on the ``closed`` contacts with ``Jn_C^T c = -g``.

    A :class:`~quasistatic.laws.ForceSet` whose matrices are built when it is first read
    (a frictionless solve takes about 0.1 ms; most callers never ask).
    """

    def __init__(self, Jn: np.ndarray, g: np.ndarray, closed: np.ndarray, dimension: int) -> None:
        self.Jn, self.g, self.closed, self.dimension = Jn, g, closed, dimension

    @cached_property
    def _set(self) -> ConsistentForces:
        columns = np.flatnonzero(self.closed)
        normal_rows = columns * self.dimension + self.dimension - 1
        M = sp.csr_matrix(
            (np.ones(columns.size), (normal_rows, np.arange(columns.size))), shape=(self.closed.size * self.dimension, columns.size)
        )
        return ConsistentForces(sp.csr_matrix(self.Jn[self.closed]).T.tocsr(), -self.g, M)

    def ranges(self, functionals: np.ndarray) -> list[Bounds]:
        return self._set.ranges(functionals)

    def feasible(self, functionals: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
        return self._set.feasible(functionals, lower, upper)


def forces_at_twist(problem: Problem, edges: np.ndarray, q: np.ndarray, masks: ModeMasks) -> ForcesAtTwist:
    """The force polytope of ``edges`` (m, K, d - 1) restricted by the contact modes at twist ``q``.

    Open contacts carry no normal force; a sliding contact uses only the edges
    that dissipate most for its slip and sits on its polygon's boundary; a
    frictionless contact has no edge force.
    """
    polytope = force_polytope(problem, edges)
    fixed = _held_columns(problem, edges, q, masks)
    # One unit row per fixed column, sparse: an identity as wide as all the columns would grow as their square.
    held = np.flatnonzero(fixed)
    # One build from index arrays (sparse vstack of small matrices costs more than the rest of this function).
    laws = polytope.A.tocoo()
    rows = np.r_[laws.row, polytope.A.shape[0] + np.arange(held.size)]
    A = sp.csr_matrix(
        (np.r_[laws.data, np.ones(held.size)], (rows, np.r_[laws.col, held])), shape=(polytope.A.shape[0] + held.size, fixed.size)
    )
    rhs = np.r_[polytope.rhs, np.zeros(int(fixed.sum()))]
    return ForcesAtTwist(polytope, edges, A, rhs, fixed)


def _held_columns(problem: Problem, edges: np.ndarray, q: np.ndarray, masks: ModeMasks) -> np.ndarray:
    """Which columns of the force polytope (normal, edge, slack) the modes hold at zero (see :func:`forces_at_twist`)."""
    m, K = edges.shape[:2]
    drive = -np.einsum("mkt,mt->mk", edges, slips(problem, q))  # dissipation rate per unit edge force
    best = drive.max(axis=1, initial=0.0)  # no edges (frictionless): nothing dissipates
    weaker = drive < best[:, None] - MOVING
    normal = ~masks.closed
    # An open contact's edge forces and slack are zero too: ``mu cn = sum beta + slack`` with cn held at 0 and all
    # of them >= 0. Holding them says so as equations, which the rank tests read (a tipping box's lifted corner
    # otherwise sent every decision to the LPs: 1.4 ms instead of 0.3 ms).
    beta = (weaker & masks.sliding[:, None]).ravel() | np.repeat((problem.mu <= 0) | normal, K)
    return np.concatenate([normal, beta, masks.sliding | normal])  # the polytope's column order: normal, beta, slack


def measured_masks(problem: Problem, edges: np.ndarray, q: np.ndarray) -> ModeMasks:
    """Modes as the velocities at ``q`` show them: open beyond ``MOVING``, sliding where some edge dissipates."""
    u = problem.velocities(q)
    drive = -np.einsum("mkt,mt->mk", edges, u[:, :-1])
    closed = ~(u[:, -1] > MOVING)
    sliding = drive.max(axis=1, initial=0.0) > MOVING
    return ModeMasks(closed, closed & ~sliding & (problem.mu > 0), sliding)


def measured_forces_at_twist(problem: Problem, edges: np.ndarray, q: np.ndarray) -> ForcesAtTwist:
    """:func:`forces_at_twist` with the modes the velocities at ``q`` show."""
    return forces_at_twist(problem, edges, q, measured_masks(problem, edges, q))


@dataclass(frozen=True)
class IndeterminateForces:
    """The normal-force ranges (scene-relative) of a motion whose forces are indeterminate, and their set.

    ``known`` holds the ranges when they were worked out to decide it; otherwise ``lazy`` works them
    out when called (two LPs per contact at most).
    """

    known: tuple[Range, ...] | None
    lazy: Callable[[], tuple[Range, ...]] | None
    force_set: ForceSet


class DeferredIndeterminacy:
    """:func:`indeterminate_forces` at twist ``q``, decided when first asked, once (a
    :class:`~quasistatic.laws.DeferredForces`): a simulation step or a sweep that never reads whether the
    forces are indeterminate does not pay for deciding it (0.3-2 ms on a 2-D grasp, more than the rest of its solve)."""

    def __init__(self, problem: Problem, edges: np.ndarray, q: np.ndarray) -> None:
        self.problem, self.edges, self.q = problem, edges, q

    @cached_property
    def found(self) -> IndeterminateForces | None:
        return indeterminate_forces(self.problem, self.edges, self.q)

    def indeterminate(self) -> bool:
        return self.found is not None

    def normal_ranges(self) -> tuple[Range, ...]:
        found = self._found()
        return found.known if found.known is not None else found.lazy()  # type: ignore[misc]  # one of the two is set

    def force_set(self) -> ForceSet:
        return self._found().force_set

    def _found(self) -> IndeterminateForces:
        if self.found is None:
            raise ValueError("the contact forces are unique: they have no ranges and no set to read")
        return self.found


def indeterminate_forces(problem: Problem, edges: np.ndarray, q: np.ndarray) -> IndeterminateForces | None:
    """The normal-force ranges over every force consistent with twist ``q``; None when the contact forces are unique.

    Unique means every component of every contact force, friction included (a box at rest on two supports,
    pulled sideways, has fixed normal forces but a free split of the pull between its supports): no
    component varies by more than ``LP_FEASIBILITY`` over the set (:func:`~.ranges.ranges_are_wide`).
    In the plane, a wrench map of full column rank on the closed contacts' own force coordinates says None
    first (:func:`_unique_in_the_plane`).
    A segment of consistent forces through a balanced point found by least squares that moves some
    force component by more than that: indeterminate, without an LP (:func:`_wide_through_balanced_point`),
    and the force set and its ranges are built only when read.
    Free columns of full rank: one force distribution, None. Every force component a combination of
    the equations (only the edge intensities vary, as both edges of a 2-D contact that sticks): None.
    Otherwise one LP decides (:func:`_forces_vary`), and the ranges wait until they are read; where it
    cannot decide, the ranges of every component are worked out now and decide.
    """
    masks = measured_masks(problem, edges, q)
    m, K = edges.shape[:2]
    normal = np.arange(m)  # the polytope's first columns
    if problem.dimension == 2:
        if _unique_in_the_plane(problem, masks, q):
            return None  # otherwise the polytope's own rank test would find some component free too: skipped
    elif min(problem.n_dof + m, m * (K + 2)) <= DENSE_MAX and _forces_fixed(problem, edges, q, masks, _component_rows(edges)):
        return None  # decided densely, before any sparse matrix is built (~0.5 ms on a grasp)
    if _wide_through_balanced_point(problem, masks, K, q):
        later = _LaterForces(problem, edges, q, masks)  # a simulation step never reads them (~1.2 ms on a planar push)
        return IndeterminateForces(None, partial(later.normal_ranges, normal), later)
    forces = forces_at_twist(problem, edges, q, masks)
    work = partial(_normal_ranges, forces, normal)
    A = forces.A.toarray() if min(forces.A.shape) <= DENSE_MAX else forces.A.tocsc()
    if not isinstance(A, np.ndarray) and _fixed_by_equations(A, forces.fixed, None):
        return None
    vary = _forces_vary(A, forces, _component_rows(edges), problem.mu) if isinstance(A, np.ndarray) else None
    if vary is not None:
        return IndeterminateForces(None, work, forces) if vary else None
    ranges = work()
    wide = ranges_are_wide(list(ranges)) or _friction_varies(forces, edges)
    return IndeterminateForces(ranges, None, forces) if wide else None


def _friction_varies(forces: ForcesAtTwist, edges: np.ndarray) -> bool:
    """Whether some contact's tangential force spans more than ``LP_FEASIBILITY`` over the set (two LPs per component,
    a few contacts' rows at a time: a large scene's rows all at once would be as large as the contacts squared)."""
    m = edges.shape[0]
    for start in range(0, m, DENSE_MAX):
        rows = _tangent_rows(edges, np.arange(start, min(start + DENSE_MAX, m)))
        spans = linear_ranges(forces.A, forces.rhs, rows, np.zeros(forces.fixed.size))
        if any(lo is None or hi is None or hi - lo > LP_FEASIBILITY for lo, hi in spans):
            return True
    return False


def _component_rows(edges: np.ndarray) -> np.ndarray:
    """Each contact-frame force component as a row over the force polytope's columns (normal, edges, slack):
    the normal forces (m), then each contact's tangential components (m (d - 1)). Small sets only (dense)."""
    m, K = edges.shape[:2]
    normal = np.zeros((m, m * (K + 2)))
    normal[np.arange(m), np.arange(m)] = 1.0
    return np.vstack([normal, _tangent_rows(edges, np.arange(m))])


def _tangent_rows(edges: np.ndarray, contacts: np.ndarray) -> np.ndarray:
    """The tangential force components of ``contacts`` (``sum_k beta_k edge_k``, d - 1 each) as rows over the columns."""
    m, K, t = edges.shape
    rows = np.zeros((contacts.size * t, m * (K + 2)))
    at, edge, axis = np.meshgrid(np.arange(contacts.size), np.arange(K), np.arange(t), indexing="ij")
    contact = contacts[at]
    rows[at * t + axis, m + contact * K + edge] = edges[contact, edge, axis]
    return rows


class _LaterForces:
    """:func:`forces_at_twist`, built when first read: a :class:`~quasistatic.laws.ForceSet` and the normal ranges."""

    def __init__(self, problem: Problem, edges: np.ndarray, q: np.ndarray, masks: ModeMasks) -> None:
        self.problem, self.edges, self.q, self.masks = problem, edges, q, masks

    @cached_property
    def forces(self) -> ForcesAtTwist:
        return forces_at_twist(self.problem, self.edges, self.q, self.masks)

    def normal_ranges(self, normal: np.ndarray) -> tuple[Range, ...]:
        return _normal_ranges(self.forces, normal)

    def ranges(self, functionals: np.ndarray) -> list[Bounds]:
        return self.forces.ranges(functionals)

    def feasible(self, functionals: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
        return self.forces.feasible(functionals, lower, upper)


def _wide_through_balanced_point(problem: Problem, masks: ModeMasks, edge_count: int, q: np.ndarray) -> bool:
    """True when a segment of forces consistent with the modes moves some force component by more than ``LP_FEASIBILITY``.

    In 3-D, only where no frictional contact slides; in 2-D a sliding contact's force is ``cn (n - mu s)``,
    ``s`` its slip's direction (the modes hold it on that edge of its cone): one column, ``cn >= 0``, as a
    frictionless contact's normal force. Every other closed contact may carry a force in its
    ``edge_count``-gon cone (frictionless ones a normal force alone), and that cone holds the disc cone
    ``|c_t| <= rho cn`` with ``rho = mu cos(pi / edge_count)`` (its inscribed circle; in 2-D the cone itself). A balanced point
    ``c`` (least squares over the closed contacts; a contact whose force leaves its disc cone is dropped,
    carrying nothing, and the rest solved again) with margins ``s_i = rho_i cn_i - |c_t,i| >= 0`` lies
    in the set. On the contacts with ``s_i > 0``, ``z``, the projection of a component's unit vector on
    the null space of their wrench map, keeps the balance, and ``c + t z`` stays in every disc cone for
    ``|t| <= min_i s_i / (|z_t,i| + rho_i |z_n,i|)`` (and ``A (c + t z)`` within ``ZERO`` of the load, as
    in :func:`_forces_vary`): that component spans at least ``2 t z_j``.
    """
    closed, mu = masks.closed, problem.mu
    sliding = closed & masks.sliding & (mu > 0.0)
    if np.any(sliding) and problem.dimension != 2:
        return False
    single = (mu <= 0.0) | sliding  # one force coordinate: the normal force, along the (tilted) normal
    tilt = _sliding_tilt(problem, q, sliding)
    inradius = _inradius(problem.dimension, edge_count)
    rho = np.where(single, 1.0, mu * inradius)  # one coordinate: its normal force >= 0
    kept = np.flatnonzero(closed)
    for _ in range(problem.n_contacts + 1):
        wrenches = _wrench_columns(problem, kept, single, tilt)
        c = np.linalg.lstsq(wrenches, -problem.g, rcond=None)[0] if kept.size else np.zeros(0)
        if float(np.max(np.abs(wrenches @ c + problem.g), initial=0.0)) > ZERO:
            return False
        tangent, cn = _per_contact(problem, kept, c, single)
        margin = rho[kept] * cn - np.linalg.norm(tangent, axis=1)
        if np.all(margin >= 0.0):
            break
        kept = kept[margin >= 0.0]
    inner = margin > 0.0
    kept, margin = kept[inner], margin[inner]
    wrenches = _wrench_columns(problem, kept, single, tilt)
    if kept.size == 0:
        return False
    basis = null_space(wrenches, FORCE_RANK)
    for j in range(basis.shape[0]):  # every force coordinate of the kept contacts: tangents and normal
        z = basis @ basis[j]
        if z[j] <= 0.0:
            continue
        moved_tangent, moved_normal = _per_contact(problem, kept, z, single)
        rate = np.linalg.norm(moved_tangent, axis=1) + rho[kept] * np.abs(moved_normal)
        reach = float(np.min(margin[rate > 0.0] / rate[rate > 0.0], initial=np.inf))
        drift = float(np.max(np.abs(wrenches @ z), initial=0.0))
        reach = min(reach, ZERO / drift if drift > 0.0 else np.inf)
        if 2.0 * reach * z[j] > LP_FEASIBILITY:
            return True
    return False


def _unique_in_the_plane(problem: Problem, masks: ModeMasks, q: np.ndarray) -> bool:
    """2-D: True when the closed contacts' force coordinates have a wrench map of full column rank, so one force
    distribution balances the load (the rank test of :func:`_forces_fixed` on a 3 x (at most 2 m) matrix instead
    of the force polytope's, which also carries each edge and slack: 30 us instead of 300 on a tipping box).

    A rolling frictional contact's force is free in the plane (tangent and normal); a sliding one's lies on one
    edge of its cone, ``cn (n - mu s)``; a frictionless one's along its normal (:func:`_wrench_columns`). The
    set of consistent forces lies in ``{c : W c = -g}``: full column rank fixes every component of it exactly.
    False decides nothing (the other tests run).
    """
    if problem.dimension != 2:
        return False
    closed = masks.closed
    sliding = closed & masks.sliding & (problem.mu > 0.0)
    single = (problem.mu <= 0.0) | sliding
    wrenches = _wrench_columns(problem, np.flatnonzero(closed), single, _sliding_tilt(problem, q, sliding))
    return full_column_rank(wrenches, FORCE_RANK)


def _inradius(dimension: int, edge_count: int) -> float:
    """Radius of the disc inside the unit friction polygon of ``edge_count`` edges: 2-D, its two edges are the cone;
    3-D, a regular polygon's inscribed circle; no edges (no friction), none."""
    if dimension == 2:
        return 1.0 if edge_count >= 2 else 0.0
    return float(np.cos(np.pi / edge_count)) if edge_count >= 3 else 0.0


def _sliding_tilt(problem: Problem, q: np.ndarray, sliding: np.ndarray) -> np.ndarray:
    """Per contact (m, d - 1): the friction per unit normal force of a sliding contact, ``-mu s`` (zero elsewhere)."""
    tilt = np.zeros((problem.n_contacts, problem.dimension - 1))
    if sliding.any():
        slip = slips(problem, q)[sliding]
        tilt[sliding] = -problem.mu[sliding, None] * slip / np.linalg.norm(slip, axis=1, keepdims=True)
    return tilt


def _wrench_columns(problem: Problem, contacts: np.ndarray, single: np.ndarray, tilt: np.ndarray) -> np.ndarray:
    """The wrench of each force coordinate of ``contacts`` on the bodies (k n, f): tangents and normal for a cone,
    one column for a ``single`` contact (frictionless, or sliding: its normal tilted by its friction ``tilt``)."""
    J = problem.J  # a single contact's column: its normal row plus its tilt times its tangent rows (no np.r_: 5 us each)
    columns = [(J[i, -1] + tilt[i] @ J[i, :-1])[:, None] if single[i] else J[i].T for i in contacts.tolist()]
    return np.hstack(columns) if columns else np.zeros((problem.n_dof, 0))


def _per_contact(problem: Problem, contacts: np.ndarray, x: np.ndarray, single: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x`` in the coordinates of :func:`_wrench_columns` as free tangent forces (k, d - 1) and normal forces (k,)."""
    d = problem.dimension
    tangent, normal = np.zeros((contacts.size, d - 1)), np.zeros(contacts.size)
    at = 0
    for k, i in enumerate(contacts.tolist()):
        if not single[i]:
            tangent[k], at = x[at : at + d - 1], at + d - 1
        normal[k], at = x[at], at + 1
    return tangent, normal


def _forces_fixed(problem: Problem, edges: np.ndarray, q: np.ndarray, masks: ModeMasks, components: np.ndarray) -> bool:
    """:func:`_fixed_by_equations` on the dense matrix of :func:`forces_at_twist` (the same rows, built densely)."""
    fixed = _held_columns(problem, edges, q, masks)
    A = np.vstack([dense_force_matrix(problem, edges), np.eye(fixed.size)[fixed]])
    return _fixed_by_equations(A, fixed, components)


def _fixed_by_equations(A: np.ndarray | sp.spmatrix, fixed: np.ndarray, components: np.ndarray | None) -> bool:
    """Free columns of full rank (one force distribution), or every force component a combination of the equations
    (only the edge intensities vary, as both edges of a 2-D contact that sticks: the ranges' LPs would find each
    component constant). ``components``: :func:`_component_rows`; None (a large set): the rank alone decides."""
    if full_column_rank(A[:, ~fixed], FORCE_RANK):
        return True
    return components is not None and bool(np.all(rows_in_row_space(A, components)))


def _normal_ranges(forces: ForcesAtTwist, normal: np.ndarray) -> tuple[Range, ...]:
    return tuple(value_ranges(forces.A, forces.rhs, normal, np.zeros(forces.fixed.size)))


def _forces_vary(A: np.ndarray, forces: ForcesAtTwist, components: np.ndarray, mu: np.ndarray) -> bool | None:
    """True: some force component provably spans more than ``LP_FEASIBILITY`` over the set; False: every
    component is constant on it; None: undecided. ``A``: ``forces.A``, dense (small sets only);
    ``components``: :func:`_component_rows`.

    The set is ``{x >= 0 : A x = rhs}``. One LP finds the columns ``P`` that are
    positive somewhere in it and a point ``x`` positive on all of them
    (:func:`_relative_interior`). The set then lies in ``{x : A x = rhs, x = 0
    off P}``, whose directions are the null space of ``A_P``: a component ``f . x``
    whose ``f_P`` is in ``A_P``'s row space is constant. Any ``z`` in that null
    space keeps ``x + t z`` in the set for ``-t_minus <= t <= t_plus`` (until a
    positive column reaches 0), so the component spans at least ``f . z (t_plus +
    t_minus)``, with ``z`` the projection of the unit ``f_P`` (the direction that
    moves it most per unit length); ``t`` also stops where ``A (x + t z)`` would
    leave ``rhs`` by ``ZERO`` (the basis is a null space to ``FORCE_RANK``). Usually no LP is needed:
    a point positive on every column not forced to zero is found by NNLS (:func:`_positive_point`),
    and those columns are then ``P``.
    """
    found = _positive_point(A, forces, mu) or _relative_interior(A, forces.rhs, forces.fixed)
    if found is None:
        return None
    x, support = found
    positive = np.flatnonzero(support)
    rows = components[:, positive]
    lengths = np.linalg.norm(rows, axis=1)
    rows = rows[lengths > 0.0] / lengths[lengths > 0.0, None]  # a component on no positive column is 0 on the set
    varying = rows[~rows_in_row_space(A[:, positive], rows)]
    if varying.shape[0] == 0:
        return False
    basis = null_space(A[:, positive], FORCE_RANK)
    for f in varying:
        z = basis @ (basis.T @ f)
        rate = float(f @ z)
        if rate <= 0.0:
            continue
        drift = float(np.max(np.abs(A[:, positive] @ z), initial=0.0))
        cap = ZERO / drift if drift > 0.0 else np.inf
        reach = min(_step(x[positive], z), cap) + min(_step(x[positive], -z), cap)
        if rate * reach > LP_FEASIBILITY:
            return True
    return None


def _positive_point(A: np.ndarray, forces: ForcesAtTwist, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """A point of ``{x >= 0 : A x = rhs}`` at least ``FORCE_INTERIOR`` of the load on every column the rows do not
    force to zero, by NNLS (``x = floor + y``, ``y >= 0``), and those columns; None when NNLS finds none (the LP decides).

    Forced to zero: the held columns, and the edge forces and friction slack of a contact whose normal force is
    held (open) or whose friction is zero (``mu cn - sum beta - slack = 0``).
    """
    p = forces.polytope
    open_contact = forces.fixed[p.normal]
    no_slack = open_contact | (mu <= 0.0)
    support = ~forces.fixed & ~np.concatenate([open_contact, np.repeat(open_contact, p.K), no_slack])
    columns = np.flatnonzero(support)
    floor = FORCE_INTERIOR * float(np.max(np.abs(forces.rhs), initial=0.0))
    if columns.size == 0 or floor <= 0.0:
        return None
    free = A[:, columns]
    y, _ = nnls(free, forces.rhs - floor * free.sum(axis=1))
    x = np.zeros(forces.fixed.size)
    x[columns] = y + floor
    if float(np.max(np.abs(A @ x - forces.rhs), initial=0.0)) > ZERO:
        return None
    return x, support


def _relative_interior(A: np.ndarray, rhs: np.ndarray, fixed: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """A point of ``{x >= 0 : A x = rhs}`` and the columns positive somewhere in the set (one LP), or None.

    The LP (Freund, Roundy and Todd's) runs on the cone ``A x = a rhs, a >= 1``:
    maximise ``sum t_j`` with ``0 <= t_j <= x_j`` and ``t_j <= 1``. Scaling and
    adding points of the cone reaches ``t_j = 1`` on every column positive
    somewhere in the set at once, and ``t_j = 0`` elsewhere, so the optimum
    marks the columns, and ``x / a`` is a point positive on all of them.
    """
    n = fixed.size
    free = np.flatnonzero(~fixed)
    k = free.size
    lift = np.zeros((k, n))
    lift[np.arange(k), free] = 1.0
    # Columns [x, a, t]: A x - a rhs = 0; x_j - t_j >= 0.
    rows = np.block([[A, -rhs[:, None], np.zeros((A.shape[0], k))], [lift, np.zeros((k, 1)), -np.eye(k)]])
    lower = np.zeros(rows.shape[0])
    upper = np.r_[np.zeros(A.shape[0]), np.full(k, np.inf)]
    cost = np.r_[np.zeros(n + 1), np.ones(k)]
    col_lower = np.r_[np.zeros(n), 1.0, np.zeros(k)]
    col_upper = np.r_[np.full(n + 1, np.inf), np.ones(k)]
    lp = solve_lp(cost, rows, lower, upper, col_lower, col_upper, maximize=True)
    if lp.status != "optimal":
        return None
    t = lp.x[n + 1 :]
    if np.any(np.abs(t - np.round(t)) > LP_FEASIBILITY):
        return None  # not the 0/1 optimum the argument needs: decide by the ranges instead
    support = np.zeros(n, dtype=bool)
    support[free[t > 0.5]] = True
    return lp.x[:n] / lp.x[n], support


def _step(x: np.ndarray, z: np.ndarray) -> float:
    """Largest ``t >= 0`` with ``x + t z >= 0`` (``x >= 0``); infinite when no entry of ``z`` is negative."""
    falling = z < 0.0
    return float(np.min(x[falling] / -z[falling])) if falling.any() else np.inf


def least_normal_forces(problem: Problem, q: np.ndarray, masks: ModeMasks, edge_count: int, screen: bool = False) -> np.ndarray | None:
    """Contact-frame forces (m, d) of least total normal force consistent with twist ``q`` and the modes; None if none.

    Edges (``edge_count`` per contact) are turned so one opposes each slip: a
    sliding contact's friction is then exactly ``-mu cn slip/|slip|``, and a
    rolling one's lies in a polygon inscribed in its exact cone. ``screen``: first look for a checked Farkas
    vector (:func:`farkas_excludes`, one small non-negative fit, dense: for small problems) and answer None
    without the LP where one excludes every force the LP could return (an infeasible LP costs HiGHS two runs).
    """
    edges = aligned_edges(problem, edge_count, slips(problem, q))
    forces = forces_at_twist(problem, edges, q, masks)
    if screen and farkas_excludes(forces, problem.g):
        return None
    cost = np.zeros(forces.fixed.size)
    cost[forces.polytope.normal] = 1.0
    lp = solve_lp(cost, forces.A, forces.rhs, forces.rhs, np.zeros(cost.size))
    return forces.contact_forces(lp.x) if lp.status == "optimal" else None


def farkas_excludes(forces: ForcesAtTwist, g: np.ndarray) -> bool:
    """Whether a checked Farkas vector shows that :func:`least_normal_forces`' LP on ``forces`` has no point.

    Every point the LP may return (each of its rows met to ``LP_FEASIBILITY``, columns down to
    ``-LP_FEASIBILITY``) balances the load ``g`` (n,) within ``margin`` (2-norm) with non-negative weights on
    the generators of its free columns: per closed contact its normal plus ``mu`` times each edge it may use,
    and its normal alone unless its slack is held (a sliding contact: ``sum beta = mu cn``); ``cn`` times a
    convex combination of these is any force the contact's rows allow. Round-off moves the wrench by at most
    ``LP_FEASIBILITY`` times each column's norm for a column below zero, as much for a held one, ``K + 2``
    times as much for edges past ``mu cn`` (the friction row and the slack's bound), and, at a sliding
    contact, its normal's norm over ``mu`` times as much for friction short of ``mu cn``: ``margin`` adds
    these, generously, to the equilibrium rows' own. A non-negative least-squares fit on the generators that
    misses the load leaves ``y = -(G w + g)``; with ``reserve = -g.y - margin |y| > 0`` and
    ``max(G^T y) FORCE_CEILING < reserve``, no weights of total normal force below :data:`FORCE_CEILING` come
    within ``margin`` of the load (as the mode branch and bound's Farkas vectors).
    """
    polytope = forces.polytope
    m, K, n = polytope.m, polytope.K, g.size
    balance = polytope.A[:n].toarray()  # (n, m (K + 2)): the equilibrium rows
    normal = balance[:, polytope.normal]
    closed = ~forces.fixed[polytope.normal]
    free_edges = ~forces.fixed[polytope.beta].reshape(m, K) & closed[:, None]
    friction = polytope.A[n:, polytope.normal].diagonal()  # mu per contact (the friction rows' normal entries)
    on_cone = closed & forces.fixed[polytope.slack] & (friction > 0.0) & free_edges.any(axis=1)
    shortfall = np.linalg.norm(normal[:, on_cone], axis=0) / friction[on_cone]
    margin = LP_FEASIBILITY * (np.sqrt(n) + (K + 4) * (float(np.linalg.norm(balance, axis=0).sum()) + float(shortfall.sum())))
    owners, edges_used = np.nonzero(free_edges)
    edge_columns = balance[:, polytope.beta].reshape(n, m, K)
    G = np.hstack([normal[:, closed & ~on_cone], normal[:, owners] + friction[owners] * edge_columns[:, owners, edges_used]])
    if not G.shape[1]:
        y = -g
    else:
        weights, _ = nnls(G, -g)
        y = -(G @ weights + g)
    reserve = -float(g @ y) - margin * float(np.linalg.norm(y))
    return bool(reserve > 0.0 and float(np.max(G.T @ y, initial=0.0)) * FORCE_CEILING < reserve)
