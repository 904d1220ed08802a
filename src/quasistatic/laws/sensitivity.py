"""Derivatives of a motion with respect to the inputs, by the implicit function theorem on the fixed-mode laws.

With every contact's mode fixed, the laws are the smooth equations ``F(x, b) = 0``
of :mod:`.fixed_modes` (``x``: twists and the closed contacts' force unknowns;
``b``: the movers' point velocities, linear in the inputs ``p``: ``b = B p``).
Where ``F_x`` is invertible, ``dx/dp = -F_x^{-1} F_b B``. The Jacobian is the
kernel's own: the inputs enter as extra "twist" columns ``-B`` of an augmented
``J``, so ``u = J q - B p`` and the kernel's derivative along those columns is
``F_b B``; their equilibrium rows are dropped. In 2-D, and in 3-D without
sliding frictional contacts, the laws are affine in ``(x, p)`` and the map is
exact along any straight line in the inputs until a contact changes mode.

The mode boundaries (:class:`Boundary`) are the quantities that must keep their
sign for the modes to hold: a separating contact's normal speed, a closed
contact's normal force, a rolling contact's distance from its cone, a sliding
contact's slip speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import FloatArray
from ..tolerances import FIXED_MODE_RESIDUAL, FREE_TWIST_DIRECTION, JACOBIAN_RANK, NEWTON_STOP
from .assemble import Problem
from .fixed_modes import ROLLING, SEPARATING, SLIDING, FixedModeLaws, columns, system
from .modes import ModeMasks

__all__ = ["Boundary", "FixedModeDerivative", "Singular", "singular", "polish", "force_derivative", "fixed_mode_derivative", "boundaries"]

_NEWTON_ITERATIONS = 30  # Newton from an audited motion converges in two or three steps; more means no root nearby


@dataclass(frozen=True)
class Singular:
    """The fixed-mode laws' Jacobian is singular, or Newton found no root: no derivative.

    ``why``: ``"forces_indeterminate"`` (a null direction moves only forces), ``"continuum"`` (it moves the
    twist), or ``"no_root"`` (the motion does not satisfy the fixed-mode laws to :data:`FIXED_MODE_RESIDUAL`).
    """

    why: str


@dataclass(frozen=True)
class FixedModeDerivative:
    """A motion and its derivative in scene-relative units, per physical unit of each input.

    Attributes
    ----------
    q : (k n,)  polished twist;  dq : (k n, P)
    c : (m, d)  contact-frame forces;  dc : (m, d, P)
    u : (m, d)  relative contact velocities;  du : (m, d, P)
    affine : bool
        The laws are affine in (twist, forces, inputs): the derivative is exact along straight input lines.
    """

    q: FloatArray
    dq: FloatArray
    c: FloatArray
    dc: FloatArray
    u: FloatArray
    du: FloatArray
    affine: bool


@dataclass(frozen=True)
class Boundary:
    """One quantity that must stay non-negative for the modes to hold, and its gradient in the inputs.

    ``what`` is one of ``separating``, ``normal_force``, ``cone``, ``slip``, ``edge`` (3-D pyramid); ``value`` is scene-relative,
    ``gradient`` (P,) per physical unit of each input. For ``cone`` in 3-D, ``tangent``/``dtangent`` and
    ``normal``/``dnormal`` give the exact quadratic ``(mu cn)^2 - |ct|^2`` along an affine path.
    """

    contact: int
    what: str
    value: float
    gradient: FloatArray
    mu: float = 0.0
    normal: float = 0.0
    dnormal: FloatArray | None = None
    tangent: FloatArray | None = None
    dtangent: FloatArray | None = None


def fixed_mode_derivative(
    problem: Problem, masks: ModeMasks, q: FloatArray, c: FloatArray, B: FloatArray
) -> FixedModeDerivative | Singular:
    """The derivative of the motion ``(q, c)`` with modes ``masks``, for inputs with ``b = B p`` (B: (m, d, P), per V)."""
    laws = FixedModeLaws(problem, masks)
    polished = polish(laws, laws.start(q, c, nonnegative=False))
    if isinstance(polished, Singular):
        return polished
    n, P, t = problem.n_dof, B.shape[2], problem.dimension - 1
    J = np.ascontiguousarray(np.concatenate([problem.J, -B], axis=2))
    column, size = columns(laws.kind, n + P, t)
    x = np.concatenate([polished[:n], np.zeros(P), polished[n:]])
    g = np.concatenate([laws.g, np.zeros(P)])
    _, jacobian, forces = system(J, laws.b, laws.mu, g, x, laws.kind, column, n + P)
    keep = np.r_[0:n, n + P : size]
    dx = -np.linalg.solve(jacobian[np.ix_(keep, keep)], jacobian[np.ix_(keep, np.arange(n, n + P))])
    dq = dx[:n]
    u = problem.velocities(polished[:n])
    du = np.einsum("mdn,nP->mdP", problem.J, dq) - B
    dc = force_derivative(laws, column - P, dx, forces, u, du)
    sliding = (laws.kind == SLIDING) & (laws.mu > 0)
    return FixedModeDerivative(polished[:n], dq, forces, dc, u, du, affine=problem.dimension == 2 or not bool(np.any(sliding)))


def polish(laws: FixedModeLaws, x: FloatArray) -> FloatArray | Singular:
    """Newton's method on the fixed-mode laws from an audited motion: the root to machine precision, or why none."""
    for _ in range(_NEWTON_ITERATIONS):
        residual, jacobian = laws.residual(x), laws.jacobian(x)
        why = singular(jacobian, laws.n)
        if why is not None:
            return why
        if float(np.max(np.abs(residual), initial=0.0)) <= NEWTON_STOP:
            return x
        x = x - np.linalg.solve(jacobian, residual)
    converged = float(np.max(np.abs(laws.residual(x)), initial=0.0)) <= FIXED_MODE_RESIDUAL
    return x if converged else Singular("no_root")


