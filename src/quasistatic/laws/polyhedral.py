"""The polyhedral contact laws as a linear complementarity system (Stewart & Trinkle 1996).

Variables, all scene-relative: twists ``q`` (free), normal forces ``cn`` (m),
edge intensities ``beta`` (m x K) and slip speeds ``lam`` (m). Each contact's
tangential force is ``sum_k beta_k mu... d_k`` with unit edge directions
``d_k`` whose polygon is inscribed in the exact cone. The laws:

    Jn^T cn + Jt^T D beta + g = 0                       equilibrium
    0 <= cn   _|_  wn   = Jn q - bn             >= 0    contact
    0 <= beta _|_  wb   = D^T (Jt q - bt) + lam >= 0    slip opposes force
    0 <= lam  _|_  wl   = mu cn - sum beta      >= 0    friction bound

Unknowns are stacked as ``x = [q, cn, beta, lam]``; the complementarity pairs
are ``(cn, wn)``, ``(beta, wb)``, ``(lam, wl)`` where each ``w = W x - r``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..model import FloatArray
from .assemble import Problem

__all__ = ["LCPForm", "polyhedral_form", "aligned_edges", "edge_jacobian", "ForcePolytope", "force_polytope", "dense_force_matrix"]


@dataclass(frozen=True)
class LCPForm:
    """Linear pieces of the polyhedral laws.

    Attributes
    ----------
    edges : (m, K, d-1)
        Unit tangent edge directions per contact (contact-frame tangent coordinates).
    E_eq, e_eq : equilibrium ``E_eq x = e_eq``, shape (k n, N)
    W, r : complementarity slacks ``w = W x - r``, row i paired with column ``pair_cols[i]``.
    pair_cols : (P,) column index in x of each pair's variable.
    n_q : number of twist entries.
    """

    problem: Problem
    edges: np.ndarray
    E_eq: np.ndarray
    e_eq: np.ndarray
    W: np.ndarray
    r: np.ndarray
    pair_cols: np.ndarray
    n_q: int

    @property
    def n_vars(self) -> int:
        return self.E_eq.shape[1]

    @property
    def n_edges(self) -> int:
        return self.edges.shape[1]

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``x`` into (q, cn, beta (m, K), lam)."""
        m, K = self.edges.shape[:2]
        q = x[: self.n_q]
        cn = x[self.n_q : self.n_q + m]
        beta = x[self.n_q + m : self.n_q + m + m * K].reshape(m, K)
        lam = x[self.n_q + m + m * K :]
        return q, cn, beta, lam

    def forces(self, x: np.ndarray) -> np.ndarray:
        """Contact-frame forces (m, d): tangential from the edges, then normal."""
        _, cn, beta, _ = self.split(x)
        tangential = np.einsum("mk,mkt->mt", beta, self.edges)
        return np.column_stack([tangential, cn])


def aligned_edges(problem: Problem, count: int, slip: np.ndarray | None = None) -> np.ndarray:
    """Edge directions per contact; 3-D edges rotated so one edge opposes ``slip`` (m, 2)."""
    m = problem.n_contacts
    if problem.dimension == 2:
        edges = np.empty((m, 2, 1))  # [+1, -1] along the tangent, each contact (filled: np.tile costs 5x more)
        edges[:, 0, 0], edges[:, 1, 0] = 1.0, -1.0
        return edges
    angles = 2.0 * np.pi * np.arange(count) / count
    offsets = np.zeros(m) if slip is None else np.arctan2(-slip[:, 1], -slip[:, 0])
    total = angles[None, :] + offsets[:, None]
    return np.stack([np.cos(total), np.sin(total)], axis=-1)


