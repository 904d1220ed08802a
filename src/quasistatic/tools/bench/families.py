"""Benchmark problem families, generated in code from fixed seeds (nothing is stored).

Every family builds its scenes through the public :class:`~quasistatic.Scene`
API. A family is a named generator ``make(size, instance) -> Scene`` with the
sizes of the quick (CI) and full runs; the same ``(size, instance)`` always
gives the same scene.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...model import Body, Contact, Mover, Scene

__all__ = ["Family", "FAMILIES", "grasp_2d", "grasp_3d", "box_push", "box_rest", "pile"]


@dataclass(frozen=True)
class Family:
    """A parametrised set of benchmark scenes.

    Attributes
    ----------
    name : str
        Row label, e.g. ``grasp-2d``.
    description : str
        One line: what the scenes are.
    make : callable (size, instance) -> Scene
        Deterministic scene generator.
    quick_sizes, full_sizes : tuple of int
        Sizes (contacts, support points or boxes; see ``size_label``) of each
        run; an empty quick tuple keeps the family to the full run.
    quick_instances, full_instances : int
        Scenes per size (different seeds).
    size_label : str
        What ``size`` counts.
    frictionless : bool
        Every contact is frictionless (``friction: none``): the LP is the reference.
    """

    name: str
    description: str
    make: Callable[[int, int], Scene]
    quick_sizes: tuple[int, ...]
    full_sizes: tuple[int, ...]
    quick_instances: int
    full_instances: int
    size_label: str
    frictionless: bool = False

    def sizes(self, full: bool) -> tuple[int, ...]:
        return self.full_sizes if full else self.quick_sizes

    def instances(self, full: bool) -> int:
        return self.full_instances if full else self.quick_instances


def _rng(*key: object) -> np.random.Generator:
    """A generator seeded from a fixed key (stable across runs and platforms)."""
    return np.random.default_rng(zlib.crc32(repr(key).encode()))


def _spread_angles(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` angles around the circle, jittered from even spacing so no two coincide."""
    base = np.arange(n) * 2.0 * np.pi / n + rng.uniform(0.0, 2.0 * np.pi)
    return base + rng.uniform(-0.35, 0.35, n) * np.pi / n


def grasp_2d(n_contacts: int, instance: int, friction: str = "exact") -> Scene:
    """An ellipse (semi-axes 6 cm and 3.5 cm) held by ``n_contacts`` point fingers moving at random.

    Each finger's velocity is the velocity its contact point would have under
    a random object twist, plus tangential noise (30 % of that speed) and, for
    one finger in four, a retreat along the normal: the mix of rolling,
    sliding and separating that random finger motions produce (see
    :func:`_finger_velocity`). mu is drawn from U[0.1, 1] per contact. The
    shape is not a disc so that the normals do not all meet at one point.
    """
    rng = _rng("grasp-2d", n_contacts, instance)
    axes = np.array([0.06, 0.035])
    angles = _spread_angles(rng, n_contacts)
    twist = np.r_[rng.normal(0.0, 0.01, 2), rng.normal(0.0, 0.2)]
    movers, contacts = [], []
    for i, angle in enumerate(angles):
        unit = np.array([np.cos(angle), np.sin(angle)])
        point = axes * unit
        inward = -unit / axes / np.linalg.norm(unit / axes)
        velocity = _finger_velocity(rng, twist[:2] + twist[2] * np.array([-point[1], point[0]]), inward)
        name = f"finger{i}"
        movers.append(Mover(name, twist=[velocity[0], velocity[1], 0.0], origin=point))
        contacts.append(Contact("object", name, point=point, normal=inward, mu=float(rng.uniform(0.1, 1.0))))
    com = rng.uniform(-0.005, 0.005, 2).tolist()
    return Scene(
        dimension=2,
        bodies=(Body("object", mass=0.2, com=com),),
        movers=tuple(movers),
        contacts=tuple(contacts),
        friction=friction,
    )


def grasp_3d(n_contacts: int, instance: int, friction: str = "exact") -> Scene:
    """An ellipsoid (semi-axes 6, 4.5 and 3.5 cm) held by ``n_contacts`` translating point fingers.

    Finger motions and mu are drawn as in :func:`grasp_2d`.
    """
    rng = _rng("grasp-3d", n_contacts, instance)
    axes = np.array([0.06, 0.045, 0.035])
    directions = _sphere_points(rng, n_contacts)
    twist = np.r_[rng.normal(0.0, 0.01, 3), rng.normal(0.0, 0.2, 3)]
    movers, contacts = [], []
    for i, unit in enumerate(directions):
        point = axes * unit
        inward = -unit / axes / np.linalg.norm(unit / axes)
        velocity = _finger_velocity(rng, twist[:3] + np.cross(twist[3:], point), inward)
        name = f"finger{i}"
        movers.append(Mover(name, twist=[*velocity, 0.0, 0.0, 0.0], origin=point))
        contacts.append(Contact("object", name, point=point, normal=inward, mu=float(rng.uniform(0.1, 1.0))))
    com = rng.uniform(-0.005, 0.005, 3).tolist()
    return Scene(
        dimension=3,
        bodies=(Body("object", mass=0.2, com=com),),
        movers=tuple(movers),
        contacts=tuple(contacts),
        friction=friction,
    )


