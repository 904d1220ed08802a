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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Protocol, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import Body, Contact, FrictionModel, Mover, Robot, Scene, Stiffness
from ..tolerances import DETECTION_MARGIN
from .detect import Collider, ContactPoint, Layout, nearest_gaps
from .robot import JointValues, UrdfRobot, link_owner
from .shapes import Pose, Shape

__all__ = ["SolidBody", "ShapedMover", "FrictionPair", "ContactDetection", "Detection", "World", "moved_parts"]

FloatArray = npt.NDArray[np.float64]
T = TypeVar("T")


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

    def mu_between(self, body: str, others: set[str]) -> float:
        """The first friction pair naming ``body`` and one of ``others``, else the default ``mu``."""
        pair = first_pair(self.pairs, body, others)
        return self.mu if pair is None else pair.mu

    def stiffness_between(self, body: str, others: set[str]) -> Stiffness | None:
        """The first stiffness pair naming ``body`` and one of ``others``, else the default ``stiffness``."""
        pair = first_pair(self.stiffness_pairs, body, others)
        return self.stiffness if pair is None else pair.stiffness

    def check_names(self, known: set[str], kinds: str) -> None:
        """Every name a pair gives is one of ``known`` (else a SceneError naming the pair and ``kinds``)."""
        named = [("friction.pairs", p.between) for p in self.pairs]
        named += [("stiffness.pairs", p.between) for p in self.stiffness_pairs]
        counts: dict[str, int] = {}
        for key, between in named:
            index = counts[key] = counts.get(key, -1) + 1
            for name in between:
                if name not in known:
                    raise SceneError(f"contact_detection.{key}[{index}].between", name, f"names no {kinds} of the scene")


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
    """Shapes, robots and explicit contacts: a scene before its contacts are found.

    :meth:`moved` gives the same world with bodies, movers and robots elsewhere, keeping everything
    that does not depend on where they are (parsed URDFs, shapes, coal geometries, the detection
    layout): what a simulation calls at every step.
    """

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
    _fixed: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        parts: list[SolidBody | ShapedMover] = [*self.bodies, *self.movers]
        known = {p.name for p in parts} | {r.name for r in self.robots} | set(self._robot_links())
        self.detection.check_names(known, "body, mover, robot or robot link (robot/link)")

    def __getstate__(self) -> dict[str, Any]:
        # The kept layout holds coal objects: rebuilt where it is needed, not pickled.
        return {key: value for key, value in self.__dict__.items() if key != "_fixed"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state, _fixed={})

    def moved(
        self,
        body_poses: Mapping[str, Pose] | None = None,
        robot_q: Mapping[str, JointValues] | None = None,
        *,
        mover_poses: Mapping[str, Pose] | None = None,
        joint_velocities: Mapping[str, JointValues] | None = None,
        mover_twists: Mapping[str, npt.ArrayLike] | None = None,
    ) -> World:
        """The same world with some parts elsewhere: a simulation's next step.

        Parameters
        ----------
        body_poses : mapping body name -> Pose, optional
            New poses of free bodies (the others stay).
        robot_q : mapping robot name -> joint positions, optional
            New joint positions (a list or array in model order, or a mapping by joint name), through
            :meth:`UrdfRobot.at`: the URDF is not parsed again.
        mover_poses : mapping mover name -> Pose, optional
            New poses of movers (a pusher that has moved along its twist).
        joint_velocities : mapping robot name -> joint velocities, optional
            New joint velocities, in the forms of ``robot_q``.
        mover_twists : mapping mover name -> twist, optional
            New twists of movers ([v of the pose origin, w], world frame; checked when the Scene is built).

        Everything that does not depend on where the parts are is kept and shared with this world:
        the parsed robots, the shapes and their coal geometries, the detection layout, the margin, the
        friction of each pair. Names are checked; poses must be :class:`Pose` values (validated when built).
        """
        bodies = moved_parts(self.bodies, body_poses, "body_poses")
        movers = moved_parts(self.movers, mover_poses, "mover_poses")
        if mover_twists:
            _check_names(mover_twists, {m.name for m in movers}, "mover_twists", "mover")
            movers = tuple(replace(m, twist=mover_twists[m.name]) if m.name in mover_twists else m for m in movers)
        robots = _moved_robots(self.robots, robot_q or {}, joint_velocities or {})
        world = object.__new__(World)
        world.__dict__.update(self.__dict__, bodies=bodies, movers=movers, robots=robots)  # the names are unchanged
        return world

    def detect(self) -> Detection:
        """The contacts within the margin, as solver contacts (normals into the free body, Jacobians for robot links)."""
        layout, margin = self._layout(), self._margin()
        positions, rotations = self._placements()
        points = layout.detect(positions, rotations, margin)
        contacts = self._contacts(points)
        touched = {c.body for c in contacts} | {c.other for c in contacts} | {c.body for c in self.contacts}
        lonely = [b.name for b in self.bodies if b.name not in touched and b.shape is not None]
        isolated = nearest_gaps(self._colliders(), lonely, self._may_touch) if lonely else {}
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
    def dimension(self) -> int:
        """3: shapes, URDF robots and their contacts live in space (:class:`~.planar_world.PlanarWorld` is the 2-D one)."""
        return 3

    @property
    def contact_margin(self) -> float:
        """Gaps up to this count as contacts [length]: ``detection.margin``, or the default relative to the bodies' size."""
        return self._margin()

    @property
    def size(self) -> float:
        """The largest free body's size [length] (1 when no body has a shape)."""
        return max((b.shape.extent for b in self.bodies if b.shape is not None), default=1.0)

    # ----------------------------------------------------------------- parts

    def _kept(self, key: str, build: Callable[[], T]) -> T:
        """``build()`` once for this world and every world :meth:`moved` gives from it (it must not depend on poses)."""
        if key not in self._fixed:
            self._fixed[key] = build()
        return cast(T, self._fixed[key])

    def _robot_links(self) -> dict[str, tuple[UrdfRobot, str]]:
        """Each robot link's name as a mover (``hand/link``): its robot and link (this world's robots, at this configuration)."""
        return {link_owner(r.name, link): (r, link) for r in self.robots for link in r.link_names}

    def _shaped(self) -> list[SolidBody | ShapedMover]:
        parts: list[SolidBody | ShapedMover] = [*self.bodies, *self.movers]
        return [p for p in parts if p.shape is not None]

    def _layout(self) -> Layout:
        """The colliders' owners and shapes (shaped bodies, shaped movers, then each robot's geometries)."""

        def build() -> Layout:
            shaped = self._shaped()
            owners = [p.name for p in shaped] + [owner for r in self.robots for owner in r.collider_owners]
            shapes = [cast(Shape, p.shape) for p in shaped] + [shape for r in self.robots for shape in r.collider_shapes]
            return Layout(owners, shapes, free=self._kept("free", lambda: frozenset(b.name for b in self.bodies)))

        return self._kept("layout", build)

    def _may_touch(self, first: str, second: str) -> bool:
        """Only pairs with a free body constrain its motion; two links of one robot, or two movers, never do."""
        free = self._kept("free", lambda: frozenset(b.name for b in self.bodies))
        return first in free or second in free

    def _placements(self) -> tuple[FloatArray, FloatArray]:
        """Every collider's world position (n, 3) and rotation (n, 3, 3), in the layout's order."""
        poses = [p.pose for p in self._shaped()]
        robots = [r.collider_placements() for r in self.robots]
        positions = np.concatenate([np.array([p.position for p in poses]).reshape(-1, 3)] + [r[0] for r in robots])
        rotations = np.concatenate([np.array([p.rotation for p in poses]).reshape(-1, 3, 3)] + [r[1] for r in robots])
        return positions, rotations

    def _colliders(self) -> list[Collider]:
        shaped = [Collider(p.name, p.shape, p.pose) for p in self._shaped()]
        return shaped + [Collider(c.owner, c.shape, c.pose) for r in self.robots for c in r.colliders]

    def _margin(self) -> float:
        if self.detection.margin is not None:
            return self.detection.margin
        return DETECTION_MARGIN * self.size

    def _contacts(self, points: Sequence[ContactPoint]) -> tuple[Contact, ...]:
        """Solver contacts: the free body first, its normal into it; a robot link's Jacobian at each of its points."""
        free = self._kept("free", lambda: frozenset(b.name for b in self.bodies))
        oriented = [(p.first, p.second, p.normal) if p.first in free else (p.second, p.first, -p.normal) for p in points]
        jacobians = self._jacobians([other for _, other, _ in oriented], [p.point for p in points])
        return tuple(
            Contact.from_trusted_arrays(body, other, point.point, normal, self._mu(body, other), jacobian, self._stiffness(body, other))
            for (body, other, normal), point, jacobian in zip(oriented, points, jacobians, strict=True)
        )

    def _link_index(self) -> dict[str, tuple[int, str]]:
        """Each robot link's name as a mover (``hand/link``): the index of its robot, and the link."""
        return self._kept(
            "links", lambda: {link_owner(r.name, link): (k, link) for k, r in enumerate(self.robots) for link in r.link_names}
        )

    def _jacobians(self, others: list[str], points: list[FloatArray]) -> list[FloatArray | None]:
        """The point Jacobian of each contact with a robot link (one batch per robot), None for the others."""
        links = self._link_index()
        result: list[FloatArray | None] = [None] * len(others)
        for index, robot in enumerate(self.robots):
            where = [k for k, other in enumerate(others) if other in links and links[other][0] == index]
            if where:
                batch = robot.point_jacobians([links[others[k]][1] for k in where], np.array([points[k] for k in where]))
                for k, jacobian in zip(where, batch, strict=True):
                    result[k] = jacobian
        return result

    def _others(self, other: str) -> set[str]:
        """``other``, and for a robot link its whole robot too: a friction or stiffness pair may name either."""
        robot_link = self._link_index().get(other)
        return {other} if robot_link is None else {other, self.robots[robot_link[0]].name}

    def _mu(self, body: str, other: str) -> float:
        """The first friction pair naming ``body`` and ``other`` (or a robot link's whole robot), else the default."""
        table: dict[tuple[str, str], float] = self._kept("mu", dict)
        if (body, other) not in table:
            table[body, other] = self.detection.mu_between(body, self._others(other))
        return table[body, other]

    def _stiffness(self, body: str, other: str) -> Stiffness | None:
        """The first stiffness pair naming ``body`` and ``other`` (or a robot link's whole robot), else the detection's default."""
        table: dict[tuple[str, str], Stiffness | None] = self._kept("stiffness", dict)
        if (body, other) not in table:
            table[body, other] = self.detection.stiffness_between(body, self._others(other))
        return table[body, other]