def polyhedral_form(problem: Problem, edges: np.ndarray) -> LCPForm:
    """Assemble the linear pieces for the given per-contact edges."""
    m, K = edges.shape[:2]
    n = problem.n_dof
    Jn, bn, bt, mu = problem.Jn, problem.bn, problem.bt, problem.mu
    JD = edge_jacobian(problem, edges).reshape(m, K, n)
    bD = np.einsum("mkt,mt->mk", edges, bt)
    N = n + m + m * K + m
    cn0, b0, l0 = n, n + m, n + m + m * K
    E_eq = np.zeros((n, N))
    E_eq[:, cn0:b0] = Jn.T
    E_eq[:, b0:l0] = JD.reshape(m * K, n).T
    e_eq = -problem.g
    W = np.zeros((m + m * K + m, N))
    r = np.zeros(W.shape[0])
    W[:m, :n] = Jn
    r[:m] = bn
    W[m : m + m * K, :n] = JD.reshape(m * K, n)
    r[m : m + m * K] = bD.ravel()
    W[m : m + m * K, l0:] = np.repeat(np.eye(m), K, axis=0)
    W[m + m * K :, cn0:b0] = np.diag(mu)
    W[m + m * K :, b0:l0] = -np.repeat(np.eye(m), K, axis=1)
    pair_cols = np.arange(n, N)
    return LCPForm(problem, edges, E_eq, e_eq, W, r, pair_cols, n)


def edge_jacobian(problem: Problem, edges: np.ndarray) -> np.ndarray:
    """Slip along each edge per unit twist, ``D_ik^T Jt_i``: shape (m K, n), row ``i K + k``."""
    m, K = edges.shape[:2]
    return np.einsum("mkt,mtn->mkn", edges, problem.Jt).reshape(m * K, problem.n_dof)


@dataclass(frozen=True)
class ForcePolytope:
    """Contact forces in the polyhedral cones that balance the load: ``A x = rhs, x >= 0``.

    Columns of ``x``: normal forces ``cn`` (m), edge intensities ``beta`` (m K, contact-major), and
    each contact's friction slack ``mu cn - sum_k beta_k`` (m). Rows: equilibrium (n), then the
    friction bound of each contact (m).
    """

    A: sp.csr_matrix
    rhs: FloatArray
    m: int
    K: int

    @property
    def normal(self) -> slice:
        return slice(0, self.m)

    @property
    def beta(self) -> slice:
        return slice(self.m, self.m + self.m * self.K)

    @property
    def slack(self) -> slice:
        return slice(self.m + self.m * self.K, 2 * self.m + self.m * self.K)


def force_polytope(problem: Problem, edges: np.ndarray) -> ForcePolytope:
    """The equilibrium forces within the cones spanned by ``edges`` (m, K, d - 1); see :class:`ForcePolytope`.

    ``A`` is sparse: its friction rows hold ``K + 2`` entries each, and a dense
    ``(n + m, m (K + 2))`` matrix grows as the square of the contacts (10,000
    contacts in 3-D: 6 GB).
    """
    m, K = edges.shape[:2]
    rows, cols, values, shape = _polytope_entries(problem, edges)
    return ForcePolytope(sp.csr_matrix((values, (rows, cols)), shape=shape), np.r_[-problem.g, np.zeros(m)], m, K)


def dense_force_matrix(problem: Problem, edges: np.ndarray) -> np.ndarray:
    """The matrix ``A`` of :func:`force_polytope`, dense (for small sets: a sparse build costs ~0.1 ms on a grasp)."""
    rows, cols, values, shape = _polytope_entries(problem, edges)
    A = np.zeros(shape)
    A[rows, cols] = values  # every (row, column) pair occurs once
    return A


def _polytope_entries(problem: Problem, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, int]]:
    """Rows, columns and values of the force polytope's matrix, and its shape (one build from index arrays:
    stacking per-block sparse matrices cost ~1 ms on a 2-contact grasp)."""
    m, K = edges.shape[:2]
    n = problem.n_dof
    balance = np.hstack([problem.Jn.T, edge_jacobian(problem, edges).T])  # (n, m + m K), dense like its sources
    rows, cols = np.nonzero(balance)
    contact = np.arange(m)
    friction_rows = n + np.concatenate([contact, np.repeat(contact, K), contact])
    friction_cols = np.concatenate([contact, m + np.arange(m * K), m + m * K + contact])
    friction_values = np.concatenate([problem.mu, -np.ones(m * K), -np.ones(m)])
    return (
        np.concatenate([rows, friction_rows]),
        np.concatenate([cols, friction_cols]),
        np.concatenate([balance[rows, cols], friction_values]),
        (n + m, m * (K + 2)),
    )
