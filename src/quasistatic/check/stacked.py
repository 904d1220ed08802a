"""The audit of many planar motions at once, each on its own scene's numbers (a :class:`~quasistatic.model.stacked.PlanarStack`).

The same laws and residuals as :mod:`.audit`'s planar kernel, contact by contact in the same order, with the
points as a leading array axis: velocities, loads and moments recomputed from the stacked scene data (world frame,
physical units), never from assembled matrices, so this stays an independent judge of a batched solve. It also
measures each contact's normal velocity and slip speed, from which a mode is named as the report names it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import FloatArray
from ..model.stacked import PlanarStack
from ..tolerances import AUDIT, MODE_SPEED

__all__ = ["StackedAudit", "audit_stack", "MODE_CODES"]

MODE_CODES = ("rolling", "sliding", "separating")
"""The mode named by each code of :attr:`StackedAudit.modes`."""


@dataclass(frozen=True)
class StackedAudit:
    """Per point: whether every residual is within the tolerance (``passed``, (N,)), each contact's mode as the audit
    measured it (``modes``, (N, m), codes into :data:`MODE_CODES`), and the measured normal velocity and slip speed
    (``normal_velocity``, ``slip_speed``, (N, m)) with the mode threshold (``threshold``, (N,))."""

    passed: np.ndarray
    modes: np.ndarray
    normal_velocity: FloatArray
    slip_speed: FloatArray
    threshold: FloatArray


def audit_stack(
    stack: PlanarStack,
    twists: FloatArray,
    forces: FloatArray,
    scales: tuple[FloatArray, FloatArray, FloatArray],
    tolerance: float = AUDIT,
) -> StackedAudit:
    """Audit each point's motion: ``twists`` (N, 3) physical, ``forces`` (N, m, 2) world forces on the body;
    ``scales`` the (length, force, velocity) of each point (N,) the residuals are divided by."""
    sums = _contact_sums(stack, twists, forces)
    passed = np.logical_and.reduce([r <= tolerance for r in _residuals(sums, twists, scales)])
    threshold = MODE_SPEED * scales[2]
    normal, slip = sums.normal_velocity, sums.slip_speed
    modes = np.where(normal > threshold[:, None], 2, np.where(slip > threshold[:, None], 1, 0))
    return StackedAudit(passed, modes.astype(np.int8), normal, slip, threshold)


@dataclass
class _Sums:
    """What the audit adds up contact by contact, per point (each (N,) unless said): the net wrench's three entries
    (load first), the worst cone, penetration, normal power and dissipation shortfall, the movers' supplied power,
    the power dissipated by slip, a sum of every input (NaN or inf anywhere shows in it), and each contact's normal
    velocity and slip speed ((N, m))."""

    loads: FloatArray
    totals: list[FloatArray]
    cone: FloatArray
    penetration: FloatArray
    normal_power: FloatArray
    shortfall: FloatArray
    supplied: FloatArray
    dissipated: FloatArray
    check: FloatArray
    normal_velocity: FloatArray
    slip_speed: FloatArray


def _contact_sums(stack: PlanarStack, twists: FloatArray, forces: FloatArray) -> _Sums:
    """The audit's sums over the contacts, in contact order, as the per-point kernel adds them."""
    n, t = stack.normal, np.stack([stack.normal[..., 1], -stack.normal[..., 0]], axis=-1)
    arm = stack.point - stack.com[:, None, :]
    offset = stack.point - stack.origin
    spin = stack.twist[..., 2]
    mover = np.stack([stack.twist[..., 0] - spin * offset[..., 1], stack.twist[..., 1] + spin * offset[..., 0]], axis=-1)
    loads = stack.loads()
    vx, vy, w = twists[:, 0], twists[:, 1], twists[:, 2]
    zeros = [np.zeros(stack.size) for _ in range(7)]
    sums = _Sums(loads, [loads[:, 0].copy(), loads[:, 1].copy(), loads[:, 2].copy()], *zeros, *(np.empty(stack.mu.shape) for _ in range(2)))
    for i in range(stack.mu.shape[1]):
        nx, ny, tx, ty = n[:, i, 0], n[:, i, 1], t[:, i, 0], t[:, i, 1]
        rx, ry, mx, my = arm[:, i, 0], arm[:, i, 1], mover[:, i, 0], mover[:, i, 1]
        fx, fy = forces[:, i, 0], forces[:, i, 1]
        ux, uy = (vx - w * ry) - mx, (vy + w * rx) - my
        sums.totals[0] += fx
        sums.totals[1] += fy
        sums.totals[2] += rx * fy - ry * fx
        sums.supplied += fx * mx + fy * my
        f_n, f_t = fx * nx + fy * ny, fx * tx + fy * ty
        u_n, u_t = ux * nx + uy * ny, ux * tx + uy * ty
        radius = stack.mu[:, i] * np.maximum(f_n, 0.0)
        sums.cone = np.maximum(np.maximum(sums.cone, -f_n), np.abs(f_t) - radius)
        sums.penetration = np.maximum(sums.penetration, -u_n)
        sums.normal_power = np.maximum(sums.normal_power, np.abs(f_n * u_n))
        sums.shortfall = np.maximum(sums.shortfall, radius * np.abs(u_t) + f_t * u_t)
        sums.dissipated -= fx * ux + fy * uy - f_n * u_n
        sums.check += fx + fy + ux + uy
        sx, sy = ux - u_n * nx, uy - u_n * ny
        sums.normal_velocity[:, i], sums.slip_speed[:, i] = u_n, np.sqrt(sx * sx + sy * sy)
    return sums


def _residuals(sums: _Sums, twists: FloatArray, scales: tuple[FloatArray, FloatArray, FloatArray]) -> tuple[FloatArray, ...]:
    """Equilibrium, cone, complementarity, maximum dissipation and power balance, each scene-relative, per point."""
    L, F, V = scales
    raised = np.zeros(twists.shape[0])
    check = sums.check
    for j in range(3):
        check += sums.totals[j]
        raised -= sums.loads[:, j] * twists[:, j]
    check += raised
    totals = sums.totals
    equilibrium = np.maximum(np.maximum(np.abs(totals[0]), np.abs(totals[1])) / F, np.abs(totals[2]) / (F * L))
    equilibrium[~np.isfinite(check)] = np.inf
    return (
        equilibrium,
        np.maximum(0.0, sums.cone / F),
        np.maximum(sums.penetration / V, sums.normal_power / (F * V)),
        np.maximum(sums.shortfall / (F * V), 0.0),
        np.abs(sums.supplied - raised - sums.dissipated) / (F * V),
    )