_Pair = TypeVar("_Pair", FrictionPair, StiffnessPair)


def first_pair(pairs: tuple[_Pair, ...], body: str, others: set[str]) -> _Pair | None:
    """The first pair naming ``body`` and one of ``others`` (either way round), or None."""
    for pair in pairs:
        a, b = pair.between
        if (a == body and b in others) or (b == body and a in others):
            return pair
    return None


class Placed(Protocol):
    """A part with a name and a pose: a body or mover of a World or a PlanarWorld (a frozen dataclass)."""

    __dataclass_fields__: ClassVar[dict[str, Any]]

    @property
    def name(self) -> str: ...

    @property
    def pose(self) -> Pose: ...


P = TypeVar("P", bound=Placed)


def moved_parts(parts: tuple[P, ...], poses: Mapping[str, Pose] | None, field: str) -> tuple[P, ...]:
    """``parts`` with the poses named in ``poses`` replaced (an unknown name or a non-Pose is a SceneError)."""
    if not poses:
        return parts
    _check_names(poses, {p.name for p in parts}, field, "part")
    for name, pose in poses.items():
        if not isinstance(pose, Pose):
            raise SceneError(f"{field}.{name}", pose, "expected a Pose (quasistatic.Pose; in the plane, quasistatic.planar_pose)")
    return tuple(replace(p, pose=poses[p.name]) if p.name in poses else p for p in parts)


