"""Random small scenes for cross-checks: one box against a table and fingertips, fixed seeds.

``random_scene(dimension, seed)`` builds a :class:`quasistatic.Scene` through
the public constructors: a box of random size and mass (com at its centre, or
slightly off it), gravity tilted by up to 25 degrees (a slope), and 2 to 4
contacts drawn from a pool of realistic placements:

- the table under a bottom corner (2-D) or bottom vertex (3-D), fixed;
- a fingertip on a side face (normal along the face's inward normal);
- a fingertip under the bottom face (lifting) or on the top face (pressing);

each with its own ``mu`` uniform in [0.1, 1] (in 3-D table vertices are drawn
three times as often as fingertips, so that boxes can stand). Every fingertip is a separate
mover with a random linear velocity (each entry uniform in [-0.02, 0.02] m/s,
biased toward its face with probability 1/2, zero with probability 1/4) and a
small random angular velocity about its contact point. The same seed always
gives the same scene.
"""

from __future__ import annotations

import numpy as np

import quasistatic as qs

__all__ = ["random_scene"]

_TILT = np.radians(25.0)


def random_scene(dimension: int, seed: int, friction: str = "exact") -> qs.Scene:
    """A random box-on-table/fingers scene in 2-D or 3-D (deterministic in ``seed``; ``friction`` as in Scene)."""
    rng = np.random.default_rng([dimension, seed])
    d = dimension
    half = rng.uniform(0.03, 0.1, size=d)
    centre = np.zeros(d)
    centre[-1] = half[-1]  # the box stands on the plane z = 0 (y = 0 in 2-D)
    com = centre + rng.uniform(-0.3, 0.3, size=d) * half * (rng.random() < 0.5)
    pool = _placements(rng, half, centre)
    count = int(rng.integers(2, 5))
    # In 3-D a box needs three supports to stand: draw table vertices three times as often.
    weights = np.array([3.0 if kind == "table" and d == 3 else 1.0 for kind, _, _ in pool])
    chosen = [pool[i] for i in sorted(rng.choice(len(pool), size=count, replace=False, p=weights / weights.sum()))]
    movers: list[qs.Mover] = []
    contacts: list[qs.Contact] = []
    for index, (kind, point, normal) in enumerate(chosen):
        mu = float(rng.uniform(0.1, 1.0))
        name = "table" if kind == "table" else f"finger{index}"
        if kind != "table":
            movers.append(qs.Mover(name, twist=_finger_twist(rng, d, normal), origin=point))
        contacts.append(qs.Contact("box", name, point=point, normal=normal, mu=mu))
    if any(kind == "table" for kind, _, _ in chosen):
        movers.append(qs.Mover("table"))
    gravity = _tilted_gravity(rng, d)
    body = qs.Body("box", mass=float(rng.uniform(0.2, 2.0)), com=com)
    return qs.Scene(bodies=(body,), movers=tuple(movers), contacts=tuple(contacts), dimension=d, gravity=gravity, friction=friction)


def _placements(rng: np.random.Generator, half: np.ndarray, centre: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Candidate contacts (kind, point, inward normal) on the box surface."""
    d = half.size
    up = np.eye(d)[-1]
    pool: list[tuple[str, np.ndarray, np.ndarray]] = []
    # Table under bottom corners: 2 in 2-D, 4 in 3-D.
    for signs in _corner_signs(d - 1):
        point = centre.copy()
        point[:-1] += signs * half[:-1]
        point[-1] = 0.0
        pool.append(("table", point, up))
    # Fingertips on the side faces, at a random point of the face.
    for axis in range(d - 1):
        for sign in (-1.0, 1.0):
            point = centre + rng.uniform(-0.9, 0.9, size=d) * half
            point[axis] = centre[axis] + sign * half[axis]
            normal = np.zeros(d)
            normal[axis] = -sign
            pool.append(("finger", point, normal))
    # A fingertip on the top face, and one under the bottom face.
    for sign in (-1.0, 1.0):
        point = centre + rng.uniform(-0.9, 0.9, size=d) * half
        point[-1] = centre[-1] + sign * half[-1]
        pool.append(("finger", point, -sign * up))
    return pool


def _corner_signs(k: int) -> list[np.ndarray]:
    if k == 1:
        return [np.array([-1.0]), np.array([1.0])]
    return [np.array([sx, sy]) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]


def _finger_twist(rng: np.random.Generator, d: int, normal: np.ndarray) -> np.ndarray:
    """A random fingertip twist about its contact point [m/s, rad/s]."""
    k = 3 if d == 2 else 6
    roll = rng.random()
    if roll < 0.25:
        return np.zeros(k)
    linear = rng.uniform(-0.02, 0.02, size=d)
    if roll < 0.75:  # pushing into the box
        linear += 0.02 * normal
    angular = rng.uniform(-0.1, 0.1, size=k - d)
    return np.r_[linear, angular]


def _tilted_gravity(rng: np.random.Generator, d: int) -> np.ndarray:
    """9.81 m/s^2 downward, tilted by up to 25 degrees about a random horizontal axis."""
    tilt = rng.uniform(-_TILT, _TILT)
    if d == 2:
        return 9.81 * np.array([np.sin(tilt), -np.cos(tilt)])
    heading = rng.uniform(0.0, 2.0 * np.pi)
    return 9.81 * np.array([np.sin(tilt) * np.cos(heading), np.sin(tilt) * np.sin(heading), -np.cos(tilt)])
