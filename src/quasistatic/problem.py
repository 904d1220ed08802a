"""Assembly: a Scene becomes the matrices of the contact laws, in scene-relative units.

Every quantity is divided by the scene's own scales (length, force, velocity),
so one tolerance serves a scene in millimetres and grams as well as one in
metres and kilograms, and the answer does not depend on where the world
origin is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .friction import FrictionModel
from .scene import Scene

__all__ = ["Scales", "Problem", "assemble"]


@dataclass(frozen=True)
class Scales:
    """The scene's own units; internal quantities are physical ones divided by these.

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
    origin: np.ndarray

    @property
    def power(self) -> float:
        """Power unit [force x length/time]."""
        return self.force * self.velocity

    def twist_units(self, dimension: int) -> np.ndarray:
        """Per-entry unit of one body twist: velocity for v, velocity/length for omega."""
        linear, angular = (2, 1) if dimension == 2 else (3, 3)
        return np.r_[np.full(linear, self.velocity), np.full(angular, self.velocity / self.length)]

    def wrench_units(self, dimension: int) -> np.ndarray:
        """Per-entry unit of one body wrench: force, then force x length."""
        linear, angular = (2, 1) if dimension == 2 else (3, 3)
        return np.r_[np.full(linear, self.force), np.full(angular, self.force * self.length)]


@dataclass(frozen=True)
class Problem:
    """The contact laws of one scene in scene-relative units.

    With ``k`` = 3 (2-D) or 6 (3-D) twist entries per body, ``n`` free bodies,
    ``m`` contacts and ``d`` the dimension:

    Attributes
    ----------
    scene : Scene
        The scene this was assembled from (names, order, original data).
    frames : (m, d, d)
        Rows of each contact frame: the tangent(s), then the normal (into ``body``).
    J : (m, d, k n)
        Relative contact velocity per unit twist, in contact frames: ``u = J q - b``.
    b : (m, d)
        Velocity of the other body's material point (movers only), in contact frames.
    g : (k n,)
        Gravity plus applied wrench on each body, about its com.
    mu : (m,)
        Friction coefficients [-], zero under ``friction: none``.
    friction : FrictionModel
    scales : Scales
    """

    scene: Scene
    frames: np.ndarray
    J: np.ndarray
    b: np.ndarray
    g: np.ndarray
    mu: np.ndarray
    friction: FrictionModel
    scales: Scales

    @property
    def dimension(self) -> int:
        return self.scene.dimension

    @property
    def n_contacts(self) -> int:
        return self.J.shape[0]

    @property
    def n_dof(self) -> int:
        return self.J.shape[2]

    @property
    def Jn(self) -> np.ndarray:
        """Normal rows of J, (m, k n)."""
        return self.J[:, -1, :]

    @property
    def Jt(self) -> np.ndarray:
        """Tangent rows of J, (m, d - 1, k n)."""
        return self.J[:, :-1, :]

    @property
    def bn(self) -> np.ndarray:
        return self.b[:, -1]

    @property
    def bt(self) -> np.ndarray:
        return self.b[:, :-1]

    @property
    def is_frictionless(self) -> bool:
        return not np.any(self.mu > 0)

    def with_velocities(self, b: np.ndarray) -> Problem:
        """The same contacts with other prescribed velocities (scene-relative)."""
        return Problem(self.scene, self.frames, self.J, b, self.g, self.mu, self.friction, self.scales)


