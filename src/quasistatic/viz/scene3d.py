"""One frame of a Solution drawn into a viser scene: shapes, robot links, contacts by mode, force and slip arrows.

:func:`draw_frame` draws (scene, motion) under one root node and returns the
names of what it drew (:class:`DrawnFrame`); drawing again under the same
root replaces the frame, so a viewer switches motions, re-solves, or (later)
steps through a trajectory by calling it once per frame. The arrow scales
(:class:`ArrowScales`) are chosen once per answer and passed in, so that
frames of one answer share them.

Everything drawn is the Solution's own numbers or the Scene's geometry: the
outline of a body known only by its contact points is their convex hull, and a
robot link is drawn with the URDF's visual meshes at the configuration (in their
colours), or its collision shapes when the URDF has none. A run's states
(:func:`draw_state`) draw the collision shapes: a recording keeps every frame,
and the visual meshes (tens of thousands of triangles per hand) would make it
hundreds of megabytes. No physics is computed here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..adapters import Box, Capsule, Convex, Cylinder, Halfspace, Mesh, Pose, Shape, ShapedMover, SolidBody, Sphere, World
from ..model import Scene
from ..sim.state import State
from ..sim.step import StepResult
from ..solution import Motion, Solution
from .geometry import FloatArray, convex_hull, lifted
from .style import BODY_FILL, FORCE_COLOUR, MODE_COLOURS, MOVER_FILL, NO_MOTION_COLOUR, ROBOT_FILL, SLIP_COLOUR, TWIST_COLOUR

__all__ = ["ArrowScales", "DrawnFrame", "draw_frame", "draw_state", "rgb", "scene_extent"]

_ARROW_SHARE = 0.3  # the longest force (and velocity) arrow is this share of the scene's size, as in the pictures
_DOT_SHARE = 0.025  # radius of a contact's ball per scene size
_SHAFT_SHARE = 0.006  # radius of an arrow's shaft per scene size
_PLANE_SHARE = 0.004  # half the thickness of a 2-D scene's bodies per scene size (drawn as thin slabs)
_ZERO = 1e-9  # forces and velocities below this share of the largest are not drawn (as in the pictures)
_ROUND_POINTS = 24  # points around a cylinder's rim or a capsule's circles
_PART_OPACITY = 0.55  # bodies and movers are see-through: contacts and forces inside a part's outline show
_FLOOR_SHARE = 0.75  # half the side of the square drawn for a halfspace per scene size


_NO_SHADOW: dict[str, Any] = {"cast_shadow": False, "receive_shadow": False}  # software WebGL speckles shadowed faces


def rgb(colour: str) -> tuple[int, int, int]:
    """``#RRGGBB`` as an (r, g, b) tuple of 0-255 integers."""
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


