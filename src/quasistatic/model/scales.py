"""The scene's own units: every tolerance is relative to them.

A scene in millimetres and grams and the same scene in metres and kilograms
have the same scale-free problem, so one tolerance serves both, and the
answer does not depend on where the world origin is.
"""

from __future__ import annotations

import functools
import math
import operator
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
        return np.array([self.velocity] * linear + [self.velocity / self.length] * angular)  # np.r_ costs 10x more

    def wrench_units(self, dimension: int) -> FloatArray:
        """Per-entry unit of one body wrench: force, then force x length."""
        linear, angular = (2, 1) if dimension == 2 else (3, 3)
        return np.array([self.force] * linear + [self.force * self.length] * angular)


def scene_scales(scene: Scene, mover_velocities: FloatArray | None = None) -> Scales:
    """Length, force and velocity scales and the origin of a scene.

    ``mover_velocities`` (m, d), when the caller has them: :func:`~.kinematics.mover_point_velocities`.
    """
    velocities = mover_point_velocities(scene) if mover_velocities is None else mover_velocities
    if 0 < len(scene.contacts) + len(scene.bodies) < ORDERED_SUMS:
        return _few_point_scales(scene, velocities)
    points = np.array([c.point for c in scene.contacts] + [b.com for b in scene.bodies], dtype=float)
    origin = points.sum(axis=0) / len(points)  # a mean without np.mean's checks (small scenes solve in ~1 ms)
    length = _length(points, origin)
    dim = scene.dimension
    loads = _loads(scene)
    linear, angular = np.sqrt(np.square(loads[:, :dim]).sum(axis=1)), np.sqrt(np.square(loads[:, dim:]).sum(axis=1))
    force = max(float(linear.max(initial=0.0)), float(angular.max(initial=0.0)) / length)
    velocity = math.sqrt(float(np.square(velocities).sum(axis=1).max(initial=0.0)))
    origin.setflags(write=False)
    return Scales(length=length, force=force or 1.0, velocity=velocity or 1.0, origin=origin)


ORDERED_SUMS = 8
"""Below this many rows NumPy adds a column in order (its pairwise sums start at 8), as the Python loops of
:func:`_few_point_scales` do, so both give the same bits."""


def _few_point_scales(scene: Scene, velocities: FloatArray) -> Scales:
    """:func:`scene_scales` in Python floats, term for term in NumPy's order: a step of a small scene pays for
    a dozen numpy calls on arrays of two or three entries otherwise."""
    points = [c.point.tolist() for c in scene.contacts] + [b.com.tolist() for b in scene.bodies]
    centroid = [functools.reduce(operator.add, column) / len(points) for column in zip(*points, strict=True)]
    length = math.sqrt(max(_square_sum([p - o for p, o in zip(point, centroid, strict=True)]) for point in points))
    origin = np.array(centroid)
    if length == 0.0:
        length = _length(np.array(points), origin)  # every point coincides
    dim = scene.dimension
    loads = _loads(scene).tolist()
    force = max([0.0, *(math.sqrt(_square_sum(load[:dim])) for load in loads)])
    torque = max([0.0, *(math.sqrt(_square_sum(load[dim:])) for load in loads)])
    force = max(force, torque / length)
    velocity = math.sqrt(max([0.0, *(_square_sum(v) for v in velocities.tolist())]))
    origin.setflags(write=False)
    return Scales(length=length, force=force or 1.0, velocity=velocity or 1.0, origin=origin)


def _square_sum(values: list[float]) -> float:
    """``sum(v * v)`` added in order from the first term, as NumPy's ``square(...).sum()`` does for a few entries."""
    total = values[0] * values[0]
    for value in values[1:]:
        total += value * value
    return total


def _loads(scene: Scene) -> FloatArray:
    """Each body's gravity plus applied wrench, (bodies, k): :meth:`Scene.load` for all at once (a Scene fills every wrench)."""
    bodies = scene.bodies
    loads = np.array([b.wrench for b in bodies], dtype=float).reshape(len(bodies), scene.twist_size)
    loads[:, : scene.dimension] += np.array([b.mass for b in bodies])[:, None] * scene.gravity
    return loads


def _length(points: FloatArray, origin: FloatArray) -> float:
    length = math.sqrt(float(np.square(points - origin).sum(axis=1).max()))
    if length > 0.0:
        return length
    # Every point coincides: only their distance from the world origin sets a size.
    length = float(np.max(np.abs(points)))
    return length if SMALLEST_LENGTH <= length <= 1.0 / SMALLEST_LENGTH else 1.0
