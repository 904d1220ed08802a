"""A world of shapes and robots, and the point-contact :class:`Scene` it gives at this instant.

:class:`World` holds what a user describes: free bodies with shapes and
poses, movers with shapes and twists, URDF robots at a configuration with
their joint velocities, the contact-detection settings, and any explicit
contacts. :meth:`World.detect` finds the contacts with coal
(:mod:`.detect`); :meth:`World.scene` turns them into the Scene the solvers
read: one ``Contact`` per point with its normal into the free body, its
friction coefficient and, for a robot link, the link's point Jacobian.

A body's ``com`` is given in the body's frame (its ``pose``); with no pose
the body frame is the world frame, as in an explicit scene.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import Body, Contact, FrictionModel, Mover, Robot, Scene, Stiffness
from ..tolerances import DETECTION_MARGIN
from .detect import Collider, ContactPoint, detect, nearest_gaps
from .robot import UrdfRobot, link_owner
from .shapes import Pose, Shape

__all__ = ["SolidBody", "ShapedMover", "FrictionPair", "ContactDetection", "Detection", "World"]

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SolidBody:
    """A free body: its shape (optional), pose, mass, centre of mass in its own frame, and applied wrench."""

    name: str
    mass: float
    shape: Shape | None = None
    pose: Pose = field(default_factory=Pose)
    com: npt.ArrayLike = (0.0, 0.0, 0.0)
    wrench: npt.ArrayLike | None = None

    def body(self) -> Body:
        """The solver's Body: the com in the world frame."""
        return Body(self.name, self.mass, self.pose.apply(np.asarray(self.com, dtype=float)), self.wrench)


@dataclass(frozen=True)
class ShapedMover:
    """A body with a prescribed motion: its shape (optional), pose, and twist [v of the pose origin, w] in the world frame."""

    name: str
    shape: Shape | None = None
    pose: Pose = field(default_factory=Pose)
    twist: npt.ArrayLike | None = None

    def mover(self) -> Mover:
        return Mover(self.name, self.twist, origin=self.pose.position)


@dataclass(frozen=True)
class FrictionPair:
    """The friction coefficient between two names: bodies, movers, robots (all their links) or links (``robot/link``)."""

    between: tuple[str, str]
    mu: float


@dataclass(frozen=True)
class StiffnessPair:
    """The contact stiffness between two names (as :class:`FrictionPair`): every detected contact between them."""

    between: tuple[str, str]
    stiffness: Stiffness


@dataclass(frozen=True)
class ContactDetection:
    """What counts as a contact and its friction.

    ``margin``: gaps up to this count as contacts [length]; None means :data:`DETECTION_MARGIN` times the
    largest free body's size, so a scene in millimetres finds the same contacts as one in metres.
    ``mu``: the default friction coefficient; ``pairs`` override it.
    ``stiffness``: the default stiffness of a detected contact (None: the scene's, else rigid);
    ``stiffness_pairs`` override it.
    """

    margin: float | None = None
    mu: float = 0.0
    pairs: tuple[FrictionPair, ...] = ()
    stiffness: Stiffness | None = None
    stiffness_pairs: tuple[StiffnessPair, ...] = ()


@dataclass(frozen=True)
class Detection:
    """The contacts found, and for each free body with none, the nearest surface and its distance."""

    contacts: tuple[Contact, ...]
    gaps: tuple[float, ...]  # per contact: > 0 apart (within the margin), < 0 overlapping [length]
    margin: float
    isolated: Mapping[str, tuple[str, float]]  # free body -> (nearest other, gap)

    def notes(self) -> tuple[str, ...]:
        """One line per free body that touches nothing, for the answer's notes."""
        return tuple(
            f"no contact within the margin {self.margin:.3g} for body {name!r}; the nearest surface is {other!r}, {gap:.3g} away"
            if other
            else f"no contact for body {name!r}: nothing else in the scene has a shape"
            for name, (other, gap) in self.isolated.items()
        )


