"""A planar world of shapes (the vertical x-y plane, gravity along -y) and the 2-D :class:`Scene` it gives.

:class:`PlanarWorld` has the interface of the 3-D :class:`~.world.World` that
``solve``, the command line and the simulation use (``detect``, ``scene``,
``moved``, ``contact_margin``, ``size``), with planar parts: bodies and movers
with :mod:`.planar` shapes, placed by planar poses (:func:`~.planar.planar_pose`),
twists ``[vx, vy, w]``. Its contacts are found in NumPy (:class:`~.planar.PlanarLayout`),
so it works without the ``robots`` extra. URDF robots are 3-D and have no place here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..model import Body, Contact, FrictionModel, Mover, Robot, Scene, Stiffness
from ..tolerances import DETECTION_MARGIN
from .detect import ContactPoint
from .planar import HalfPlane, PlanarLayout, PlanarShape, planar_pose, pose_angle
from .shapes import Pose
from .world import ContactDetection, Detection, moved_parts

__all__ = ["PlanarBody", "PlanarMover", "PlanarWorld"]

FloatArray = npt.NDArray[np.float64]
T = TypeVar("T")


@dataclass(frozen=True)
class PlanarBody:
    """A free body in the plane: shape (optional), planar pose, mass, centre of mass [x, y] in its own frame, wrench [fx, fy, m]."""

    name: str
    mass: float
    shape: PlanarShape | None = None
    pose: Pose = field(default_factory=planar_pose)
    com: npt.ArrayLike = (0.0, 0.0)
    wrench: npt.ArrayLike | None = None

    def body(self) -> Body:
        """The solver's Body: the com in the world frame."""
        return Body(self.name, self.mass, self.world_com(), self.wrench)

    def world_com(self) -> FloatArray:
        """The centre of mass in the world frame [x, y]."""
        local = np.asarray(self.com, dtype=float)
        return np.asarray(self.pose.rotation[:2, :2] @ local + self.pose.position[:2], dtype=float)


@dataclass(frozen=True)
class PlanarMover:
    """A body with a prescribed motion in the plane: shape (optional), planar pose, twist [vx, vy of the pose origin, w]."""

    name: str
    shape: PlanarShape | None = None
    pose: Pose = field(default_factory=planar_pose)
    twist: npt.ArrayLike | None = None

    def mover(self) -> Mover:
        return Mover(self.name, self.twist, origin=self.pose.position[:2])

    def place(self) -> tuple[npt.ArrayLike | None, FloatArray]:
        """The solver's Mover's numbers: its twist and origin."""
        return self.twist, self.pose.position[:2]


