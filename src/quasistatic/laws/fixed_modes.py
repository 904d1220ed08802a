"""The exact contact laws with every contact's mode fixed: smooth equations, and their Jacobian.

With the modes fixed, Coulomb's laws become equations (exact circular cones
in 3-D, the two edges in 2-D):

    sum_i J_i^T c_i + g = 0                       equilibrium (n rows)
    u_n,i = 0                                     each closed contact
    u_t,i = 0                                     each rolling contact (d - 1 rows)
    c_t,i = -mu_i c_n,i u_t,i / |u_t,i|           each sliding contact (substituted, no unknowns)

Unknowns ``x``: the twist ``q`` (n), then per closed contact its normal force
and, when it rolls, its tangential force. The system is square. This module is
the one place these laws are written (once as loops for numba, once as
whole-array numpy for plain Python, and in C in ``quasistatic._lemke`` for installs
without numba; tests keep the three equal): the fast path's
Newton iteration, the exact-cone refinement and the paper method's polish all
solve it.

Encoding: ``kind[i]`` is 0 (separating), 1 (rolling, frictional) or 2
(sliding, or closed and frictionless); ``column[i]`` is where contact i's
unknowns start in ``x`` and its equations start in the residual.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..compiled import HAVE_EXTENSION
from ..compiled import fixed_mode_system as compiled_fixed_mode_system
from ..interval import Interval, matmul, point
from ..jit import njit
from ..model import FloatArray
from .assemble import Problem
from .modes import ModeMasks

__all__ = ["SEPARATING", "ROLLING", "SLIDING", "system", "columns", "FixedModeLaws"]

SEPARATING, ROLLING, SLIDING = 0, 1, 2
IntArray = npt.NDArray[np.int64]


@njit
def columns(kind: IntArray, n: int, t: int) -> tuple[IntArray, int]:
    """Where each contact's unknowns start, and the number of unknowns."""
    m = kind.shape[0]
    column = np.zeros(m, dtype=np.int64)
    size = n
    for i in range(m):
        column[i] = size
        size += 0 if kind[i] == SEPARATING else (1 + t if kind[i] == ROLLING else 1)
    return column, size


