"""The scene's own units: every tolerance is relative to them.

A scene in millimetres and grams and the same scene in metres and kilograms
have the same scale-free problem, so one tolerance serves both, and the
answer does not depend on where the world origin is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..tolerances import SMALLEST_LENGTH
from .kinematics import mover_point_velocities
from .scene import FloatArray, Scene

__all__ = ["Scales", "scene_scales"]


@dataclass(frozen=True)
class Scales:
    """The scene's own units; scene-relative quantities are physical ones divided by these.

    Attributes
    ----------
    length : float
        Spread of the contact points and centres of mass [length].
    force : float
        Largest load on one body (weight plus applied force) [force].
    velocity : float
        Largest prescribed contact-point velocity [length/time]; 1 when all movers rest.
    origin : array (d,)
        Centroid of the contact points and centres of mass [length].
    """

    length: float
    force: float
    velocity: float
    origin: FloatArray

    @property
    def power(self) -> float:
        """Power unit [force x length/time]."""
        return self.force * self.velocity

    def twist_units(self, dimension: int) -> FloatArray:
        """Per-entry unit of one body twist: velocity for v, velocity/length for omega."""
        linear, angular = (2, 1) if dimension == 2 else (3, 3)
        return np.r_[np.full(linear, self.velocity), np.full(angular, self.velocity / self.length)]

    def wrench_units(self, dimension: int) -> FloatArray:
        """Per-entry unit of one body wrench: force, then force x length."""
        linear, angular = (2, 1) if dimension == 2 else (3, 3)
        return np.r_[np.full(linear, self.force), np.full(angular, self.force * self.length)]


def scene_scales(scene: Scene, mover_velocities: FloatArray | None = None) -> Scales:
    """Length, force and velocity scales and the origin of a scene.

    ``mover_velocities`` (m, d), when the caller has them: :func:`~.kinematics.mover_point_velocities`.
    """
    points = np.array([c.point for c in scene.contacts] + [b.com for b in scene.bodies], dtype=float)
    origin = points.mean(axis=0)
    length = _length(points, origin)
    dim = scene.dimension
    loads = [scene.load(body) for body in scene.bodies]
    force = max([float(np.linalg.norm(w[:dim])) for w in loads] + [float(np.linalg.norm(w[dim:])) / length for w in loads])
    velocities = mover_point_velocities(scene) if mover_velocities is None else mover_velocities
    velocity = float(np.max(np.linalg.norm(velocities, axis=1), initial=0.0))
    origin.setflags(write=False)
    return Scales(length=length, force=force or 1.0, velocity=velocity or 1.0, origin=origin)


def _length(points: FloatArray, origin: FloatArray) -> float:
    length = float(np.max(np.linalg.norm(points - origin, axis=1)))
    if length > 0.0:
        return length
    # Every point coincides: only their distance from the world origin sets a size.
    length = float(np.max(np.abs(points)))
    return length if SMALLEST_LENGTH <= length <= 1.0 / SMALLEST_LENGTH else 1.0
