"""The commanded inputs of a scene as one vector: robot joint velocities, then rigid movers' twists.

Sensitivities differentiate with respect to this vector and the planner solves
for part of it. Each contact's mover point velocity is linear in it
(:meth:`InputVector.point_velocity_map`), which is all the contact laws see of it.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..model import FloatArray, Mover, Robot, Scene
from ..model.kinematics import cross

__all__ = ["Input", "InputVector", "twist_components"]


def twist_components(dimension: int) -> tuple[str, ...]:
    """Names of a twist's entries: linear velocity, then angular velocity."""
    return ("v_x", "v_y", "omega_z") if dimension == 2 else ("v_x", "v_y", "v_z", "omega_x", "omega_y", "omega_z")


@dataclass(frozen=True)
class Input:
    """One commanded number: joint ``index`` of robot ``owner``, or entry ``index`` of mover ``owner``'s twist.

    ``name`` reads ``hand.joint[1]`` or ``pusher.v_x``.
    """

    owner: str
    kind: Literal["joint", "twist"]
    index: int
    name: str


@dataclass(frozen=True)
class InputVector:
    """An ordered selection of a scene's inputs [joint: rad/time or length/time; twist: length/time, rad/time]."""

    entries: tuple[Input, ...]

    @classmethod
    def of(cls, scene: Scene, owners: Collection[str] | None = None) -> InputVector:
        """Every robot's joints (scene order), then every rigid mover's twist; only ``owners`` (names) when given."""
        entries: list[Input] = []
        for robot in scene.robots:
            entries += [Input(robot.name, "joint", j, f"{robot.name}.{label}") for j, label in enumerate(robot.joint_labels())]
        for mover in scene.movers:
            if mover.robot is None:
                components = twist_components(scene.dimension)
                entries += [Input(mover.name, "twist", a, f"{mover.name}.{c}") for a, c in enumerate(components)]
        if owners is not None:
            entries = [e for e in entries if e.owner in owners]
        return cls(tuple(entries))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.entries)

    @property
    def size(self) -> int:
        return len(self.entries)

    def values(self, scene: Scene) -> FloatArray:
        """The scene's current value of each input, (P,)."""
        return np.array([_value(scene, e) for e in self.entries], dtype=float)

    def apply(self, scene: Scene, values: FloatArray) -> Scene:
        """A new Scene with these inputs set to ``values`` (P,); everything else as in ``scene``."""
        joints = {r.name: np.array(r.joint_velocities, dtype=float) for r in scene.robots}
        twists = {m.name: np.array(m.twist, dtype=float) for m in scene.movers if m.robot is None}
        for entry, value in zip(self.entries, np.asarray(values, dtype=float), strict=True):
            (joints if entry.kind == "joint" else twists)[entry.owner][entry.index] = value
        robots = [
            Robot(r.name, joints[r.name], joint_names=r.joint_names, torque_limits=r.torque_limits, joint_stiffness=r.joint_stiffness)
            for r in scene.robots
        ]
        # A Scene fills in a robot-driven mover's twist with zeros, which a new Scene refuses: rebuilt without it.
        movers = [Mover(m.name, None if m.robot else twists[m.name], m.origin, m.robot) for m in scene.movers]
        dimension, gravity, friction = scene.dimension, scene.gravity, scene.friction
        return Scene(scene.bodies, scene.contacts, movers, robots, dimension, gravity, friction, scene.stiffness, scene.closing_time)

    def point_velocity_map(self, scene: Scene) -> FloatArray:
        """World velocity of each contact's mover point per unit input, (m, d, P) [length/time per input unit].

        Zero at contacts between free bodies and at movers not selected.
        """
        d, m = scene.dimension, len(scene.contacts)
        W = np.zeros((m, d, self.size))
        movers = {mv.name: mv for mv in scene.movers}
        for i, contact in enumerate(scene.contacts):
            mover = movers.get(contact.other)
            if mover is None:
                continue
            for p, entry in enumerate(self.entries):
                if entry.kind == "joint" and mover.robot == entry.owner:
                    assert contact.jacobian is not None  # a Scene guarantees it for robot-driven movers
                    W[i, :, p] = contact.jacobian[:, entry.index]
                elif entry.kind == "twist" and mover.name == entry.owner:
                    assert mover.origin is not None  # filled in by the Scene
                    W[i, :, p] = _twist_column(d, entry.index, contact.point - mover.origin)
        return W


def _value(scene: Scene, entry: Input) -> float:
    if entry.kind == "joint":
        return float(scene.robot(entry.owner).joint_velocities[entry.index])
    twist = scene.mover(entry.owner).twist
    assert twist is not None  # filled in by the Scene
    return float(twist[entry.index])


def _twist_column(d: int, axis: int, r: FloatArray) -> FloatArray:
    """Velocity of the point at ``r`` from the mover's origin per unit of twist entry ``axis``."""
    if axis < d:
        return np.eye(d)[axis]
    if d == 2:
        return np.array([-r[1], r[0]])
    return cross(np.eye(3)[axis - 3], r)
