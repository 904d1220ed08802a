"""Rigid-body kinematics of a scene: contact frames, material-point velocities.

Assembly builds its matrices from these; the audit deliberately recomputes
the same quantities its own way (see :mod:`quasistatic.check.audit`), so a
bug here cannot hide from it.
"""

from __future__ import annotations

import numpy as np

from .scene import Contact, FloatArray, Scene

__all__ = ["contact_frame", "point_velocity_map", "mover_point_velocity"]


def contact_frame(normal: FloatArray) -> FloatArray:
    """Rows: tangent(s) then the unit normal; right-handed, deterministic. Shape (d, d)."""
    if normal.size == 2:
        return np.array([[normal[1], -normal[0]], normal])
    axis = np.zeros(3)
    axis[np.argmin(np.abs(normal))] = 1.0
    t1 = np.cross(normal, axis)
    t1 /= np.linalg.norm(t1)
    return np.array([t1, np.cross(normal, t1), normal])


def point_velocity_map(r: FloatArray) -> FloatArray:
    """Matrix taking a body twist (v_com, omega) to the velocity of the point com + r: (2, 3) or (3, 6)."""
    if r.size == 2:
        return np.array([[1.0, 0.0, -r[1]], [0.0, 1.0, r[0]]])
    skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    return np.hstack([np.eye(3), -skew])


def mover_point_velocity(scene: Scene, contact: Contact) -> FloatArray:
    """World velocity of the mover ``contact.other``'s material point at the contact point [length/time]."""
    mover = scene.mover(contact.other)
    if mover.robot is not None:
        assert contact.jacobian is not None  # a Scene guarantees it for robot-driven movers
        return np.asarray(contact.jacobian @ scene.robot(mover.robot).joint_velocities, dtype=float)
    assert mover.twist is not None and mover.origin is not None  # filled in by the Scene
    twist = mover.twist
    r = contact.point - mover.origin
    if scene.dimension == 2:
        return np.asarray(twist[:2] + twist[2] * np.array([-r[1], r[0]]), dtype=float)
    return np.asarray(twist[:3] + np.cross(twist[3:], r), dtype=float)
