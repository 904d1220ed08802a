"""Many planar one-body scenes of one shape as stacked arrays (a leading point axis), for batched solves.

A sweep's points share their structure: the same body, the same contacts against the same rigid movers, only a
few numbers changed. :class:`PlanarStack` holds each point's numbers as a Scene holds them (world frame,
physical units), so that assembly (:mod:`quasistatic.laws.stacked`) and the audit (:mod:`quasistatic.check.stacked`)
each read them their own way, as they read a Scene, without a Scene per point.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .scene import FloatArray, Scene

__all__ = ["PlanarStack", "stackable"]


@dataclass(frozen=True)
class PlanarStack:
    """``N`` planar scenes of one free body, each contact against a rigidly moving mover (N points, m contacts).

    Attributes
    ----------
    scene : Scene
        One of them (names, order, friction model): every other number below is per point.
    point, normal : (N, m, 2)
        Contact points [length] and unit normals into the body.
    mu : (N, m)
        Friction coefficients [-].
    mass : (N,)
        The body's mass [mass].
    com : (N, 2)
        Its centre of mass [length].
    wrench : (N, 3)
        Applied wrench on it about its com [force, force x length].
    gravity : (N, 2)
        [length / time^2].
    twist, origin : (N, m, 3), (N, m, 2)
        Each contact's mover: its twist [length/time, rad/time] and the point that twist is about [length].
    """

    scene: Scene
    point: FloatArray
    normal: FloatArray
    mu: FloatArray
    mass: FloatArray
    com: FloatArray
    wrench: FloatArray
    gravity: FloatArray
    twist: FloatArray
    origin: FloatArray

    @property
    def size(self) -> int:
        """Points in the stack."""
        return int(self.mu.shape[0])

    def loads(self) -> FloatArray:
        """Gravity plus applied wrench on the body, about its com (N, 3), as :meth:`Scene.load` adds them."""
        load = self.wrench.copy()
        load[:, :2] += self.mass[:, None] * self.gravity
        return load

    def taken(self, members: np.ndarray) -> PlanarStack:
        """The stack of the points ``members`` (indices) only."""
        arrays = {f.name: getattr(self, f.name)[members] for f in fields(self) if f.name != "scene"}
        return PlanarStack(self.scene, **arrays)

    @classmethod
    def tiled(cls, scene: Scene, count: int) -> PlanarStack:
        """``count`` copies of ``scene`` (check :func:`stackable` first), to be changed in place by the caller."""
        movers = {mover.name: mover for mover in scene.movers}
        body = scene.bodies[0]
        rows = [movers[c.other] for c in scene.contacts]

        def tile(values: object) -> FloatArray:
            array = np.asarray(values, dtype=float)
            return np.array(np.broadcast_to(array, (count, *array.shape)))  # a writable copy per point

        return cls(
            scene,
            tile([c.point for c in scene.contacts]),
            tile([c.normal for c in scene.contacts]),
            tile([c.mu for c in scene.contacts]),
            tile(body.mass),
            tile(body.com),
            tile(np.zeros(3) if body.wrench is None else body.wrench),
            tile(scene.gravity),
            tile([mover.twist for mover in rows]),
            tile([mover.origin for mover in rows]),
        )


def stackable(scene: Scene) -> bool:
    """Whether ``scene`` is of the shape a :class:`PlanarStack` holds: 2-D, one free body, every contact against a
    rigid mover (no robot, no other body), friction on the plane's exact cone, no stiffness."""
    if scene.dimension != 2 or len(scene.bodies) != 1 or not scene.contacts or scene.robots or scene.friction.kind == "none":
        return False
    if scene.compliant or scene.closing_time is not None:
        return False
    movers = {mover.name: mover for mover in scene.movers}
    return all(c.other in movers and movers[c.other].robot is None and c.jacobian is None for c in scene.contacts)
