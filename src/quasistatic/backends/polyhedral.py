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

from ..problem import Problem

__all__ = ["LCPForm", "polyhedral_form", "aligned_edges"]


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
        return np.tile(np.array([[1.0], [-1.0]]), (m, 1, 1))
    angles = 2.0 * np.pi * np.arange(count) / count
    offsets = np.zeros(m) if slip is None else np.arctan2(-slip[:, 1], -slip[:, 0])
    total = angles[None, :] + offsets[:, None]
    return np.stack([np.cos(total), np.sin(total)], axis=-1)


def polyhedral_form(problem: Problem, edges: np.ndarray) -> LCPForm:
    """Assemble the linear pieces for the given per-contact edges."""
    m, K = edges.shape[:2]
    n = problem.n_dof
    Jn, Jt, bn, bt, mu = problem.Jn, problem.Jt, problem.bn, problem.bt, problem.mu
    # Edge rows: D_ik^T Jt_i, shape (m, K, n).
    JD = np.einsum("mkt,mtn->mkn", edges, Jt)
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