def _finger_velocity(rng: np.random.Generator, point_velocity: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """A finger velocity near the object's point velocity that never drives the finger into the object.

    ``normal`` points into the object. Tangential noise is 30 % of the speed;
    one finger in four also retreats along the normal by 10 to 50 % of it.
    """
    speed = max(float(np.linalg.norm(point_velocity)), 1e-3)
    noise = rng.normal(0.0, 0.3 * speed, normal.size)
    noise -= (noise @ normal) * normal
    retreat = rng.uniform(0.1, 0.5) * speed if rng.uniform() < 0.25 else 0.0
    return point_velocity + noise - retreat * normal


def _sphere_points(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` unit vectors spread over the sphere (jittered Fibonacci lattice, randomly rotated)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k + rng.uniform(-0.3, 0.3, n)
    r = np.sqrt(1.0 - z**2)
    points = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    points = points @ q.T
    return points / np.linalg.norm(points, axis=1, keepdims=True)


def box_push(n_support: int, instance: int, friction: str = "exact") -> Scene:
    """A 10 cm cube on a table, pushed at one side by a fingertip.

    The support face is discretised into ``n_support`` contact points (a
    square grid; ``n_support`` must be a square), which makes the support
    forces statically indeterminate. With friction (table mu 0.3 to 0.6,
    finger mu 0.5) the finger pushes off-centre, so the box slides and turns.
    Frictionless (``friction="none"``), a frictionless push is undetermined
    (the box may run ahead of the finger, slide sideways or turn), so the
    table is tilted by about 6 degrees against the push and two guide rails
    (two contacts each) hold the box's sideways motion and yaw: the push then
    has one answer.
    """
    rng = _rng("box-push", n_support, instance)
    side = int(round(n_support**0.5))
    if side * side != n_support:
        raise ValueError(f"n_support must be a square number, got {n_support}")
    half = 0.05
    grid = np.linspace(-half, half, side) if side > 1 else np.zeros(1)
    mu_table = float(rng.uniform(0.3, 0.6))
    contacts = [Contact("box", "table", point=[x, y, 0.0], normal=[0.0, 0.0, 1.0], mu=mu_table) for x in grid for y in grid]
    offset = float(rng.uniform(-0.02, 0.02))
    contacts.append(Contact("box", "finger", point=[-half, offset, 0.03], normal=[1.0, 0.0, 0.0], mu=0.5))
    movers = [Mover("table"), Mover("finger", twist=[0.01, 0.0, 0.0, 0.0, 0.0, 0.0])]
    gravity = None
    if friction == "none":
        gravity = [-1.0, 0.0, -9.76]
        movers.append(Mover("rails"))
        for sign in (1.0, -1.0):
            for x in (-0.04, 0.04):
                contacts.append(Contact("box", "rails", point=[x, sign * half, 0.05], normal=[0.0, -sign, 0.0]))
    return Scene(
        dimension=3,
        bodies=(Body("box", mass=1.0, com=[0.0, 0.0, half]),),
        movers=tuple(movers),
        contacts=tuple(contacts),
        gravity=gravity,
        friction=friction,
    )


def box_rest(n_support: int, instance: int, friction: str = "exact") -> Scene:
    """A 10 cm cube resting on a table under gravity alone, its support face a square grid of ``n_support`` points.

    mu 0.5; no mover moves. Large grids (10,000 points) are the memory test of
    the frictional methods: their dense matrices would grow as the square of the
    contacts, so they answer an honest ``failed`` with the audited rest motion.
    """
    side = int(round(n_support**0.5))
    if side * side != n_support:
        raise ValueError(f"n_support must be a square number, got {n_support}")
    half = 0.05
    grid = np.linspace(-half, half, side) if side > 1 else np.zeros(1)
    contacts = tuple(Contact("box", "table", point=[x, y, 0.0], normal=[0.0, 0.0, 1.0], mu=0.5) for x in grid for y in grid)
    body = Body("box", mass=1.0, com=[0.0, 0.0, half])
    return Scene(dimension=3, bodies=(body,), movers=(Mover("table"),), contacts=contacts, friction=friction)


def pile(n_boxes: int, instance: int, friction: str = "exact") -> Scene:
    """A planar pile of ``n_boxes`` 10 cm boxes in columns of at most 10, pushed at the side.

    Boxes rest on each other and on a table (two contacts per support face)
    and touch their neighbours in the next column (two contacts per side
    face); a fingertip pushes the bottom box of the first column sideways. mu
    between boxes is drawn from U[0.3, 0.8]. Frictionless, the upper boxes
    would be free to slide either way, so gravity is tilted by about 6
    degrees away from the push and a wall holds the first column above its
    bottom box (the finger pushes through a slot under it): the bottom row
    slides out and the rest stays, one answer.
    """
    rng = _rng("pile", n_boxes, instance)
    size, height = 0.1, min(n_boxes, 10)
    bodies, contacts = [], []
    names: dict[tuple[int, int], str] = {}
    for index in range(n_boxes):
        col, row = divmod(index, height)
        name = f"box{col}_{row}"
        names[col, row] = name
        bodies.append(Body(name, mass=0.5, com=[col * size, (row + 0.5) * size]))
    for (col, row), name in names.items():
        x0, y0 = col * size - size / 2, row * size
        below = names.get((col, row - 1), "table")
        for dx in (0.0, size):
            contacts.append(Contact(name, below, point=[x0 + dx, y0], normal=[0.0, 1.0], mu=float(rng.uniform(0.3, 0.8))))
        right = names.get((col + 1, row))
        if right is not None:
            for dy in (0.0, size):
                contacts.append(Contact(right, name, point=[x0 + size, y0 + dy], normal=[1.0, 0.0], mu=float(rng.uniform(0.3, 0.8))))
    contacts.append(Contact(names[0, 0], "finger", point=[-size / 2, 0.03], normal=[1.0, 0.0], mu=0.5))
    movers = [Mover("table"), Mover("finger", twist=[0.01, 0.0, 0.0])]
    gravity = None
    if friction == "none":
        gravity = [-1.0, -9.76]
        movers.append(Mover("wall"))
        for row in range(1, height):
            for dy in (0.0, size):
                contacts.append(Contact(names[0, row], "wall", point=[-size / 2, row * size + dy], normal=[1.0, 0.0]))
    return Scene(dimension=2, bodies=tuple(bodies), movers=tuple(movers), contacts=tuple(contacts), gravity=gravity, friction=friction)


def _variant(make: Callable[..., Scene], friction: str) -> Callable[[int, int], Scene]:
    def build(size: int, instance: int) -> Scene:
        return make(size, instance, friction=friction)

    build.__name__ = f"{make.__name__}_{friction}"
    return build


FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family(
            "grasp-2d",
            "ellipse held by point fingers moving at random, exact 2-D cones, mu ~ U[0.1, 1]",
            _variant(grasp_2d, "exact"),
            quick_sizes=(2, 4, 8),
            full_sizes=(2, 3, 4, 6, 8),
            quick_instances=3,
            full_instances=6,
            size_label="contacts",
        ),
        Family(
            "grasp-2d-nf",
            "the grasp-2d scenes with friction: none (linprog on their velocity LP: the speed targets' yardstick)",
            _variant(grasp_2d, "none"),
            quick_sizes=(2, 4, 8),
            full_sizes=(2, 3, 4, 6, 8),
            quick_instances=3,
            full_instances=6,
            size_label="contacts",
            frictionless=True,
        ),
        Family(
            "grasp-3d",
            "ellipsoid held by point fingers moving at random, exact 3-D cones, mu ~ U[0.1, 1]",
            _variant(grasp_3d, "exact"),
            quick_sizes=(4, 8),
            full_sizes=(4, 6, 8),
            quick_instances=1,
            full_instances=2,
            size_label="contacts",
        ),
        Family(
            "grasp-3d-nf",
            "the grasp-3d scenes with friction: none",
            _variant(grasp_3d, "none"),
            quick_sizes=(4, 8),
            full_sizes=(2, 4, 6, 8),
            quick_instances=3,
            full_instances=8,
            size_label="contacts",
            frictionless=True,
        ),
        Family(
            "box-push",
            "10 cm cube on a table pushed off-centre by a fingertip, support grid of N points",
            _variant(box_push, "exact"),
            quick_sizes=(),
            full_sizes=(4, 16, 64),
            quick_instances=1,
            full_instances=1,
            size_label="support points",
        ),
        Family(
            "box-push-nf",
            "the cube with friction: none, pushed up a 6-degree slope between two guide rails",
            _variant(box_push, "none"),
            quick_sizes=(4, 16, 64),
            full_sizes=(4, 16, 64, 256, 1024),
            quick_instances=1,
            full_instances=1,
            size_label="support points",
            frictionless=True,
        ),
        Family(
            "box-rest",
            "10 cm cube resting on a grid of N frictional support points under gravity, exact cones",
            _variant(box_rest, "exact"),
            quick_sizes=(),
            full_sizes=(10000,),
            quick_instances=1,
            full_instances=1,
            size_label="support points",
        ),
        Family(
            "pile",
            "planar pile of N boxes in columns of 10, pushed at the bottom of the first column",
            _variant(pile, "exact"),
            quick_sizes=(),
            full_sizes=(10, 100),
            quick_instances=1,
            full_instances=1,
            size_label="boxes",
        ),
        Family(
            "pile-nf",
            "the pile with friction: none, tilted gravity, a wall holding the first column",
            _variant(pile, "none"),
            quick_sizes=(10,),
            full_sizes=(10, 100, 1000),
            quick_instances=1,
            full_instances=1,
            size_label="boxes",
            frictionless=True,
        ),
    )
}