@dataclass(frozen=True)
class PlanarWorld:
    """Planar shapes and explicit contacts: a 2-D scene before its contacts are found.

    ``robots`` is always empty (URDF robots are 3-D); it is here so a simulation reads both worlds alike.
    :meth:`moved` keeps the detection layout (shapes, the pairs that may touch) across poses.
    """

    bodies: tuple[PlanarBody, ...]
    movers: tuple[PlanarMover, ...] = ()
    explicit_robots: tuple[Robot, ...] = ()
    contacts: tuple[Contact, ...] = ()
    detection: ContactDetection = field(default_factory=ContactDetection)
    gravity: npt.ArrayLike | None = None
    friction: FrictionModel | str = "exact"
    stiffness: Stiffness | None = None
    closing_time: float | None = None
    robots: tuple[()] = field(default=(), init=False)
    _fixed: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for body in self.bodies:
            if isinstance(body.shape, HalfPlane):
                reason = "a free body needs a bounded shape; a halfplane is for movers"
                raise SceneError(f"bodies.{body.name}.shape.halfplane", "halfplane", reason)
        self.detection.check_names({b.name for b in self.bodies} | {m.name for m in self.movers}, "body or mover")

    def __getstate__(self) -> dict[str, Any]:
        return {key: value for key, value in self.__dict__.items() if key != "_fixed"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state, _fixed={})

    @property
    def dimension(self) -> int:
        return 2

    def moved(
        self,
        body_poses: Mapping[str, Pose] | None = None,
        robot_q: Mapping[str, Any] | None = None,
        *,
        mover_poses: Mapping[str, Pose] | None = None,
        joint_velocities: Mapping[str, Any] | None = None,
        mover_twists: Mapping[str, npt.ArrayLike] | None = None,
    ) -> PlanarWorld:
        """The same world with some parts elsewhere (planar poses) or movers at new twists; the layout is kept.

        ``robot_q`` and ``joint_velocities`` must be empty: a planar world has no URDF robots.
        """
        for argument, given in (("robot_q", robot_q), ("joint_velocities", joint_velocities)):
            if given:
                raise SceneError(argument, sorted(given), "a planar world has no URDF robots")
        bodies = moved_parts(self.bodies, body_poses, "body_poses")
        movers = moved_parts(self.movers, mover_poses, "mover_poses")
        if mover_twists:
            unknown = set(mover_twists) - {m.name for m in movers}
            if unknown:
                raise SceneError("mover_twists", sorted(unknown), "no such mover")
            movers = tuple(replace(m, twist=mover_twists[m.name]) if m.name in mover_twists else m for m in movers)
        world = object.__new__(PlanarWorld)
        world.__dict__.update(self.__dict__, bodies=bodies, movers=movers)
        return world

    def detect(self) -> Detection:
        """The contacts within the margin (normals into the free body), and the nearest surface of each body touching nothing."""
        layout, margin = self._layout(), self.contact_margin
        poses = self._poses()
        points = layout.detect(poses, margin)
        contacts = self._contacts(points)
        touched = {c.body for c in contacts} | {c.other for c in contacts} | {c.body for c in self.contacts}
        lonely = [b.name for b in self.bodies if b.name not in touched and b.shape is not None]
        isolated = layout.nearest(poses, lonely) if lonely else {}
        return Detection(contacts, tuple(p.gap for p in points), margin, isolated)

    def scene(self, detection: Detection | None = None) -> Scene:
        """The 2-D point-contact Scene at this instant: detected contacts first, then the explicit ones.

        The last Scene made of this world (or of one :meth:`moved` gave) is restated with this instant's numbers when
        its contacts touch the same pairs (:meth:`Scene.moved`: the new numbers checked, the rest kept); a
        simulation makes most of its steps' scenes so.
        """
        detection = detection or self.detect()
        contacts = detection.contacts + self.contacts
        kept: Scene | None = self._fixed.get("scene")
        if kept is not None:
            coms = [b.world_com() for b in self.bodies]
            restated = kept.moved(coms, [m.place() for m in self.movers], contacts)
            if restated is not None:
                return restated
        scene = Scene(
            bodies=[b.body() for b in self.bodies],
            movers=[m.mover() for m in self.movers],
            robots=self.explicit_robots,
            contacts=contacts,
            dimension=2,
            gravity=self.gravity,
            friction=self.friction,
            stiffness=self.stiffness,
            closing_time=self.closing_time,
        )
        self._fixed["scene"] = scene
        return scene

    @property
    def contact_margin(self) -> float:
        """Gaps up to this count as contacts [length]: ``detection.margin``, or the default relative to the bodies' size."""
        if self.detection.margin is not None:
            return self.detection.margin
        return DETECTION_MARGIN * self.size

    @property
    def size(self) -> float:
        """The largest free body's bounding radius [length] (1 when no body has a shape); kept, as :meth:`moved` keeps the shapes."""
        return self._kept("size", lambda: max((b.shape.extent for b in self.bodies if b.shape is not None), default=1.0))

    # ----------------------------------------------------------------- parts

    def _kept(self, key: str, build: Callable[[], T]) -> T:
        """``build()`` once for this world and every world :meth:`moved` gives from it."""
        if key not in self._fixed:
            self._fixed[key] = build()
        return cast(T, self._fixed[key])

    def _shaped(self) -> list[PlanarBody | PlanarMover]:
        parts: list[PlanarBody | PlanarMover] = [*self.bodies, *self.movers]
        return [p for p in parts if p.shape is not None]

    def _layout(self) -> PlanarLayout:
        def build() -> PlanarLayout:
            shaped = self._shaped()
            free = {b.name for b in self.bodies}
            return PlanarLayout([p.name for p in shaped], [cast(PlanarShape, p.shape) for p in shaped], free)

        return self._kept("layout", build)

    def _poses(self) -> FloatArray:
        """Each shaped part's [x, y, angle], in the layout's order."""
        return np.array([[p.pose.position[0], p.pose.position[1], pose_angle(p.pose)] for p in self._shaped()]).reshape(-1, 3)

    def _contacts(self, points: Sequence[ContactPoint]) -> tuple[Contact, ...]:
        free = self._kept("free", lambda: frozenset(b.name for b in self.bodies))
        oriented = [(p.first, p.second, p.normal) if p.first in free else (p.second, p.first, -p.normal) for p in points]
        return tuple(
            Contact.from_trusted_arrays(body, other, p.point, np.array(normal), self._mu(body, other), None, self._spring(body, other))
            for (body, other, normal), p in zip(oriented, points, strict=True)
        )

    def _mu(self, body: str, other: str) -> float:
        table: dict[tuple[str, str], float] = self._kept("mu", dict)
        if (body, other) not in table:
            table[body, other] = self.detection.mu_between(body, {other})
        return table[body, other]

    def _spring(self, body: str, other: str) -> Stiffness | None:
        table: dict[tuple[str, str], Stiffness | None] = self._kept("stiffness", dict)
        if (body, other) not in table:
            table[body, other] = self.detection.stiffness_between(body, {other})
        return table[body, other]