@dataclass(frozen=True)
class ArrowScales:
    """Lengths drawn per unit, shared by every frame of one answer.

    Attributes
    ----------
    size : float
        The scene's size: the diagonal of the box around its contacts, coms and shapes [length].
    centre : array (3,)
        The middle of that box [length].
    force : float
        Drawn length per force [length/force]; 0 when every force is zero.
    velocity : float
        Drawn length per velocity [time]; 0 when nothing moves.
    """

    size: float
    centre: FloatArray
    force: float
    velocity: float

    @classmethod
    def of(cls, solution: Solution, scene: Scene, world: World | None = None) -> ArrowScales:
        """Scales for all motions of ``solution``: its longest force and fastest slip or com velocity get 30 % of the size."""
        centre, size = scene_extent(scene, world)
        motions = list(solution.solutions) or ([solution.motion] if solution.motion is not None else [])
        force = max((float(np.linalg.norm(c.force)) for m in motions for c in m.contacts), default=0.0)
        speed = max((_speed(m, scene.dimension) for m in motions), default=0.0)
        return cls.sized(size, centre, force, speed)

    @classmethod
    def sized(cls, size: float, centre: FloatArray, force: float, speed: float) -> ArrowScales:
        """Scales on which the largest ``force`` and fastest ``speed`` are 30 % of ``size`` (0: nothing to draw)."""
        return cls(size, centre, _ARROW_SHARE * size / force if force > 0 else 0.0, _ARROW_SHARE * size / speed if speed > 0 else 0.0)

    @classmethod
    def of_run(cls, world: World, states: Sequence[State], steps: Sequence[StepResult]) -> ArrowScales:
        """One set of scales for every state of a run (on ``world``): the box around every recorded contact and
        every bounded shape at each state; the largest recorded force and com speed get 30 % of its size."""
        points = [c.point for s in steps for c in s.contacts]
        parts: list[SolidBody | ShapedMover] = [*world.bodies, *world.movers]
        for part in parts:
            if part.shape is not None and not isinstance(part.shape, Halfspace):
                local = _local_mesh(part.shape)[0]
                poses = (s.bodies.get(part.name) or s.movers.get(part.name) for s in states)
                points.extend(p for pose in poses if pose is not None for p in pose.apply(local))
        cloud = np.array(points) if points else np.zeros((1, 3))
        low, high = cloud.min(axis=0), cloud.max(axis=0)
        size = float(np.linalg.norm(high - low)) or 1.0
        force = max((float(np.linalg.norm(c.force)) for s in steps for c in s.contacts), default=0.0)
        speed = max((float(np.linalg.norm(np.asarray(t, dtype=float)[:3])) for s in steps for t in s.twists.values()), default=0.0)
        return cls.sized(size, (low + high) / 2, force, speed)


def scene_extent(scene: Scene, world: World | None = None) -> tuple[FloatArray, float]:
    """(centre, size) of the box around the contacts, the coms and the bounded shapes of the bodies and movers [length]."""
    points = [lifted(c.point) for c in scene.contacts] + [lifted(b.com) for b in scene.bodies]
    parts: list[SolidBody | ShapedMover] = [] if world is None else [*world.bodies, *world.movers]
    for part in parts:
        if part.shape is not None and not isinstance(part.shape, Halfspace):
            points.extend(part.pose.apply(_local_mesh(part.shape)[0]))
    cloud = np.array(points) if points else np.zeros((1, 3))
    low, high = cloud.min(axis=0), cloud.max(axis=0)
    return (low + high) / 2, float(np.linalg.norm(high - low)) or 1.0


def _speed(motion: Motion, dimension: int) -> float:
    slips = [float(np.linalg.norm(c.slip)) for c in motion.contacts if c.mode == "sliding"]
    coms = [float(np.linalg.norm(_linear(t, dimension))) for t in motion.twists.values()]
    return max([*slips, *coms, 0.0])


def _linear(twist: FloatArray, dimension: int) -> FloatArray:
    twist = np.asarray(twist, dtype=float)
    return np.array([twist[0], twist[1], 0.0]) if dimension == 2 else twist[:3]


def _angular(twist: FloatArray, dimension: int) -> FloatArray:
    twist = np.asarray(twist, dtype=float)
    return np.array([0.0, 0.0, twist[2]]) if dimension == 2 else twist[3:]


@dataclass(frozen=True)
class DrawnFrame:
    """The scene-tree names of what one frame drew, by kind (one entry per part, contact or arrow).

    ``forces`` and ``slips`` hold one arrow per contact with a non-zero force or a sliding contact's slip;
    ``twists`` one com-velocity arrow per moving body.
    """

    root: str
    bodies: tuple[str, ...]
    movers: tuple[str, ...]
    robot_links: tuple[str, ...]
    contacts: tuple[str, ...]
    forces: tuple[str, ...]
    slips: tuple[str, ...]
    twists: tuple[str, ...]

    @property
    def names(self) -> tuple[str, ...]:
        return self.bodies + self.movers + self.robot_links + self.contacts + self.forces + self.slips + self.twists


