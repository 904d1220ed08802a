"""Contact forces consistent with a given twist: the one place that law is written for polyhedral cones.

With the twist fixed, every contact's velocity is known and the laws on the
forces are linear (Trinkle & Hunter's force formulation at a known motion):
an open contact carries nothing, a sliding one pushes on the
maximum-dissipation face of its friction polygon, a rolling one anywhere in
its polygon, and together they balance the load. The set is a polytope; the
certified search reports each normal force's range over it
(:func:`force_ranges`), the exact-cone refinement picks its point of least
total normal force (:func:`least_normal_forces`). A :class:`ConsistentForces`
keeps the set with the motion, for the ranges of what else the forces
determine (a robot's joint torques, a mover's wrench) and whether limits on
them can be met, worked out only when they are read.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ...laws import ModeMasks, Problem, slips
from ...laws.polyhedral import ForcePolytope, aligned_edges, force_polytope
from ...tolerances import FORCE_RANK, ZERO
from ..result import Range
from .highs import solve_lp
from .ranges import Bounds, linear_ranges, ranges_are_wide, rows_feasible, value_ranges
from .rank import full_column_rank

__all__ = [
    "ForcesAtTwist",
    "ConsistentForces",
    "FrictionlessForces",
    "forces_at_twist",
    "measured_forces_at_twist",
    "force_ranges",
    "least_normal_forces",
]

_MOVING = ZERO * 10  # scene-relative speed or dissipation rate above which a contact opens or slides


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
    K = polytope.K
    drive = -np.einsum("mkt,mt->mk", edges, slips(problem, q))  # dissipation rate per unit edge force
    best = drive.max(axis=1, initial=0.0)  # no edges (frictionless): nothing dissipates
    fixed = np.zeros(polytope.A.shape[1], dtype=bool)
    fixed[polytope.normal] = ~masks.closed
    weaker = drive < best[:, None] - _MOVING
    fixed[polytope.beta] = (weaker & masks.sliding[:, None]).ravel() | np.repeat(problem.mu <= 0, K)
    fixed[polytope.slack] = masks.sliding
    # One unit row per fixed column, sparse: an identity as wide as all the columns would grow as their square.
    held = np.flatnonzero(fixed)
    pinned = sp.csr_matrix((np.ones(held.size), (np.arange(held.size), held)), shape=(held.size, fixed.size))
    A = sp.vstack([sp.csr_matrix(polytope.A), pinned], format="csr")
    rhs = np.r_[polytope.rhs, np.zeros(int(fixed.sum()))]
    return ForcesAtTwist(polytope, edges, A, rhs, fixed)


def _measured_masks(problem: Problem, edges: np.ndarray, q: np.ndarray) -> ModeMasks:
    """Modes as the velocities at ``q`` show them: open beyond ``_MOVING``, sliding where some edge dissipates."""
    u = problem.velocities(q)
    drive = -np.einsum("mkt,mt->mk", edges, u[:, :-1])
    closed = ~(u[:, -1] > _MOVING)
    sliding = drive.max(axis=1, initial=0.0) > _MOVING
    return ModeMasks(closed, closed & ~sliding & (problem.mu > 0), sliding)


def measured_forces_at_twist(problem: Problem, edges: np.ndarray, q: np.ndarray) -> ForcesAtTwist:
    """:func:`forces_at_twist` with the modes the velocities at ``q`` show."""
    return forces_at_twist(problem, edges, q, _measured_masks(problem, edges, q))


def force_ranges(problem: Problem, edges: np.ndarray, q: np.ndarray) -> tuple[list[Range], ConsistentForces] | None:
    """Normal-force ranges (scene-relative) over all forces consistent with twist ``q``, and that set; None when the forces are unique."""
    forces = measured_forces_at_twist(problem, edges, q)
    free = ~forces.fixed
    if full_column_rank(forces.A.tocsc()[:, free], FORCE_RANK):
        return None
    normal = np.arange(forces.fixed.size)[forces.polytope.normal]
    ranges = value_ranges(forces.A, forces.rhs, normal, np.zeros(forces.fixed.size))
    return (ranges, forces.consistent()) if ranges_are_wide(ranges) else None


def least_normal_forces(problem: Problem, q: np.ndarray, masks: ModeMasks, edge_count: int) -> np.ndarray | None:
    """Contact-frame forces (m, d) of least total normal force consistent with twist ``q`` and the modes; None if none.

    Edges (``edge_count`` per contact) are turned so one opposes each slip: a
    sliding contact's friction is then exactly ``-mu cn slip/|slip|``, and a
    rolling one's lies in a polygon inscribed in its exact cone.
    """
    edges = aligned_edges(problem, edge_count, slips(problem, q))
    forces = forces_at_twist(problem, edges, q, masks)
    cost = np.zeros(forces.fixed.size)
    cost[forces.polytope.normal] = 1.0
    lp = solve_lp(cost, forces.A, forces.rhs, forces.rhs, np.zeros(cost.size))
    return forces.contact_forces(lp.x) if lp.status == "optimal" else None
