"""Rigid-body kinematics of a scene: contact frames, material-point velocities.

Assembly builds its matrices from these; the audit deliberately recomputes
the same quantities its own way (see :mod:`quasistatic.check.audit`), so a
bug here cannot hide from it.
"""

from __future__ import annotations

import numpy as np

from .scene import Contact, FloatArray, Scene

__all__ = ["contact_frames", "mover_point_velocity", "mover_point_velocities"]


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


def contact_frames(normals: FloatArray) -> FloatArray:
    """Each contact's frame, (m, d, d) for unit ``normals`` (m, d): rows are the tangent(s), then the normal.

    Right-handed and deterministic: in 2-D the tangent is the normal turned clockwise; in 3-D the
    first tangent is ``n x e`` (normalised) with ``e`` the axis along the normal's smallest entry
    (the first of equal ones), the second ``n x t1``.
    """
    m, d = normals.shape
    if d == 2:
        return np.stack([np.column_stack([normals[:, 1], -normals[:, 0]]), normals], axis=1)
    axes = np.zeros((m, 3))
    axes[np.arange(m), np.argmin(np.abs(normals), axis=1)] = 1.0
    t1 = np.cross(normals, axes)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return np.stack([t1, np.cross(normals, t1), normals], axis=1)


def mover_point_velocities(scene: Scene) -> FloatArray:
    """:func:`mover_point_velocity` at every contact whose ``other`` is a mover (zero rows for body-body contacts), (m, d)."""
    movers = {m.name: m for m in scene.movers}
    velocities = np.zeros((len(scene.contacts), scene.dimension))
    for i, contact in enumerate(scene.contacts):
        if contact.other in movers:
            velocities[i] = mover_point_velocity(scene, contact)
    return velocities