@dataclass(frozen=True)
class World:
    """Shapes, robots and explicit contacts: a scene before its contacts are found."""

    bodies: tuple[SolidBody, ...]
    movers: tuple[ShapedMover, ...] = ()
    robots: tuple[UrdfRobot, ...] = ()
    explicit_robots: tuple[Robot, ...] = ()
    contacts: tuple[Contact, ...] = ()
    detection: ContactDetection = field(default_factory=ContactDetection)
    gravity: npt.ArrayLike | None = None
    friction: FrictionModel | str = "exact"
    stiffness: Stiffness | None = None  # the Scene's default: every contact without a stiffness of its own
    closing_time: float | None = None  # the Scene's: how long the movers advance against the springs

    def __post_init__(self) -> None:
        parts: list[SolidBody | ShapedMover] = [*self.bodies, *self.movers]
        known = {p.name for p in parts} | {r.name for r in self.robots} | set(self._robot_links())
        named = [("friction.pairs", p.between) for p in self.detection.pairs]
        named += [("stiffness.pairs", p.between) for p in self.detection.stiffness_pairs]
        counts: dict[str, int] = {}
        for key, between in named:
            index = counts[key] = counts.get(key, -1) + 1
            for name in between:
                if name not in known:
                    field = f"contact_detection.{key}[{index}].between"
                    raise SceneError(field, name, "names no body, mover, robot or robot link (robot/link) of the scene")

    def detect(self) -> Detection:
        """The contacts within the margin, as solver contacts (normals into the free body, Jacobians for robot links)."""
        colliders = self._colliders()
        margin = self._margin()
        free = frozenset(b.name for b in self.bodies)

        def may_touch(first: str, second: str) -> bool:
            """Only pairs with a free body constrain its motion; two links of one robot, or two movers, never do."""
            return first in free or second in free

        points = detect(colliders, may_touch, margin)
        links = self._robot_links()
        contacts = tuple(self._contact(point, free, links) for point in points)
        touched = {c.body for c in contacts} | {c.other for c in contacts} | {c.body for c in self.contacts}
        lonely = [b.name for b in self.bodies if b.name not in touched and b.shape is not None]
        isolated = nearest_gaps(colliders, lonely, may_touch) if lonely else {}
        return Detection(contacts, tuple(p.gap for p in points), margin, isolated)

    def scene(self, detection: Detection | None = None) -> Scene:
        """The point-contact Scene at this instant: detected contacts first, then the explicit ones."""
        detection = detection or self.detect()
        contacts = detection.contacts + self.contacts
        robot_links = self._robot_links()
        links = sorted({c.other for c in contacts if c.other in robot_links})
        return Scene(
            bodies=[b.body() for b in self.bodies],
            movers=[m.mover() for m in self.movers] + [Mover(link, robot=robot_links[link][0].name) for link in links],
            robots=[_robot(r) for r in self.robots] + list(self.explicit_robots),
            contacts=contacts,
            dimension=3,
            gravity=self.gravity,
            friction=self.friction,
            stiffness=self.stiffness,
            closing_time=self.closing_time,
        )

    @property
    def contact_margin(self) -> float:
        """Gaps up to this count as contacts [length]: ``detection.margin``, or the default relative to the bodies' size."""
        return self._margin()

    @property
    def size(self) -> float:
        """The largest free body's size [length] (1 when no body has a shape)."""
        return max((b.shape.extent for b in self.bodies if b.shape is not None), default=1.0)

    # ----------------------------------------------------------------- parts

    def _robot_links(self) -> dict[str, tuple[UrdfRobot, str]]:
        """Each robot link's name as a mover (``hand/link``): its robot and link."""
        return {link_owner(r.name, link): (r, link) for r in self.robots for link in r.link_names}

    def _colliders(self) -> list[Collider]:
        parts: list[SolidBody | ShapedMover] = [*self.bodies, *self.movers]
        shaped = [Collider(p.name, p.shape, p.pose) for p in parts if p.shape is not None]
        return shaped + [Collider(c.owner, c.shape, c.pose) for r in self.robots for c in r.colliders]

    def _margin(self) -> float:
        if self.detection.margin is not None:
            return self.detection.margin
        return DETECTION_MARGIN * self.size

    def _contact(self, point: ContactPoint, free: frozenset[str], links: dict[str, tuple[UrdfRobot, str]]) -> Contact:
        """A solver contact: the free body first, its normal into it; a robot link's Jacobian at the point."""
        body, other, normal = point.first, point.second, point.normal
        if body not in free:
            body, other, normal = other, body, -normal
        robot_link = links.get(other)
        jacobian = None if robot_link is None else robot_link[0].point_jacobian(robot_link[1], point.point)
        # A friction pair may name a robot link's whole robot.
        others = {other} if robot_link is None else {other, robot_link[0].name}
        stiffness = self._stiffness(body, others)
        return Contact(body, other, point.point, normal, mu=self._mu(body, others), jacobian=jacobian, stiffness=stiffness)

    def _mu(self, body: str, others: set[str]) -> float:
        """The first friction pair naming ``body`` and one of ``others``, else the default."""
        pair = _first_pair(self.detection.pairs, body, others)
        return self.detection.mu if pair is None else pair.mu

    def _stiffness(self, body: str, others: set[str]) -> Stiffness | None:
        """The first stiffness pair naming ``body`` and one of ``others``, else the detection's default."""
        pair = _first_pair(self.detection.stiffness_pairs, body, others)
        return self.detection.stiffness if pair is None else pair.stiffness


_Pair = TypeVar("_Pair", FrictionPair, StiffnessPair)


def _first_pair(pairs: tuple[_Pair, ...], body: str, others: set[str]) -> _Pair | None:
    for pair in pairs:
        a, b = pair.between
        if (a == body and b in others) or (b == body and a in others):
            return pair
    return None


def _robot(robot: UrdfRobot) -> Robot:
    """The solver's view of a URDF robot: its joint velocities, names and torque limits."""
    return Robot(robot.name, robot.joint_velocities, joint_names=robot.joint_names, torque_limits=robot.torque_limits)
