"""The planar laws of many scenes of one shape at once: :func:`~quasistatic.laws.assemble` with a leading point axis.

Each point's ``J``, ``b``, ``g``, ``mu`` and scales equal, bit for bit, what :func:`~quasistatic.laws.assemble`
gives its Scene: the same operations on the same numbers in the same order, element by element (no matrix
product, whose summation order could change with the stack). A batched solve then reproduces the per-point
answers exactly where it runs the same kernels on them (tested against ``assemble`` on random stacks).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import FloatArray
from ..model.stacked import PlanarStack

__all__ = ["StackedLaws", "assemble_stack"]


@dataclass(frozen=True)
class StackedLaws:
    """The scene-relative laws of each point of a :class:`~quasistatic.model.stacked.PlanarStack` (one body, twist ``q`` in R^3).

    Attributes
    ----------
    stack : PlanarStack
    frames : (N, m, 2, 2)
        Each contact's frame rows: tangent, then normal.
    J : (N, m, 2, 3)
        Relative contact velocity per unit twist, in contact frames.
    b : (N, m, 2)
        The movers' point velocities in contact frames.
    g : (N, 3)
        Gravity plus applied wrench.
    mu : (N, m)
    length, force, velocity : (N,)
        Each point's scales (:class:`~quasistatic.model.Scales`).
    """

    stack: PlanarStack
    frames: FloatArray
    J: FloatArray
    b: FloatArray
    g: FloatArray
    mu: FloatArray
    length: FloatArray
    force: FloatArray
    velocity: FloatArray

    @property
    def size(self) -> int:
        return self.stack.size

    def twist_units(self) -> FloatArray:
        """(N, 3): the unit of each twist entry, ``[V, V, V / L]`` (as ``Scales.twist_units``)."""
        return np.stack([self.velocity, self.velocity, self.velocity / self.length], axis=1)


def assemble_stack(stack: PlanarStack) -> StackedLaws | None:
    """The laws of every point; None when some point's scales need the rule for coincident points (then each point
    is assembled alone)."""
    velocities = _mover_velocities(stack)
    load = stack.loads()
    scales = _scales(stack, velocities, load)
    if scales is None:
        return None
    origin, L, F, V = scales
    coms = (stack.com - origin) / L[:, None]
    points = (stack.point - origin[:, None, :]) / L[:, None, None]
    n = stack.normal
    frames = np.empty((*n.shape[:2], 2, 2))
    frames[..., 0, 0], frames[..., 0, 1], frames[..., 1, :] = n[..., 1], -n[..., 0], n
    arms = points - coms[:, None, :]
    rows = np.empty((*n.shape[:2], 2, 3))
    rows[..., :2] = frames
    rows[..., 2] = arms[..., None, 0] * frames[..., 1] - arms[..., None, 1] * frames[..., 0]
    J = 0.0 + rows  # assemble adds each block into zeros
    b = (frames[..., 0] * velocities[..., None, 0] + frames[..., 1] * velocities[..., None, 1]) / V[:, None, None]
    units = np.stack([F, F, F * L], axis=1)
    return StackedLaws(stack, frames, J, b, load / units, stack.mu.copy(), L, F, V)


def _mover_velocities(stack: PlanarStack) -> FloatArray:
    """Each contact's mover point velocity (N, m, 2), as ``mover_point_velocities``: ``v + omega (-r_y, r_x)``."""
    r = stack.point - stack.origin
    twist = stack.twist
    spin = np.empty_like(r)
    spin[..., 0] = twist[..., 2] * r[..., 1] * -1.0
    spin[..., 1] = twist[..., 2] * r[..., 0] * 1.0
    return 0.0 + twist[..., :2] + spin


def _scales(stack: PlanarStack, velocities: FloatArray, load: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None:
    """Origin, length, force and velocity of each point, as ``scene_scales``: the contact points and the com, their
    sums in order (as NumPy adds a column, and the few-point rule in Python floats)."""
    places = np.concatenate((stack.point, stack.com[:, None, :]), axis=1)  # (N, m + 1, 2): contacts, then the body
    total = places[:, 0].copy()
    for k in range(1, places.shape[1]):
        total += places[:, k]
    origin = total / places.shape[1]
    offset = places - origin[:, None, :]
    length = np.sqrt((offset[..., 0] * offset[..., 0] + offset[..., 1] * offset[..., 1]).max(axis=1))
    if not (length > 0.0).all():
        return None
    linear = np.maximum(0.0, np.sqrt(load[:, 0] * load[:, 0] + load[:, 1] * load[:, 1]))
    angular = np.maximum(0.0, np.sqrt(load[:, 2] * load[:, 2]))
    force = np.maximum(linear, angular / length)
    speed = velocities[..., 0] * velocities[..., 0] + velocities[..., 1] * velocities[..., 1]
    velocity = np.sqrt(np.maximum(0.0, speed.max(axis=1)))
    return origin, length, np.where(force == 0.0, 1.0, force), np.where(velocity == 0.0, 1.0, velocity)