def assemble(scene: Scene) -> Problem:
    """Build the scene-relative matrices of the contact laws."""
    dim = scene.dimension
    scales = _scales(scene)
    L, V = scales.length, scales.velocity
    k = scene.twist_size
    n_dof = k * len(scene.bodies)
    m = len(scene.contacts)
    frames = np.empty((m, dim, dim))
    J = np.zeros((m, dim, n_dof))
    b = np.zeros((m, dim))
    coms = {body.name: (np.asarray(body.com) - scales.origin) / L for body in scene.bodies}
    for i, contact in enumerate(scene.contacts):
        frames[i] = contact_frame(np.asarray(contact.normal))
        point = (np.asarray(contact.point) - scales.origin) / L
        world = np.zeros((dim, n_dof))
        a = scene.body_index(contact.body)
        world[:, a * k : (a + 1) * k] += _point_velocity_map(point - coms[contact.body])
        if contact.other in coms:
            o = scene.body_index(contact.other)
            world[:, o * k : (o + 1) * k] -= _point_velocity_map(point - coms[contact.other])
        else:
            b[i] = frames[i] @ mover_point_velocity(scene, contact.other, np.asarray(contact.point), contact.jacobian) / V
        J[i] = frames[i] @ world
    g = np.concatenate([_load(body, scene) / scales.wrench_units(dim) for body in scene.bodies])
    mu = np.array([c.mu for c in scene.contacts]) if scene.friction.kind != "none" else np.zeros(m)
    friction = scene.friction
    assert isinstance(friction, FrictionModel)
    return Problem(scene, frames, J, b, g, mu, friction, scales)


def contact_frame(normal: np.ndarray) -> np.ndarray:
    """Rows: tangent(s) then the unit normal; right-handed, deterministic."""
    if normal.size == 2:
        return np.array([[normal[1], -normal[0]], normal])
    axis = np.zeros(3)
    axis[np.argmin(np.abs(normal))] = 1.0
    t1 = np.cross(normal, axis)
    t1 /= np.linalg.norm(t1)
    return np.array([t1, np.cross(normal, t1), normal])


def mover_point_velocity(scene: Scene, name: str, point: np.ndarray, jacobian: object) -> np.ndarray:
    """World velocity of mover ``name``'s material point at ``point`` [length/time]."""
    mover = scene.mover(name)
    if mover.robot is not None:
        return np.asarray(jacobian) @ np.asarray(scene.robot(mover.robot).joint_velocities)
    twist = np.asarray(mover.twist)
    r = point - np.asarray(mover.origin)
    if scene.dimension == 2:
        return twist[:2] + twist[2] * np.array([-r[1], r[0]])
    return twist[:3] + np.cross(twist[3:], r)


def _point_velocity_map(r: np.ndarray) -> np.ndarray:
    """Matrix taking a body twist (v_com, omega) to the velocity of the point com + r."""
    if r.size == 2:
        return np.array([[1.0, 0.0, -r[1]], [0.0, 1.0, r[0]]])
    skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    return np.hstack([np.eye(3), -skew])


def _load(body: object, scene: Scene) -> np.ndarray:
    """Gravity plus applied wrench on a body, about its com [force, force x length]."""
    dim = scene.dimension
    weight = body.mass * np.asarray(scene.gravity)  # type: ignore[attr-defined]
    wrench = np.array(body.wrench, dtype=float)  # type: ignore[attr-defined]
    wrench[:dim] += weight
    return wrench


_SMALLEST_LENGTH = 1e-150  # a length whose square (in moments and inertia-free products) stays a normal float


def _scales(scene: Scene) -> Scales:
    points = np.array([c.point for c in scene.contacts] + [b.com for b in scene.bodies], dtype=float)
    origin = points.mean(axis=0)
    length = float(np.max(np.linalg.norm(points - origin, axis=1)))
    if length <= 0.0:  # every point coincides: only their distance from the world origin sets a size
        length = float(np.max(np.abs(points)))
        if not _SMALLEST_LENGTH <= length <= 1.0 / _SMALLEST_LENGTH:
            length = 1.0
    dim = scene.dimension
    loads = [_load(body, scene) for body in scene.bodies]
    force = max([float(np.linalg.norm(w[:dim])) for w in loads] + [float(np.linalg.norm(w[dim:])) / length for w in loads])
    speeds = [
        float(np.linalg.norm(mover_point_velocity(scene, c.other, np.asarray(c.point), c.jacobian)))
        for c in scene.contacts
        if c.other not in {b.name for b in scene.bodies}
    ]
    velocity = max(speeds, default=0.0)
    origin.setflags(write=False)
    return Scales(length=length, force=force or 1.0, velocity=velocity or 1.0, origin=origin)