def singular(jacobian: FloatArray, n: int) -> Singular | None:
    """Why the square fixed-mode system (twist first, ``n`` entries) has no unique solution, or None when it has one."""
    if jacobian.size == 0:
        return None
    _, s, vt = np.linalg.svd(jacobian)
    if s[-1] > JACOBIAN_RANK * s[0]:
        return None
    null = vt[s <= JACOBIAN_RANK * s[0]]
    moves_twist = bool(np.max(np.abs(null[:, :n]), initial=0.0) > FREE_TWIST_DIRECTION)
    return Singular("continuum" if moves_twist else "forces_indeterminate")


def force_derivative(
    laws: FixedModeLaws, column: FloatArray, dx: FloatArray, forces: FloatArray, u: FloatArray, du: FloatArray
) -> FloatArray:
    """d(contact-frame forces)/dp, (m, d, P): unknowns read from ``dx``; sliding friction ``-mu cn e`` differentiated."""
    m, d = forces.shape
    t, P = d - 1, dx.shape[1]
    dc = np.zeros((m, d, P))
    for i in np.flatnonzero(laws.kind != SEPARATING):
        col = int(column[i])
        dc[i, t] = dx[col]
        if laws.kind[i] == ROLLING:
            dc[i, :t] = dx[col + 1 : col + 1 + t]
        elif laws.mu[i] > 0:
            slip = u[i, :t]
            speed = float(np.linalg.norm(slip))
            e = slip / speed
            turn = (np.eye(t) - np.outer(e, e)) / speed  # zero in 2-D, where e is a sign
            dc[i, :t] = -laws.mu[i] * (np.outer(e, dx[col]) + forces[i, t] * turn @ du[i, :t])
    return dc


def boundaries(derivative: FixedModeDerivative, masks: ModeMasks, mu: FloatArray) -> list[Boundary]:
    """The quantities whose sign keeps each contact in its mode, with their gradients in the inputs."""
    out: list[Boundary] = []
    c, dc, u, du = derivative.c, derivative.dc, derivative.u, derivative.du
    t = c.shape[1] - 1
    for i in range(c.shape[0]):
        if not masks.closed[i]:
            out.append(Boundary(i, "separating", float(u[i, t]), du[i, t]))
            continue
        out.append(Boundary(i, "normal_force", float(c[i, t]), dc[i, t]))
        if masks.rolling[i]:
            out += _cone_boundaries(i, float(mu[i]), c[i], dc[i])
        elif masks.sliding[i]:
            speed = float(np.linalg.norm(u[i, :t]))
            out.append(Boundary(i, "slip", speed, (u[i, :t] / speed) @ du[i, :t]))
    return out


def _cone_boundaries(i: int, mu: float, c: FloatArray, dc: FloatArray) -> list[Boundary]:
    """A rolling contact's distance from its cone: two linear sides in 2-D, ``mu cn - |ct|`` in 3-D."""
    t = c.shape[0] - 1
    if t == 1:
        return [Boundary(i, "cone", mu * c[1] - s * c[0], mu * dc[1] - s * dc[0]) for s in (1.0, -1.0)]
    tangent = c[:t]
    size = float(np.linalg.norm(tangent))
    direction = tangent / size if size > 0 else np.zeros(t)
    gradient = mu * dc[t] - direction @ dc[:t]
    return [Boundary(i, "cone", mu * c[t] - size, gradient, mu, float(c[t]), dc[t], tangent, dc[:t])]


def crossing(boundary: Boundary, direction: FloatArray, affine: bool) -> float:
    """How far along ``direction`` (P,) in the inputs the quantity first reaches 0 (inf if never).

    Exact on an affine path (a linear quantity, or the 3-D cone's quadratic ``(mu cn)^2 - |ct|^2``);
    otherwise to first order in the distance.
    """
    if affine and boundary.tangent is not None and boundary.dtangent is not None and boundary.dnormal is not None:
        return _cone_crossing(boundary, direction)
    rate = float(boundary.gradient @ direction)
    return boundary.value / -rate if rate < 0 else float("inf")


def _cone_crossing(boundary: Boundary, direction: FloatArray) -> float:
    """First s > 0 with ``mu (cn + s a) = |ct + s w|`` (a, w: the force's rates along ``direction``)."""
    assert boundary.tangent is not None and boundary.dtangent is not None and boundary.dnormal is not None
    mu, cn, ct = boundary.mu, boundary.normal, boundary.tangent
    a, w = float(boundary.dnormal @ direction), boundary.dtangent @ direction
    # (mu cn + s mu a)^2 - |ct + s w|^2 = A s^2 + 2 H s + C, positive at s = 0
    A, H, C = (mu * a) ** 2 - float(w @ w), mu * mu * cn * a - float(ct @ w), (mu * cn) ** 2 - float(ct @ ct)
    if A == 0.0:
        roots = [-C / (2 * H)] if H != 0.0 else []
    else:
        discriminant = H * H - A * C
        roots = [] if discriminant < 0.0 else [(-H + sign * np.sqrt(discriminant)) / A for sign in (1.0, -1.0)]
    # Both cones of the quadratic count: its zero on the mirror cone (cn < 0) is past the normal force's own zero.
    return min((float(r) for r in roots if r > 0.0), default=float("inf"))


def ball_radius(boundary: Boundary) -> float:
    """Distance in the inputs to the quantity's zero, to first order (exact for a linear quantity)."""
    size = float(np.linalg.norm(boundary.gradient))
    return boundary.value / size if size > 0 else float("inf")