def _system_numpy(
    J: FloatArray, b: FloatArray, mu: FloatArray, g: FloatArray, x: FloatArray, kind: IntArray, column: IntArray, n: int
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Whole-array twin of :func:`system` for plain Python: every contact of a mode at once (numba compiles the loops).

    Without numba each numpy call costs about a microsecond whatever its size, so the
    contacts are handled by mode in a fixed number of calls rather than one block per contact.
    """
    m, d = J.shape[0], J.shape[1]
    t = d - 1
    size = x.shape[0]
    residual = np.zeros(size)
    jacobian = np.zeros((size, size))
    forces = np.zeros((m, d))
    velocity = J.dot(x[:n]) - b  # (m, d): tangent slips, then normal velocity
    closed = np.flatnonzero(kind != SEPARATING)
    normal_col = column[closed]
    forces[closed, t] = x[normal_col]
    # Closed: no normal velocity; the normal force enters equilibrium.
    residual[normal_col] = velocity[closed, t]
    normal_rows = J[closed, t]  # (c, n)
    jacobian[normal_col, :n] = normal_rows
    jacobian[:n, normal_col] = normal_rows.T  # distinct columns, each written once
    rolling = np.flatnonzero(kind == ROLLING)
    if rolling.size:
        tangent_col = (column[rolling, None] + 1 + np.arange(t)).ravel()
        tangent_rows = J[rolling, :t].reshape(-1, J.shape[2])  # (r t, n)
        forces[rolling, :t] = x[tangent_col].reshape(-1, t)
        residual[tangent_col] = velocity[rolling, :t].ravel()
        jacobian[tangent_col, :n] = tangent_rows
        jacobian[:n, tangent_col] = tangent_rows.T
    sliding = np.flatnonzero((kind == SLIDING) & (mu > 0.0))
    if sliding.size:
        _sliding_friction_numpy(
            J[sliding, :t], mu[sliding], forces[sliding, t], column[sliding], velocity[sliding, :t], sliding, forces, jacobian
        )
    residual[:n] = g + forces[closed].ravel().dot(J[closed].reshape(-1, J.shape[2]))
    return residual, jacobian, forces


def _sliding_friction_numpy(
    tangent: FloatArray,
    mu: FloatArray,
    cn: FloatArray,
    col: IntArray,
    slip: FloatArray,
    contacts: IntArray,
    forces: FloatArray,
    jacobian: FloatArray,
) -> None:
    """Whole-array twin of :func:`_sliding_friction` over the sliding contacts ``contacts`` (tangent rows (s, t, n), slips (s, t)).

    The twist block ``sum_s k_s T_s^T (I - e_s e_s^T) T_s`` is summed as ``k T^T T - k a a^T`` with ``a = T^T e``.
    """
    speed = np.sqrt((slip * slip).sum(axis=1))
    moving = speed > 0.0
    if not moving.all():
        tangent, mu, cn, col, slip, contacts, speed = (a[moving] for a in (tangent, mu, cn, col, slip, contacts, speed))
    n = tangent.shape[2]
    e = slip / speed[:, None]
    forces[contacts, : slip.shape[1]] = -(mu * cn)[:, None] * e
    along = np.matmul(e[:, None, :], tangent)[:, 0, :]  # (s, n): a = T^T e per contact
    jacobian[:n, col] -= (mu[:, None] * along).T  # distinct columns: no index repeats
    k = -(mu * cn) / speed
    rows = tangent.reshape(-1, n)
    jacobian[:n, :n] += (rows * np.repeat(k, tangent.shape[1])[:, None]).T.dot(rows) - (along * k[:, None]).T.dot(along)


# Without numba: the C extension's loops when it was built, else the whole-array twin.
_PLAIN_SYSTEM = compiled_fixed_mode_system if HAVE_EXTENSION else _system_numpy


@njit(python=_PLAIN_SYSTEM)
def system(
    J: FloatArray, b: FloatArray, mu: FloatArray, g: FloatArray, x: FloatArray, kind: IntArray, column: IntArray, n: int
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Residual (N,), Jacobian (N, N) of the fixed-mode laws at ``x``, and the contact forces (m, d) in contact frames.

    ``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,) as in :class:`~quasistatic.laws.Problem`.
    """
    m, d = J.shape[0], J.shape[1]
    t = d - 1
    size = x.shape[0]
    residual = np.zeros(size)
    jacobian = np.zeros((size, size))
    forces = np.zeros((m, d))
    slip = np.zeros(t)
    residual[:n] = g
    for i in range(m):
        if kind[i] == SEPARATING:
            continue
        for s in range(t):
            slip[s] = -b[i, s]
            for j in range(n):
                slip[s] += J[i, s, j] * x[j]
        col = column[i]
        cn = x[col]
        forces[i, t] = cn
        # Closed: no normal velocity; the normal force enters equilibrium.
        residual[col] = -b[i, t]
        for j in range(n):
            residual[col] += J[i, t, j] * x[j]
            jacobian[col, j] = J[i, t, j]
            jacobian[j, col] += J[i, t, j]
        if kind[i] == ROLLING:
            for s in range(t):
                forces[i, s] = x[col + 1 + s]
                residual[col + 1 + s] = slip[s]
                for j in range(n):
                    jacobian[col + 1 + s, j] = J[i, s, j]
                    jacobian[j, col + 1 + s] += J[i, s, j]
        elif mu[i] > 0.0:
            _sliding_friction(J, mu, i, cn, col, slip, n, forces, jacobian)
        for j in range(n):
            for s in range(d):
                residual[j] += J[i, s, j] * forces[i, s]
    return residual, jacobian, forces


@njit
def _sliding_friction(
    J: FloatArray, mu: FloatArray, i: int, cn: float, col: int, slip: FloatArray, n: int, forces: FloatArray, jacobian: FloatArray
) -> None:
    """Friction ``-mu cn e`` (``e = slip/|slip|``) of sliding contact ``i`` into ``forces``, its derivatives into ``jacobian``.

    d(-mu cn e)/d cn = -mu e;  d(-mu cn e)/d slip = -mu cn (I - e e^T) / |slip|  (zero in 2-D, where e is a sign).
    """
    t = slip.shape[0]
    speed = np.sqrt(np.sum(slip * slip))
    if speed <= 0.0:
        return
    e = slip / speed
    k = -mu[i] * cn / speed
    for s in range(t):
        forces[i, s] = -mu[i] * cn * e[s]
    for j in range(n):
        for s in range(t):
            jacobian[j, col] += J[i, s, j] * (-mu[i] * e[s])
        for k2 in range(n):
            total = 0.0
            for s in range(t):
                for r in range(t):
                    projector = k * ((1.0 if s == r else 0.0) - e[s] * e[r])
                    total += J[i, s, j] * projector * J[i, r, k2]
            jacobian[j, k2] += total


class FixedModeLaws:
    """The fixed-mode laws of one problem and one mode pattern, for a least-squares solver.

    Parameters
    ----------
    problem : Problem
    masks : ModeMasks
        Closed, rolling and sliding contacts.
    """

    def __init__(self, problem: Problem, masks: ModeMasks) -> None:
        self.problem, self.masks = problem, masks
        kind = np.where(masks.closed, np.where(masks.rolling, ROLLING, SLIDING), SEPARATING).astype(np.int64)
        self.kind = kind
        self.n, self.t = problem.n_dof, problem.dimension - 1
        self.column, self.size = columns(kind, self.n, self.t)
        self._last: tuple[FloatArray, tuple[FloatArray, FloatArray, FloatArray]] | None = None
        self.J, self.b = np.ascontiguousarray(problem.J, dtype=float), np.ascontiguousarray(problem.b, dtype=float)
        self.mu, self.g = np.ascontiguousarray(problem.mu, dtype=float), np.ascontiguousarray(problem.g, dtype=float)

    def start(self, q: FloatArray, c: FloatArray, nonnegative: bool = True) -> FloatArray:
        """The unknowns at twist ``q`` with contact-frame forces ``c`` (m, d); negative normal forces clipped to 0 if ``nonnegative``."""
        x = np.zeros(self.size)
        x[: self.n] = q
        for i in np.flatnonzero(self.kind != SEPARATING):
            x[self.column[i]] = max(float(c[i, -1]), 0.0) if nonnegative else float(c[i, -1])
            if self.kind[i] == ROLLING:
                x[self.column[i] + 1 : self.column[i] + 1 + self.t] = c[i, :-1]
        return x

    def residual(self, x: FloatArray) -> FloatArray:
        return self._system(x)[0]

    def jacobian(self, x: FloatArray) -> FloatArray:
        return self._system(x)[1]

    def _system(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:func:`system` at ``x``, kept for the last ``x``: a least-squares step asks for the residual and the Jacobian at one point."""
        if self._last is None or not np.array_equal(self._last[0], x):
            self._last = (x.copy(), system(self.J, self.b, self.mu, self.g, x, self.kind, self.column, self.n))
        return self._last[1]

    def motion(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Twist (n,) and contact-frame forces (m, d) at ``x``."""
        return x[: self.n].copy(), self._system(x)[2]

    def enclosure(self, box: Interval) -> tuple[Interval, Interval] | None:
        """Intervals holding the residual (N,) and the Jacobian (N, N) at every ``x`` in ``box`` (rounded outwards,
        :mod:`quasistatic.interval`); None where a sliding contact's slip may vanish in the box (the laws are not
        smooth there). The same equations as :func:`system`, written once more for intervals."""
        n, t, J, b = self.n, self.t, self.J, self.b
        q = box[:n]
        lo, hi = np.zeros(self.size), np.zeros(self.size)
        jac_lo, jac_hi = np.zeros((self.size, self.size)), np.zeros((self.size, self.size))

        def put(rows: slice, cols: int | slice, value: Interval) -> None:
            jac_lo[rows, cols], jac_hi[rows, cols] = value.lo, value.hi

        equilibrium = point(self.g)
        twist_block = Interval(np.zeros((n, n)), np.zeros((n, n)))
        for i in np.flatnonzero(self.kind != SEPARATING):
            col = int(self.column[i])
            cn = box[col]
            gap = matmul(J[i, t][None, :], q)[0] - b[i, t]
            lo[col], hi[col] = gap.lo, gap.hi
            jac_lo[col, :n] = jac_hi[col, :n] = J[i, t]
            normal_column = point(J[i, t])
            equilibrium = equilibrium + normal_column * cn
            slip = matmul(J[i, :t], q) - b[i, :t]
            if self.kind[i] == ROLLING:
                tangential = box[col + 1 : col + 1 + t]
                lo[col + 1 : col + 1 + t], hi[col + 1 : col + 1 + t] = slip.lo, slip.hi
                jac_lo[col + 1 : col + 1 + t, :n] = jac_hi[col + 1 : col + 1 + t, :n] = J[i, :t]
                jac_lo[:n, col + 1 : col + 1 + t] = jac_hi[:n, col + 1 : col + 1 + t] = J[i, :t].T
                equilibrium = equilibrium + matmul(J[i, :t].T, tangential)
            elif self.mu[i] > 0.0:
                squared = slip.square().sum()
                if squared.lo <= 0.0:
                    return None
                inverse_speed = squared.sqrt().reciprocal()
                e = slip * inverse_speed  # the slip direction
                along, normal_column = self._sliding_column(int(i), e)
                mu = float(self.mu[i])
                equilibrium = equilibrium - along * (cn * mu)
                k = -(cn * inverse_speed) * mu
                projector = point(J[i, :t].T @ J[i, :t]) - along[:, None] * along[None, :]
                twist_block = twist_block + projector * k
            put(slice(0, n), col, normal_column)
        put(slice(0, n), slice(0, n), twist_block)
        lo[:n], hi[:n] = equilibrium.lo, equilibrium.hi
        return Interval(lo, hi), Interval(jac_lo, jac_hi)

    def force_matrix(self, directions: Interval) -> Interval:
        """The equilibrium's derivative in the force unknowns, ``E`` (n, N - n) with ``g + E f = 0`` at fixed
        twist, for every slip direction of each sliding contact within ``directions`` (m, t): the same columns as
        :meth:`enclosure`'s, the directions given rather than taken from a box's slips."""
        n, t, J = self.n, self.t, self.J
        lo, hi = np.zeros((n, self.size - n)), np.zeros((n, self.size - n))
        for i in np.flatnonzero(self.kind != SEPARATING):
            col = int(self.column[i]) - n
            column = self._sliding_column(int(i), directions[i])[1] if self.kind[i] == SLIDING and self.mu[i] > 0.0 else point(J[i, t])
            lo[:, col], hi[:, col] = column.lo, column.hi
            if self.kind[i] == ROLLING:
                lo[:, col + 1 : col + 1 + t] = hi[:, col + 1 : col + 1 + t] = J[i, :t].T
        return Interval(lo, hi)

    def _sliding_column(self, i: int, e: Interval) -> tuple[Interval, Interval]:
        """``T^T e`` and the normal force's column ``N - mu T^T e`` of sliding contact ``i`` (friction ``-mu c_n e``)."""
        along = matmul(self.J[i, : self.t].T, e)
        return along, point(self.J[i, self.t]) - along * float(self.mu[i])
