"""The contact laws of 3-D pyramid friction (``pyramid:K``) with every contact's mode fixed: linear equations.

Maximum dissipation on an inscribed pyramid loads the edges ``d_k`` most opposed
to a sliding contact's slip (those maximising ``-d_k . u_t``). Generically that is
either

- one edge ``j`` (a *vertex* of the friction polygon): ``c_t = mu c_n d_j``, while
  the slip may point anywhere inside the sector where ``j`` wins; or
- two neighbouring edges ``j, j + 1`` (a *face*): ``c_t = s d_j + (mu c_n - s) d_{j+1}``
  with ``0 <= s <= mu c_n``, while the slip is held along the face's normal,
  ``(d_j - d_{j+1}) . u_t = 0``.

With the modes and these edges fixed, the laws are linear in the twist ``q`` and
the closed contacts' force unknowns (per closed contact ``c_n``; a rolling one
also ``c_t``, a face one also ``s``):

    sum_i J_i^T c_i + g = 0        equilibrium
    J_n,i q = b_n,i                each closed contact
    J_t,i q = b_t,i                each rolling contact
    (d_j - d_{j+1}) . J_t,i q = (d_j - d_{j+1}) . b_t,i     each face contact

so the motion and its derivative in the inputs (``b = b0 + B p``) come from one
linear solve, exact along any straight line in the inputs until a mode changes.
The mode boundaries are linear too (:func:`pyramid_boundaries`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import FloatArray
from ..tolerances import MODE_BOUNDARY
from .assemble import Problem
from .modes import ModeMasks
from .sensitivity import Boundary, FixedModeDerivative, Singular, singular

__all__ = ["PyramidModes", "pyramid_derivative", "pyramid_boundaries"]


@dataclass(frozen=True)
class PyramidModes:
    """Contact modes and, per sliding frictional contact, its loaded edge ``edge`` and whether it is a ``face``
    (edges ``edge`` and ``edge + 1``); ``edge`` is -1 elsewhere. ``count``: the pyramid's K."""

    masks: ModeMasks
    edge: np.ndarray  # (m,) int
    face: np.ndarray  # (m,) bool
    count: int

    @classmethod
    def of(cls, problem: Problem, masks: ModeMasks, c: FloatArray) -> PyramidModes:
        """The edges the contact-frame forces ``c`` (m, 3) load: a face when both of the two around the friction's
        direction carry more than :data:`MODE_BOUNDARY` of it (scene-relative), else the nearer edge."""
        K = problem.friction.edges
        directions = _directions(K)
        edge = np.full(problem.n_contacts, -1)
        face = np.zeros(problem.n_contacts, dtype=bool)
        for i in np.flatnonzero(masks.sliding):
            j = int(np.floor(np.arctan2(c[i, 1], c[i, 0]) / (2 * np.pi / K))) % K
            weights = np.linalg.solve(np.column_stack([directions[j], directions[(j + 1) % K]]), c[i, :2])
            face[i] = bool(np.all(weights > MODE_BOUNDARY))
            edge[i] = j if face[i] or weights[0] >= weights[1] else (j + 1) % K
        return cls(masks, edge, face, K)


def _directions(K: int) -> FloatArray:
    angles = 2 * np.pi * np.arange(K) / K
    return np.column_stack([np.cos(angles), np.sin(angles)])


@dataclass(frozen=True)
class _Layout:
    """Where each closed contact's unknowns start (``column``) and how many there are (``size``)."""

    column: np.ndarray
    size: int

    @classmethod
    def of(cls, n: int, modes: PyramidModes) -> _Layout:
        column = np.full(modes.edge.shape[0], -1)
        size = n
        for i in np.flatnonzero(modes.masks.closed):
            column[i] = size
            size += 1 + (2 if modes.masks.rolling[i] else int(modes.face[i]))
        return cls(column, size)


