"""``plot``: a Solution drawn on its scene, headless (matplotlib's Agg), one panel per motion.

What is drawn, and in which colours, is described in docs/pictures.md and
:mod:`quasistatic.viz.style`. Everything comes from the Solution and the
Scene (or the World of shapes it was built from): the twists, forces, slips
and modes are the Solution's own numbers, only scaled onto the page.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..adapters import Halfspace, PlanarBody, PlanarMover, PlanarWorld, ShapedMover, SolidBody, World
from ..model import Scene
from ..solution import Motion, Solution
from .chart import summary_figure
from .geometry import VIEWS, FloatArray, Projection, convex_hull, lifted, plane_patch, shape_outline
from .planar import draw_planar_parts, planar_extent
from .style import (
    BODY_FILL,
    EDGE_COLOUR,
    FORCE_COLOUR,
    MODE_COLOURS,
    MOVER_FILL,
    NO_MOTION_COLOUR,
    ROBOT_FILL,
    SLIP_COLOUR,
    TWIST_COLOUR,
    headline,
    require_matplotlib,
    styled,
    wrapped,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["MAX_PANELS", "plot"]

MAX_PANELS = 6
"""An ambiguous answer gets one panel per motion, up to this many (the title says how many were left out)."""
_ARROW_SHARE = 0.3  # the longest force (and velocity) arrow is this share of the drawing's size
_AXIS_SHARE = 0.6  # half the length of a drawn screw axis, per drawing size
_FAR = 2.0  # an ICR or screw axis farther than this many drawing sizes from the com is left off the page
_ZERO = 1e-9  # velocities and forces below this share of the largest one are drawn as zero
_LABEL_LIMIT = 12  # parts named on the page when there are at most this many


@dataclass(frozen=True)
class _Frame:
    """What every panel of one figure shares: the scene, the view and the arrow scales."""

    scene: Scene
    world: World | PlanarWorld | None
    projection: Projection
    centre: FloatArray  # world point at the middle of the scene [length]
    size: float  # the drawing's size on the page [length]
    force_scale: float  # page length per force [length/force]
    velocity_scale: float  # page length per velocity [s]
    speed: float  # largest velocity drawn [length/time]


@dataclass
class _Legend:
    """Legend entries in the order first drawn, one per label."""

    handles: dict[str, Any] = field(default_factory=dict)

    def add(self, label: str, **line: Any) -> None:
        if label not in self.handles:
            from matplotlib.lines import Line2D

            self.handles[label] = Line2D([], [], label=label, **line)


def plot(solution: Solution, scene: Scene | World | PlanarWorld | None = None, ax: Axes | None = None, view: str = "iso") -> Figure:
    """Draw a solution on its scene and return the matplotlib Figure (nothing is shown or saved).

    Parameters
    ----------
    solution : Solution
        The answer to draw: contact modes, forces, slips and twists.
    scene : Scene, World or PlanarWorld, optional
        The scene it answers (a world of shapes: its shapes are drawn too, a planar one in its plane). Without one,
        a Solution has no geometry: each contact's normal force is drawn as a bar instead.
    ax : matplotlib Axes, optional
        Draw into this axes (one panel: an ambiguous answer's first motion) instead of a new figure.
    view : {"iso", "xy", "xz", "yz"}
        How a 3-D scene is seen (orthographic); a 2-D scene is drawn in its plane.

    Raises
    ------
    BackendUnavailableError
        When matplotlib (the ``figures`` extra) is not installed.
    ValueError
        For an unknown view.
    """
    require_matplotlib()
    if view not in VIEWS:
        raise ValueError(f"view {view!r} is not one of {', '.join(VIEWS)}")
    with styled():
        if scene is None:
            return summary_figure(solution, ax)
        frame = _frame(solution, scene, view)
        panels = _panels(solution, single=ax is not None)
        figure, axes = _axes(len(panels), ax)
        legend = _Legend()
        for panel_ax, (label, motion) in zip(axes, panels, strict=True):
            _draw_panel(panel_ax, frame, motion, label, legend)
        _decorate(figure, axes, solution, len(panels), legend, own_figure=ax is None)
    return figure


# --------------------------------------------------------------------------- layout


def _motions(solution: Solution) -> list[Motion]:
    return list(solution.solutions) or ([solution.motion] if solution.motion is not None else [])


def _frame(solution: Solution, scene: Scene | World | PlanarWorld, view: str) -> _Frame:
    world = scene if isinstance(scene, World | PlanarWorld) else None
    plain = scene if isinstance(scene, Scene) else scene.scene()
    projection = Projection.of(plain.dimension, view)
    world_points = np.array([lifted(p) for p in [*(c.point for c in plain.contacts), *(b.com for b in plain.bodies)]])
    page = [projection(world_points), *[o for o in _shape_outlines(world, projection) if o is not None]]
    page_points = np.vstack(page)
    size = float(np.linalg.norm(page_points.max(axis=0) - page_points.min(axis=0))) or 1.0
    motions = _motions(solution)
    force = max((float(np.linalg.norm(c.force)) for m in motions for c in m.contacts), default=0.0)
    speed = max((_speed(m, plain, size) for m in motions), default=0.0)
    return _Frame(
        plain,
        world,
        projection,
        world_points.mean(axis=0),
        size,
        _ARROW_SHARE * size / force if force > 0 else 0.0,
        _ARROW_SHARE * size / speed if speed > 0 else 0.0,
        speed,
    )


def _speed(motion: Motion, scene: Scene, size: float) -> float:
    """The largest velocity drawn for a motion: a slip, a com velocity, or a rotation times the drawing's size."""
    slips = [float(np.linalg.norm(c.slip)) for c in motion.contacts if c.mode == "sliding"]
    twists = [_linear_angular(t, scene.dimension) for t in motion.twists.values()]
    return max([*slips, *(float(np.linalg.norm(v)) for v, _ in twists), *(float(np.linalg.norm(w)) * size for _, w in twists), 0.0])


def _linear_angular(twist: FloatArray, dimension: int) -> tuple[FloatArray, FloatArray]:
    """(com velocity, angular velocity) as 3-D vectors: a 2-D twist (vx, vy, w) turns about z."""
    twist = np.asarray(twist, dtype=float)
    if dimension == 2:
        return np.array([twist[0], twist[1], 0.0]), np.array([0.0, 0.0, twist[2]])
    return twist[:3], twist[3:]


def _panels(solution: Solution, single: bool) -> list[tuple[str, Motion | None]]:
    if solution.status == "ambiguous" and solution.solutions:
        count = len(solution.solutions)
        shown = solution.solutions[: 1 if single else MAX_PANELS]
        return [(f"motion {i + 1} of {count}" + (" (a continuum)" if m.continuum else ""), m) for i, m in enumerate(shown)]
    return [("", solution.motion)]


def _axes(count: int, ax: Axes | None) -> tuple[Figure, list[Axes]]:
    from matplotlib.figure import Figure

    if ax is not None:
        figure = ax.get_figure()
        assert isinstance(figure, Figure)  # an Axes drawn into belongs to a figure
        return figure, [ax]
    columns = min(count, 3)
    rows = math.ceil(count / columns)
    size = (6.4, 6.0) if count == 1 else (4.2 * columns, 4.0 * rows + 1.4)
    figure = Figure(figsize=size, layout="constrained")
    grid = figure.subplots(rows, columns, squeeze=False).ravel()
    for extra in grid[count:]:
        extra.set_axis_off()
    return figure, list(grid[:count])


# --------------------------------------------------------------------------- one panel


def _draw_panel(ax: Axes, frame: _Frame, motion: Motion | None, label: str, legend: _Legend) -> None:
    page: list[FloatArray] = []
    _draw_parts(ax, frame, page)
    _draw_contacts(ax, frame, motion, legend)
    if motion is not None:
        _draw_arrows(ax, frame, motion, legend, page)
        for name, twist in motion.twists.items():
            _draw_twist(ax, frame, name, twist, legend, page)
    _finish(ax, frame, label, page)


def _draw_parts(ax: Axes, frame: _Frame, page: list[FloatArray]) -> None:
    """The shapes of a World; otherwise each body's outline through its contact points and com."""
    from matplotlib.patches import Polygon

    shaped = set() if frame.world is None else {b.name for b in frame.world.bodies if b.shape is not None}
    for outline in _robot_links(frame):  # behind everything, and left out of the page: an arm would dwarf the part
        ax.add_patch(Polygon(outline, closed=True, facecolor=ROBOT_FILL, edgecolor=EDGE_COLOUR, linewidth=0.5, alpha=0.6, zorder=0.5))
    if isinstance(frame.world, PlanarWorld):
        page += draw_planar_parts(ax, frame.world.bodies, frame.world.movers, frame.centre, 3.0 * frame.size)
    for outline, fill in [*_world_parts(frame), *_contact_outlines(frame, shaped)]:
        ax.add_patch(Polygon(outline, closed=True, facecolor=fill, edgecolor=EDGE_COLOUR, linewidth=0.8, zorder=1))
        page.append(outline)
    for body in frame.scene.bodies:
        com = frame.projection(body.com)[0]
        ax.plot(*com, marker="+", color=EDGE_COLOUR, markersize=8, zorder=3)
        page.append(com[None, :])
        _name(ax, frame, com, body.name)
    for name, where in _mover_places(frame).items():
        _name(ax, frame, where, name)


def _world_parts(frame: _Frame) -> list[tuple[FloatArray, str]]:
    if not isinstance(frame.world, World):
        return []
    parts: list[tuple[SolidBody | ShapedMover, str]] = [(p, MOVER_FILL) for p in frame.world.movers]
    parts += [(p, BODY_FILL) for p in frame.world.bodies]
    out: list[tuple[FloatArray, str]] = []
    for part, fill in parts:
        if isinstance(part.shape, Halfspace):
            patch = plane_patch(part.shape, part.pose, frame.centre, 0.75 * frame.size, frame.projection)
            out.insert(0, (patch, "#F4F4F4"))  # a floor goes under everything
        elif part.shape is not None:
            outline = shape_outline(part.shape, part.pose, frame.projection)
            out += [] if outline is None else [(outline, fill)]
    return out


def _robot_links(frame: _Frame) -> list[FloatArray]:
    """The collision shapes of every URDF robot's links at its configuration, projected."""
    if not isinstance(frame.world, World):
        return []
    outlines = [shape_outline(c.shape, c.pose, frame.projection) for r in frame.world.robots for c in r.colliders]
    return [o for o in outlines if o is not None]


def _shape_outlines(world: World | PlanarWorld | None, projection: Projection) -> list[FloatArray | None]:
    if isinstance(world, PlanarWorld):
        planar: list[PlanarBody | PlanarMover] = [*world.bodies, *world.movers]
        return [planar_extent(p.shape, p.pose) for p in planar if p.shape is not None]
    parts: list[SolidBody | ShapedMover] = [] if world is None else [*world.bodies, *world.movers]
    return [shape_outline(p.shape, p.pose, projection) for p in parts if p.shape is not None and not isinstance(p.shape, Halfspace)]


def _contact_outlines(frame: _Frame, shaped: set[str]) -> list[tuple[FloatArray, str]]:
    out = []
    for body in frame.scene.bodies:
        if body.name in shaped:
            continue
        points = [c.point for c in frame.scene.contacts if body.name in (c.body, c.other)] + [body.com]
        hull = convex_hull(frame.projection(np.array([lifted(p) for p in points])))
        if len(hull) >= 2:  # two points: the outline is a segment
            out.append((hull, BODY_FILL))
    return out


def _mover_places(frame: _Frame) -> dict[str, FloatArray]:
    """Where each mover's name goes: the middle of its contact points on the page."""
    points: dict[str, list[FloatArray]] = {}
    for contact in frame.scene.contacts:
        points.setdefault(contact.other, []).append(frame.projection(contact.point)[0])
    bodies = {b.name for b in frame.scene.bodies}
    return {name: np.mean(p, axis=0) for name, p in points.items() if name not in bodies}


def _name(ax: Axes, frame: _Frame, where: FloatArray, name: str) -> None:
    if len(frame.scene.bodies) + len(frame.scene.movers) <= _LABEL_LIMIT:
        right = where[0] > frame.projection(frame.centre)[0, 0]  # names point away from the middle, into the margin
        offset = 0.02 * frame.size
        x = where[0] - offset if right else where[0] + offset
        ax.text(x, where[1] + offset, name, fontsize=7, color=EDGE_COLOUR, zorder=7, clip_on=True, ha="right" if right else "left")


def _draw_contacts(ax: Axes, frame: _Frame, motion: Motion | None, legend: _Legend) -> None:
    if not frame.scene.contacts:
        return
    points = frame.projection(np.array([lifted(c.point) for c in frame.scene.contacts]))
    if motion is None:
        colours = [NO_MOTION_COLOUR] * len(points)
        legend.add("contact (no motion)", **_dot(NO_MOTION_COLOUR))
    else:
        colours = [MODE_COLOURS[mode] for mode in motion.modes]
        for mode in MODE_COLOURS:
            if mode in motion.modes:
                legend.add(mode, **_dot(MODE_COLOURS[mode]))
    ax.scatter(points[:, 0], points[:, 1], s=70, c=colours, edgecolors="black", linewidths=0.6, zorder=6)


def _dot(colour: str) -> dict[str, Any]:
    return {"marker": "o", "markersize": 8, "markerfacecolor": colour, "markeredgecolor": "black", "linestyle": "None"}


def _draw_arrows(ax: Axes, frame: _Frame, motion: Motion, legend: _Legend, page: list[FloatArray]) -> None:
    """Forces on the body at every contact, and the slip at sliding ones, both from the contact point."""
    points = [lifted(c.point) for c in frame.scene.contacts]
    forces = [(p, lifted(c.force) * frame.force_scale) for p, c in zip(points, motion.contacts, strict=True)]
    slips = [(p, lifted(c.slip) * frame.velocity_scale) for p, c in zip(points, motion.contacts, strict=True) if c.mode == "sliding"]
    if _quiver(ax, frame, forces, FORCE_COLOUR, page):
        legend.add(f"contact force on the body (x {frame.force_scale:.3g})", color=FORCE_COLOUR, **_ARROW)
    if _quiver(ax, frame, slips, SLIP_COLOUR, page):
        legend.add(f"slip (x {frame.velocity_scale:.3g})", color=SLIP_COLOUR, **_ARROW)


_ARROW: dict[str, Any] = {"linewidth": 2.0, "marker": ">", "markersize": 6}


def _quiver(ax: Axes, frame: _Frame, arrows: list[tuple[FloatArray, FloatArray]], colour: str, page: list[FloatArray]) -> bool:
    """Arrows (world start, world vector already scaled to length), true length on the page; False when all are zero."""
    longest = max((float(np.linalg.norm(v)) for _, v in arrows), default=0.0)
    kept = [(p, v) for p, v in arrows if float(np.linalg.norm(v)) > _ZERO * longest]
    if not kept:
        return False
    starts = frame.projection(np.array([p for p, _ in kept]))
    vectors = frame.projection(np.array([v for _, v in kept]))
    ax.quiver(
        starts[:, 0], starts[:, 1], vectors[:, 0], vectors[:, 1],
        color=colour, angles="xy", scale_units="xy", scale=1.0, width=0.006, zorder=5,
    )  # fmt: skip
    page.append(starts + vectors)
    return True


def _draw_twist(ax: Axes, frame: _Frame, name: str, twist: FloatArray, legend: _Legend, page: list[FloatArray]) -> None:
    """The com velocity, and the instantaneous centre (2-D) or screw axis (3-D) when it lies near the body."""
    v, w = _linear_angular(twist, frame.scene.dimension)
    com = lifted(next(b.com for b in frame.scene.bodies if b.name == name))
    tiny = _ZERO * frame.speed
    if float(np.linalg.norm(v)) > tiny:
        _quiver(ax, frame, [(com, v * frame.velocity_scale)], TWIST_COLOUR, page)
        legend.add(f"com velocity (x {frame.velocity_scale:.3g})", color=TWIST_COLOUR, **_ARROW)
    rate = float(np.linalg.norm(w))
    if rate * frame.size <= tiny:
        return
    foot = com + np.cross(w, v) / rate**2  # the point of the axis nearest the com: its velocity is along w
    if float(np.linalg.norm(foot - com)) > _FAR * frame.size:
        return
    if frame.scene.dimension == 2:
        centre = frame.projection(foot)[0]
        ax.plot(*centre, marker="X", markersize=14, color=TWIST_COLOUR, markeredgecolor="black", zorder=4)  # under a contact there
        legend.add("instantaneous centre of rotation", marker="X", markersize=9, color=TWIST_COLOUR, linestyle="None")
        page.append(centre[None, :])
        return
    ends = frame.projection(np.array([foot - _AXIS_SHARE * frame.size * w / rate, foot + _AXIS_SHARE * frame.size * w / rate]))
    ax.plot(ends[:, 0], ends[:, 1], color=TWIST_COLOUR, linewidth=1.8, linestyle="-.", zorder=4)
    head, tail = ends[1], ends[1] - 0.1 * (ends[1] - ends[0])  # an arrowhead at the end w points to
    ax.annotate("", xy=(head[0], head[1]), xytext=(tail[0], tail[1]), arrowprops={"arrowstyle": "-|>", "color": TWIST_COLOUR})
    legend.add("screw axis (arrow: angular velocity)", color=TWIST_COLOUR, linewidth=1.8, linestyle="-.")
    page.append(ends)


def _finish(ax: Axes, frame: _Frame, label: str, page: list[FloatArray]) -> None:
    points = np.vstack([*page, frame.projection(np.array([lifted(c.point) for c in frame.scene.contacts] or [frame.centre]))])
    low, high = points.min(axis=0), points.max(axis=0)
    margin = 0.12 * max(float(np.max(high - low)), frame.size * 0.1)  # room for the names beside the points
    ax.set_xlim(low[0] - margin, high[0] + margin)
    ax.set_ylim(low[1] - margin, high[1] + margin)
    ax.set_aspect("equal", adjustable="box")
    if label:
        ax.set_title(label)
    if frame.projection.name == "iso":
        ax.set_xticks([])
        ax.set_yticks([])
        _triad(ax, frame.projection)
        return
    names = ("x", "y") if frame.projection.name == "plane" else tuple(frame.projection.name)
    ax.set_xlabel(f"{names[0]} (scene units)")
    ax.set_ylabel(f"{names[1]} (scene units)")


def _triad(ax: Axes, projection: Projection) -> None:
    """The world axes as seen in this view, in the panel's lower left corner."""
    origin = np.array([0.07, 0.07])
    for index, axis_name in enumerate("xyz"):
        direction = projection.matrix[:, index] * 0.06
        tip = origin + direction
        label = origin + 1.35 * direction
        ax.annotate(
            "", xy=(tip[0], tip[1]), xytext=(0.07, 0.07), xycoords="axes fraction", arrowprops={"arrowstyle": "->", "color": EDGE_COLOUR}
        )
        ax.text(label[0], label[1], axis_name, transform=ax.transAxes, fontsize=7, ha="center", va="center")


def _decorate(figure: Figure, axes: list[Axes], solution: Solution, panels: int, legend: _Legend, own_figure: bool) -> None:
    title = headline(solution)
    if solution.status == "ambiguous" and len(solution.solutions) > panels:
        title += f" (showing {panels} of {len(solution.solutions)} motions)"
    indeterminate = solution.forces_indeterminate or any(m.forces_indeterminate for m in solution.solutions)
    if indeterminate:
        title += " (forces drawn: one consistent distribution)"
    handles = list(legend.handles.values())
    if not own_figure:
        axes[0].set_title(wrapped(title, 60), loc="left")
        axes[0].legend(handles=handles, loc="best")
        return
    width = figure.get_figwidth()  # inches: about 11 characters of the title's font fit in one
    figure.suptitle(wrapped(title, int(11 * width)), horizontalalignment="left", x=0.02)
    figure.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 2) or 1)