def draw_frame(
    api: Any, scene: Scene, motion: Motion | None, scales: ArrowScales, world: World | None = None, root: str = "/frame"
) -> DrawnFrame:
    """Draw one frame into a viser scene (``server.scene``), replacing what was drawn under ``root``.

    Parameters
    ----------
    api : viser SceneApi
        Where to draw.
    scene : Scene
        The point-contact scene the motion answers (contact points, coms).
    motion : Motion or None
        The motion to draw (modes, forces, slips, twists); None for an answer without one (contacts grey).
    scales : ArrowScales
        Arrow lengths per unit, shared by the frames of one answer.
    world : World, optional
        The World of shapes the scene came from: its shapes and robot links are drawn.
    """
    api.remove_by_name(root)
    parts: list[SolidBody | ShapedMover] = [] if world is None else [*world.bodies, *world.movers]
    shaped = {p.name for p in parts if p.shape is not None}
    bodies = _draw_bodies(api, scene, world, scales, shaped, root)
    movers = _draw_movers(api, world, scales, root)
    links = _draw_robot_links(api, world, root, visual=True)
    contacts = _draw_contacts(api, scene, motion, scales, root)
    forces, slips, twists = _draw_arrows(api, scene, motion, scales, root) if motion is not None else ((), (), ())
    return DrawnFrame(root, bodies, movers, links, contacts, forces, slips, twists)


def draw_state(api: Any, world: World, step: StepResult, scales: ArrowScales, label: str = "", root: str = "/frame") -> DrawnFrame:
    """Draw one state of a run into a viser scene, replacing what was drawn under ``root``.

    Parameters
    ----------
    world : World
        The World placed at the state (``State.applied``): its shapes, movers and robot links are drawn there.
    step : StepResult
        What the trajectory recorded at that state: each contact (its ball in the colour of its mode, grey
        without a motion, and the force on the body as an arrow) and each body's twist (its com velocity).
    scales : ArrowScales
        One set for the whole run (:meth:`ArrowScales.of_run`).
    label : str
        Text shown above the scene (the time and status): a scene node, so an exported recording keeps it.
    """
    api.remove_by_name(root)
    bodies = _draw_world_bodies(api, world, step, scales, root)
    movers = _draw_movers(api, world, scales, root)
    links = _draw_robot_links(api, world, root)
    contacts = _contact_balls(api, [(c.point, c.body, c.other, c.mode) for c in step.contacts], scales, root)
    forces = [(f"{root}/forces/{i}", c.point, c.force * scales.force) for i, c in enumerate(step.contacts)]
    slips = [(f"{root}/slips/{i}", c.point, c.slip * scales.velocity) for i, c in enumerate(step.contacts)]
    coms = {b.name: b.body().com for b in world.bodies}
    twists = [
        (f"{root}/twists/{n}", coms[n], np.asarray(t, dtype=float)[:3] * scales.velocity) for n, t in step.twists.items() if n in coms
    ]
    if label:
        above = scales.centre + np.array([0.0, 0.0, 0.5 * scales.size])
        api.add_label(f"{root}/label", label, position=tuple(above))
    return DrawnFrame(
        root, bodies, movers, links, contacts, _arrows(api, forces, FORCE_COLOUR, scales), _arrows(api, slips, SLIP_COLOUR, scales),
        _arrows(api, twists, TWIST_COLOUR, scales),
    )  # fmt: skip


# --------------------------------------------------------------------------- parts


def _draw_world_bodies(api: Any, world: World, step: StepResult, scales: ArrowScales, root: str) -> tuple[str, ...]:
    """Each free body of a run: its shape where placed, or the hull of its recorded contact points and com."""
    names = []
    for body in world.bodies:
        name = f"{root}/bodies/{body.name}"
        if body.shape is not None:
            _draw_shape(api, name, body.shape, body.pose, BODY_FILL, scales)
        else:
            points = np.array([c.point for c in step.contacts if body.name in (c.body, c.other)] + [body.body().com])
            vertices, faces = _hull_mesh(_thickened(points, scales))
            api.add_mesh_simple(name, vertices, faces, color=rgb(BODY_FILL), opacity=_PART_OPACITY, **_NO_SHADOW, flat_shading=True)
        names.append(name)
    return tuple(names)


