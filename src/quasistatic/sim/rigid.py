"""Rigid motion over a time step: the exponential map of SE(3), and of SE(2) for planar twists.

A twist held constant over a step is a screw motion about a fixed axis. Integrating it
exactly (rather than adding ``v dt`` to the position and ``w dt`` to angles) keeps a box
tipping about its edge on that edge, and a wheel rolling on its rim: no drift that a
contact would then have to absorb.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ..adapters import Pose

__all__ = ["screw", "advance_pose", "point_velocity"]

FloatArray = npt.NDArray[np.float64]


def _hat(w: FloatArray) -> FloatArray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def screw(rotation_vector: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(R, V)`` of the exponential of a rotation vector phi = w dt.

    ``R = exp([phi])`` (Rodrigues) and ``V = I + (1 - cos t)/t^2 [phi] + (t - sin t)/t^3 [phi]^2``, t = |phi|:
    a constant twist (v at a point c, w) moves every point x to ``c + R (x - c) + V v dt``.
    """
    angle = float(np.linalg.norm(rotation_vector))
    hat = _hat(rotation_vector)
    hat2 = hat @ hat
    if angle < 1e-8:  # series: the closed forms lose every digit below this angle
        return np.eye(3) + hat + hat2 / 2.0, np.eye(3) + hat / 2.0 + hat2 / 6.0
    a = math.sin(angle) / angle
    b = (1.0 - math.cos(angle)) / angle**2
    c = (angle - math.sin(angle)) / angle**3
    return np.eye(3) + a * hat + b * hat2, np.eye(3) + b * hat + c * hat2


def advance_pose(pose: Pose, twist: FloatArray, point: FloatArray, dt: float) -> Pose:
    """The pose after moving for ``dt`` with ``twist`` = [velocity of the world point ``point``, angular velocity] held constant.

    A planar twist [vx, vy, w] moves a planar pose (:func:`~quasistatic.adapters.planar_pose`) on SE(2), exactly.
    """
    if len(twist) == 3:
        return _advance_planar(pose, twist, point, dt)
    rotation, v_matrix = screw(twist[3:] * dt)
    position = point + rotation @ (pose.position - point) + v_matrix @ twist[:3] * dt
    new_rotation = rotation @ pose.rotation
    # Re-orthonormalise: thousands of steps would otherwise let round-off leave SO(3).
    u, _, vt = np.linalg.svd(new_rotation)
    return Pose.from_trusted_arrays(np.asarray(position, dtype=float), u @ vt)


def _advance_planar(pose: Pose, twist: FloatArray, point: FloatArray, dt: float) -> Pose:
    """SE(2)'s exponential: a turn by ``phi = w dt`` about the point ``point`` carried along ``V v dt``,
    ``V = [[sin phi, cos phi - 1], [1 - cos phi, sin phi]] / phi``; the rotation stays about z exactly."""
    phi = float(twist[2]) * dt
    c, s = math.cos(phi), math.sin(phi)
    if abs(phi) < 1e-8:  # series: the closed forms lose every digit below this angle
        a, b = 1.0 - phi * phi / 6.0, phi / 2.0
    else:
        a, b = s / phi, (1.0 - c) / phi
    vx, vy = float(twist[0]) * dt, float(twist[1]) * dt
    rx, ry = float(pose.position[0] - point[0]), float(pose.position[1] - point[1])
    x = float(point[0]) + c * rx - s * ry + a * vx - b * vy
    y = float(point[1]) + s * rx + c * ry + b * vx + a * vy
    r = pose.rotation
    angle = math.atan2(float(r[1, 0]), float(r[0, 0])) + phi  # from the angle, not a product: no drift off SO(2)
    cn, sn = math.cos(angle), math.sin(angle)
    return Pose.from_trusted_arrays(np.array([x, y, 0.0]), np.array([[cn, -sn, 0.0], [sn, cn, 0.0], [0.0, 0.0, 1.0]]))


def point_velocity(twist: FloatArray, reference: FloatArray, point: FloatArray) -> FloatArray:
    """Velocity of the material point at ``point`` of a body with twist [v of ``reference``, w] (planar: [vx, vy, w])."""
    if len(twist) == 3:
        dx, dy = point[0] - reference[0], point[1] - reference[1]
        return np.array([twist[0] - twist[2] * dy, twist[1] + twist[2] * dx], dtype=float)
    return np.asarray(twist[:3] + np.cross(twist[3:], point - reference), dtype=float)
