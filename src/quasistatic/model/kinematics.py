"""Rigid-body kinematics of a scene: contact frames, material-point velocities.

Assembly builds its matrices from these; the audit deliberately recomputes
the same quantities its own way (see :mod:`quasistatic.check.audit`), so a
bug here cannot hide from it.
"""

from __future__ import annotations

import numpy as np

from ..compiled import stack_rows
from .scene import Contact, FloatArray, Scene

__all__ = ["contact_frames", "cross", "mover_parts", "mover_point_velocity", "mover_point_velocities"]

_TURN = np.array([-1.0, 1.0])  # (r_y, r_x) to (-r_y, r_x): a vector turned a quarter turn counter-clockwise
_TURN.setflags(write=False)


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
    return np.asarray(twist[:3] + cross(twist[3:], r), dtype=float)


def contact_frames(normals: FloatArray) -> FloatArray:
    """Each contact's frame, (m, d, d) for unit ``normals`` (m, d): rows are the tangent(s), then the normal.

    Right-handed and deterministic: in 2-D the tangent is the normal turned clockwise; in 3-D the
    first tangent is ``n x e`` (normalised) with ``e`` the axis along the normal's smallest entry
    (the first of equal ones), the second ``n x t1``.
    """
    m, d = normals.shape
    if d == 2:
        frames = np.empty((m, 2, 2))  # filled in place: stacking columns costs more than the numbers on small scenes
        frames[:, 0, 0], frames[:, 0, 1], frames[:, 1, :] = normals[:, 1], -normals[:, 0], normals
        return frames
    axes = np.zeros((m, 3))
    axes[np.arange(m), np.argmin(np.abs(normals), axis=1)] = 1.0
    t1 = cross(normals, axes)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return np.stack([t1, cross(normals, t1), normals], axis=1)


def mover_point_velocities(scene: Scene) -> FloatArray:
    """:func:`mover_point_velocity` at every contact whose ``other`` is a mover (zero rows for body-body contacts), (m, d).

    Rigidly moving movers all at once (``v + omega x r``); robot links through their Jacobians.
    """
    twists, origins, places, driven = mover_parts(scene)
    r = places - origins
    if scene.dimension == 2:
        spin = twists[:, 2:3] * r[:, ::-1] * _TURN  # omega x r in the plane: omega (-r_y, r_x)
        return driven + twists[:, :2] + spin
    return driven + twists[:, :3] + cross(twists[:, 3:], r)


def mover_parts(scene: Scene) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """What each contact's mover point velocity is made of: the twist (m, k) and origin (m, d) of a rigidly
    moving mover with the contact point (m, d), and a robot link's point velocity through its Jacobian (m, d);
    zero rows where they do not apply (a body-body contact has all four zero)."""
    movers = {m.name: m for m in scene.movers}
    d, k = scene.dimension, scene.twist_size
    no_twist, no_point = np.zeros(k), np.zeros(d)
    twists, origins, places, driven = [], [], [], []  # rows, stacked at the end (cheaper than filling arrays row by row)
    for contact in scene.contacts:
        mover = movers.get(contact.other)
        twist, origin, place, through_joints = no_twist, no_point, no_point, no_point
        if mover is not None and mover.robot is not None:
            through_joints = mover_point_velocity(scene, contact)
        elif mover is not None:
            assert mover.twist is not None and mover.origin is not None  # filled in by the Scene
            twist, origin, place = mover.twist, mover.origin, contact.point
        twists.append(twist)
        origins.append(origin)
        places.append(place)
        driven.append(through_joints)
    return stack_rows(twists, k), stack_rows(origins, d), stack_rows(places, d), stack_rows(driven, d)


def cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a x b`` over the last axis of 3-vectors, broadcast (``np.cross`` costs ~50 us a call in its axis handling)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)