def _draw_bodies(api: Any, scene: Scene, world: World | None, scales: ArrowScales, shaped: set[str], root: str) -> tuple[str, ...]:
    """Each free body: its shape, or the hull of its contact points and com; its name beside its com."""
    names = []
    for body in scene.bodies:
        name = f"{root}/bodies/{body.name}"
        part = None if world is None else next((b for b in world.bodies if b.name == body.name and b.name in shaped), None)
        if part is not None and part.shape is not None:
            _draw_shape(api, name, part.shape, part.pose, BODY_FILL, scales)
        else:
            vertices, faces = _outline_mesh(scene, body.name, scales)
            api.add_mesh_simple(name, vertices, faces, color=rgb(BODY_FILL), opacity=_PART_OPACITY, **_NO_SHADOW, flat_shading=True)
        api.add_label(f"{name}/label", body.name, position=tuple(lifted(body.com)))
        names.append(name)
    return tuple(names)


def _draw_movers(api: Any, world: World | None, scales: ArrowScales, root: str) -> tuple[str, ...]:
    names = []
    for mover in [] if world is None else world.movers:
        if mover.shape is not None:
            name = f"{root}/movers/{mover.name}"
            _draw_shape(api, name, mover.shape, mover.pose, MOVER_FILL, scales)
            names.append(name)
    return tuple(names)


def _draw_robot_links(api: Any, world: World | None, root: str, visual: bool = False) -> tuple[str, ...]:
    """Every URDF robot's links at its configuration, translucent: its visual meshes (``visual``) if any, else its collision shapes."""
    names = []
    for robot in [] if world is None else world.robots:
        visuals = robot.visuals if visual else ()
        for index, part in enumerate(visuals):
            name = f"{root}/robots/{robot.name}/{part.link}_{index}"
            if part.vertices is not None and part.faces is not None:
                vertices, faces = part.vertices, part.faces
            elif part.shape is not None:
                vertices, faces = _local_mesh(part.shape)
            else:
                continue
            colour = tuple(int(round(255 * c)) for c in part.colour[:3])
            api.add_mesh_simple(name, vertices, faces, color=colour, opacity=0.6, **_NO_SHADOW, **_placement(part.pose))
            names.append(name)
        for index, collider in enumerate(() if visuals else robot.colliders):
            name = f"{root}/robots/{robot.name}/{collider.link}_{index}"
            vertices, faces = _local_mesh(collider.shape)
            api.add_mesh_simple(name, vertices, faces, color=rgb(ROBOT_FILL), opacity=0.6, **_NO_SHADOW, **_placement(collider.pose))
            names.append(name)
    return tuple(names)


def _draw_shape(api: Any, name: str, shape: Shape, pose: Pose, colour: str, scales: ArrowScales) -> None:
    if isinstance(shape, Halfspace):
        vertices, faces = _floor(shape, pose, scales)
        api.add_mesh_simple(name, vertices, faces, color=rgb("#F4F4F4"), side="double", **_NO_SHADOW)
        return
    vertices, faces = _local_mesh(shape)
    api.add_mesh_simple(name, vertices, faces, color=rgb(colour), opacity=_PART_OPACITY, **_NO_SHADOW, **_placement(pose))


def _placement(pose: Pose) -> dict[str, Any]:
    return {"position": tuple(pose.position), "wxyz": _quaternion(pose.rotation)}