def _check_names(given: Mapping[str, object], known: set[str], field: str, kind: str) -> None:
    """Every name in ``given`` is one of ``known`` (else a SceneError naming ``field.name``)."""
    for name in given:
        if name not in known:
            raise SceneError(f"{field}.{name}", name, f"no such {kind}; the known ones are {', '.join(sorted(known)) or 'none'}")


def _moved_robots(
    robots: tuple[UrdfRobot, ...], positions: Mapping[str, JointValues], velocities: Mapping[str, JointValues]
) -> tuple[UrdfRobot, ...]:
    """Each robot at its new joint positions and velocities (what is not given is kept)."""
    for argument, given in (("robot_q", positions), ("joint_velocities", velocities)):
        _check_names(given, {r.name for r in robots}, argument, "robot")
    return tuple(
        r.at(q=positions.get(r.name), joint_velocities=velocities.get(r.name)) if r.name in positions or r.name in velocities else r
        for r in robots
    )


def _robot(robot: UrdfRobot) -> Robot:
    """The solver's view of a URDF robot: its joint velocities, names, torque limits and joint stiffness."""
    return Robot(
        robot.name,
        robot.joint_velocities,
        joint_names=robot.joint_names,
        torque_limits=robot.torque_limits,
        joint_stiffness=robot.joint_stiffness,
    )