def pyramid_derivative(problem: Problem, modes: PyramidModes, B: FloatArray) -> FixedModeDerivative | Singular:
    """The motion with ``modes`` and its derivative per physical unit of each input (``b = b0 + B p``, B: (m, 3, P))."""
    n = problem.n_dof
    layout = _Layout.of(n, modes)
    directions = _directions(modes.count)
    A = np.zeros((layout.size, layout.size))
    rhs = np.zeros((layout.size, 1 + B.shape[2]))  # the right-hand side, then its derivative per input
    rhs[:n, 0] = -problem.g
    for i in np.flatnonzero(modes.masks.closed):
        col, J, b = int(layout.column[i]), problem.J[i], np.column_stack([problem.b[i], B[i]])
        A[col, :n], rhs[col] = J[2], b[2]
        if modes.masks.rolling[i]:
            A[:n, col], A[:n, col + 1 : col + 3] = J[2], J[:2].T
            A[col + 1 : col + 3, :n], rhs[col + 1 : col + 3] = J[:2], b[:2]
        elif modes.edge[i] >= 0:
            j, mu = int(modes.edge[i]), float(problem.mu[i])
            last = directions[(j + 1) % modes.count] if modes.face[i] else directions[j]
            A[:n, col] = J[2] + mu * last @ J[:2]  # all of mu c_n on the last edge, s moves it to edge j
            if modes.face[i]:
                turn = directions[j] - last
                A[:n, col + 1] = turn @ J[:2]
                A[col + 1, :n], rhs[col + 1] = turn @ J[:2], turn @ b[:2]
        else:
            A[:n, col] = J[2]  # frictionless: the normal force alone
    why = singular(A, n)
    if why is not None:
        return why
    solved = np.linalg.solve(A, rhs).astype(float)
    forces = _forces(problem, modes, layout, solved)
    q, dq = solved[:n, 0], solved[:n, 1:]
    du = np.einsum("mdn,nP->mdP", problem.J, dq) - B
    return FixedModeDerivative(q, dq, forces[:, :, 0], forces[:, :, 1:], problem.velocities(q), du, affine=True)


def _forces(problem: Problem, modes: PyramidModes, layout: _Layout, x: FloatArray) -> FloatArray:
    """Contact-frame forces (m, 3, columns of ``x``) from the unknowns (or their derivatives) ``x`` (size, cols)."""
    directions = _directions(modes.count)
    c = np.zeros((problem.n_contacts, 3, x.shape[1]))
    for i in np.flatnonzero(modes.masks.closed):
        col = int(layout.column[i])
        c[i, 2] = x[col]
        if modes.masks.rolling[i]:
            c[i, :2] = x[col + 1 : col + 3]
        elif modes.edge[i] >= 0:
            j = int(modes.edge[i])
            last = directions[(j + 1) % modes.count] if modes.face[i] else directions[j]
            c[i, :2] = problem.mu[i] * np.outer(last, x[col])
            if modes.face[i]:
                c[i, :2] += np.outer(directions[j] - last, x[col + 1])
    return c


def pyramid_boundaries(derivative: FixedModeDerivative, modes: PyramidModes, mu: FloatArray) -> list[Boundary]:
    """The linear quantities whose sign keeps each contact in its mode (and each sliding one on its edges).

    A separating contact's normal speed; a closed contact's normal force; a rolling force's distance from each
    facet of its pyramid, ``mu c_n cos(pi/K) - f . c_t`` (``cone``); a face contact's two edge weights (``face``:
    its friction reaches an edge) and its slip speed along the face's normal (``slip``); a vertex contact's slip
    staying inside its edge's sector, ``(d_k - d_j) . u_t`` for the two neighbours ``k`` (``edge``).
    """
    c, dc, u, du = derivative.c, derivative.dc, derivative.u, derivative.du
    K = modes.count
    directions = _directions(K)
    facets = np.column_stack([np.cos((2 * np.arange(K) + 1) * np.pi / K), np.sin((2 * np.arange(K) + 1) * np.pi / K)])
    out: list[Boundary] = []
    for i in range(c.shape[0]):
        if not modes.masks.closed[i]:
            out.append(Boundary(i, "separating", float(u[i, 2]), du[i, 2]))
            continue
        out.append(Boundary(i, "normal_force", float(c[i, 2]), dc[i, 2]))
        if modes.masks.rolling[i]:
            inradius = mu[i] * np.cos(np.pi / K)
            out += [Boundary(i, "cone", float(inradius * c[i, 2] - f @ c[i, :2]), inradius * dc[i, 2] - f @ dc[i, :2]) for f in facets]
        elif modes.edge[i] >= 0:
            out += _sliding_boundaries(i, int(modes.edge[i]), bool(modes.face[i]), directions, derivative)
    return out


def _sliding_boundaries(i: int, j: int, face: bool, directions: FloatArray, derivative: FixedModeDerivative) -> list[Boundary]:
    c, dc, u, du = derivative.c[i], derivative.dc[i], derivative.u[i], derivative.du[i]
    K = directions.shape[0]
    if face:
        pair = np.column_stack([directions[j], directions[(j + 1) % K]])
        weights, rates = np.linalg.solve(pair, c[:2]), np.linalg.solve(pair, dc[:2])
        return [
            Boundary(i, "face", float(weights[0]), rates[0]),
            Boundary(i, "face", float(weights[1]), rates[1]),
            Boundary(i, "slip", float(-directions[j] @ u[:2]), -directions[j] @ du[:2]),
        ]
    turns = [directions[(j + 1) % K] - directions[j], directions[(j - 1) % K] - directions[j]]
    return [Boundary(i, "edge", float(turn @ u[:2]), turn @ du[:2]) for turn in turns]