def _quaternion(rotation: FloatArray) -> tuple[float, float, float, float]:
    """(w, x, y, z) of a rotation matrix (Shepperd's method: the largest of the four is found first)."""
    r = np.asarray(rotation, dtype=float)
    trace = float(np.trace(r))
    candidates = [trace, r[0, 0], r[1, 1], r[2, 2]]
    k = int(np.argmax(candidates))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = (s / 4, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    else:
        i, j, m = [(0, 1, 2), (1, 2, 0), (2, 0, 1)][k - 1]
        s = 2.0 * math.sqrt(max(1.0 + r[i, i] - r[j, j] - r[m, m], 0.0))
        v = [0.0, 0.0, 0.0]
        v[i], v[j], v[m] = s / 4, (r[j, i] + r[i, j]) / s, (r[m, i] + r[i, m]) / s
        q = ((r[m, j] - r[j, m]) / s, v[0], v[1], v[2])
    return float(q[0]), float(q[1]), float(q[2]), float(q[3])


# --------------------------------------------------------------------------- meshes


def _local_mesh(shape: Shape) -> tuple[FloatArray, np.ndarray]:
    """Triangles of a bounded shape in its own frame: (vertices (n, 3), faces (m, 3))."""
    if isinstance(shape, Convex):
        return np.asarray(shape.vertices, dtype=float), np.asarray(shape.triangles)
    if isinstance(shape, Mesh):
        return np.asarray(shape.convex.vertices, dtype=float), np.asarray(shape.convex.triangles)
    return _hull_mesh(_local_points(shape))


def _local_points(shape: Shape) -> FloatArray:
    """Points whose convex hull draws the shape (a sphere and the round parts: polygons of ``_ROUND_POINTS``)."""
    circle = np.linspace(0.0, 2 * math.pi, _ROUND_POINTS, endpoint=False)
    if isinstance(shape, Box):
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        out: FloatArray = corners * np.asarray(shape.size) / 2
        return out
    if isinstance(shape, Cylinder):
        rim = np.column_stack([shape.radius * np.cos(circle), shape.radius * np.sin(circle)])
        return np.vstack([np.column_stack([rim, np.full(len(rim), z)]) for z in (-shape.length / 2, shape.length / 2)])
    sphere = _sphere_points(shape.radius if isinstance(shape, (Sphere, Capsule)) else 0.0)
    if isinstance(shape, Capsule):
        return np.vstack([sphere + [0.0, 0.0, -shape.length / 2], sphere + [0.0, 0.0, shape.length / 2]])
    return sphere


def _sphere_points(radius: float) -> FloatArray:
    """A latitude-longitude grid on a sphere (poles included)."""
    polar = np.linspace(0.0, math.pi, _ROUND_POINTS // 2 + 1)
    azimuth = np.linspace(0.0, 2 * math.pi, _ROUND_POINTS, endpoint=False)
    p, a = np.meshgrid(polar, azimuth)
    grid = np.column_stack([np.sin(p).ravel() * np.cos(a).ravel(), np.sin(p).ravel() * np.sin(a).ravel(), np.cos(p).ravel()])
    return radius * np.unique(np.round(grid, 12), axis=0)


def _hull_mesh(points: FloatArray) -> tuple[FloatArray, np.ndarray]:
    """The convex hull's triangles, counter-clockwise seen from outside (so only front faces need drawing); flat
    or tiny point sets are joggled (qhull's QJ) so that a hull exists."""
    from scipy.spatial import ConvexHull

    points = np.asarray(points, dtype=float)
    faces = np.asarray(ConvexHull(points, qhull_options="QJ").simplices)
    a, b, c = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - points.mean(axis=0)) >= 0.0
    return points, np.where(outward[:, None], faces, faces[:, [0, 2, 1]])


def _outline_mesh(scene: Scene, body: str, scales: ArrowScales) -> tuple[FloatArray, np.ndarray]:
    """The convex hull of a body's contact points and com (a 2-D scene's: a thin slab in its plane)."""
    points = np.array(
        [lifted(c.point) for c in scene.contacts if body in (c.body, c.other)] + [lifted(scene.bodies[scene.body_index(body)].com)]
    )
    thickness = _PLANE_SHARE * scales.size
    if scene.dimension == 2:
        polygon = convex_hull(points[:, :2])
        points = np.vstack([np.column_stack([polygon, np.full(len(polygon), z)]) for z in (-thickness, thickness)])
    else:
        points = _thickened(points, scales)
    return _hull_mesh(points)


def _thickened(points: FloatArray, scales: ArrowScales) -> FloatArray:
    """A point, a segment or a triangle thickened along the axes so that its hull exists and shows."""
    if len(points) >= 4:
        return points
    thickness = _PLANE_SHARE * scales.size
    return np.vstack([points + offset for offset in thickness * np.vstack([np.eye(3), -np.eye(3)])])


def _floor(halfspace: Halfspace, pose: Pose, scales: ArrowScales) -> tuple[FloatArray, np.ndarray]:
    """A square of the halfspace's boundary plane around the scene's centre, in world coordinates."""
    local_centre = pose.inverse().apply(scales.centre)
    normal = np.asarray(halfspace.normal, dtype=float)
    foot = local_centre - (normal @ local_centre - halfspace.offset) * normal
    u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    half = _FLOOR_SHARE * scales.size
    corners = np.array([foot + half * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return pose.apply(corners), np.array([[0, 1, 2], [0, 2, 3]])


# --------------------------------------------------------------------------- contacts and arrows


def _draw_contacts(api: Any, scene: Scene, motion: Motion | None, scales: ArrowScales, root: str) -> tuple[str, ...]:
    modes = [None] * len(scene.contacts) if motion is None else list(motion.modes)
    balls = [(lifted(c.point), c.body, c.other, mode) for c, mode in zip(scene.contacts, modes, strict=True)]
    return _contact_balls(api, balls, scales, root)


def _contact_balls(api: Any, balls: Sequence[tuple[FloatArray, str, str, str | None]], scales: ArrowScales, root: str) -> tuple[str, ...]:
    """A ball per (point, body, other, mode) in the colour of its mode (grey: no mode)."""
    names = []
    for index, (point, body, other, mode) in enumerate(balls):
        name = f"{root}/contacts/{index}_{body}-{other}"
        colour = NO_MOTION_COLOUR if mode is None else MODE_COLOURS[mode]
        api.add_icosphere(name, radius=_DOT_SHARE * scales.size, color=rgb(colour), position=tuple(point), **_NO_SHADOW)
        names.append(name)
    return tuple(names)


def _draw_arrows(api: Any, scene: Scene, motion: Motion, scales: ArrowScales, root: str) -> tuple[tuple[str, ...], ...]:
    """The force on the body at every contact, the slip at sliding ones (from the contact point), each body's com velocity."""
    points = [lifted(c.point) for c in scene.contacts]
    forces = [
        (f"{root}/forces/{i}", p, lifted(c.force) * scales.force) for i, (p, c) in enumerate(zip(points, motion.contacts, strict=True))
    ]
    slips = [
        (f"{root}/slips/{i}", p, lifted(c.slip) * scales.velocity)
        for i, (p, c) in enumerate(zip(points, motion.contacts, strict=True))
        if c.mode == "sliding"
    ]
    coms = {b.name: lifted(b.com) for b in scene.bodies}
    twists = [(f"{root}/twists/{name}", coms[name], _linear(t, scene.dimension) * scales.velocity) for name, t in motion.twists.items()]
    return (
        _arrows(api, forces, FORCE_COLOUR, scales),
        _arrows(api, slips, SLIP_COLOUR, scales),
        _arrows(api, twists, TWIST_COLOUR, scales),
    )


def _arrows(api: Any, arrows: list[tuple[str, FloatArray, FloatArray]], colour: str, scales: ArrowScales) -> tuple[str, ...]:
    """One arrow node per (name, start, drawn vector); vectors shorter than ``_ZERO`` of the longest are left out."""
    longest = max((float(np.linalg.norm(v)) for _, _, v in arrows), default=0.0)
    shaft = _SHAFT_SHARE * scales.size
    names = []
    for name, start, vector in arrows:
        length = float(np.linalg.norm(vector))
        if length <= _ZERO * longest or length == 0.0:
            continue
        head = min(4 * shaft, 0.4 * length)  # a short arrow keeps a visible shaft
        api.add_arrows(
            name, np.array([[start, start + vector]]), rgb(colour), shaft_radius=shaft, head_radius=2.5 * shaft, head_length=head
        )
        names.append(name)
    return tuple(names)
