"""A Trajectory as a moving picture (GIF, or MP4 when ffmpeg is installed): matplotlib, headless.

Each frame draws the World at one state of the run (its shapes and URDF links, from
``State.applied``; a planar world's shapes in their plane, :mod:`.planar`) with the
contacts recorded at that step: dots in the colour of their mode, force arrows on one
scale for the whole run. The camera is fixed over the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import numpy.typing as npt

from ..adapters import AnyWorld, Halfspace, PlanarWorld, World
from ..errors import SceneError
from ..sim.state import State
from ..sim.step import StepResult
from .choices import ANIMATION_FORMATS, animation_output
from .geometry import Projection, plane_patch, shape_outline
from .planar import draw_planar_parts
from .style import BODY_FILL, EDGE_COLOUR, FORCE_COLOUR, MODE_COLOURS, MOVER_FILL, NO_MOTION_COLOUR, ROBOT_FILL, require_matplotlib, styled

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["animate", "ANIMATION_FORMATS", "MAX_FRAMES", "Run", "check_run_names", "frame_indices"]

FloatArray = npt.NDArray[np.float64]
MAX_FRAMES = 240  # a longer run is sampled at even times: a picture, not a record (the file holds every step)
FORCE_LENGTH = 0.3  # the largest force of the run is drawn this fraction of the largest body's size


class Run(Protocol):
    """What the pictures read from a run: a :class:`quasistatic.sim.Trajectory`, named here by what it holds so
    that ``Trajectory._repr_html_`` may draw itself through this module without an import cycle."""

    @property
    def states(self) -> tuple[State, ...]: ...

    @property
    def steps(self) -> tuple[StepResult, ...]: ...

    @property
    def times(self) -> FloatArray: ...


@dataclass(frozen=True)
class _Camera:
    projection: Projection
    low: FloatArray
    high: FloatArray
    force_scale: float  # length per unit force
    size: float


def animate(
    trajectory: Run, world: AnyWorld, output: str | Path, *, view: str = "iso", fps: int = 20, max_frames: int = MAX_FRAMES
) -> Path:
    """Write ``trajectory`` (a Trajectory run on ``world``) as an animation; ``.gif`` always, ``.mp4`` with ffmpeg on
    the PATH. A run of more than ``max_frames`` states is drawn at that many even times. A planar world is drawn in
    its plane (``view`` is for 3-D worlds)."""
    require_matplotlib()
    output = animation_output(output)
    check_run_names(trajectory, world)
    frames = frame_indices(trajectory, max_frames)
    camera = _camera(trajectory, world, Projection.of(world.dimension, view))
    _write(trajectory, world, frames, camera, output, fps)
    return output


def check_run_names(trajectory: Run, world: AnyWorld) -> None:
    """Raise :class:`SceneError` unless ``world`` has the trajectory's bodies, movers and robots: the scene it was run on."""
    state = trajectory.states[0]
    for kind, names, known in (
        ("bodies", set(state.bodies), {b.name for b in world.bodies}),
        ("movers", set(state.movers), {m.name for m in world.movers}),
        ("robots", set(state.robots), {r.name for r in world.robots}),
    ):
        if names != known:
            raise SceneError(
                kind, sorted(names), f"the trajectory's {kind} differ from the scene's ({sorted(known)}): not the scene it was run on"
            )


def frame_indices(trajectory: Run, limit: int) -> list[int]:
    """Every state, or for a long run the last state at or before each of ``limit`` even times (ends included)."""
    count = len(trajectory.states)
    if count <= limit:
        return list(range(count))
    times = trajectory.times
    wanted = np.linspace(times[0], times[-1], limit)
    return [int(i) for i in np.searchsorted(times, wanted, side="right") - 1]


def _camera(trajectory: Run, world: AnyWorld, projection: Projection) -> _Camera:
    """Bounds that hold every body and mover over the run, and one force scale for every frame."""
    size = world.size
    points = [
        projection(np.array([p.position for p in s.bodies.values()] + [p.position for p in s.movers.values()])) for s in trajectory.states
    ]
    stacked = np.vstack([p for p in points if len(p)]) if any(len(p) for p in points) else np.zeros((1, 2))
    low, high = stacked.min(axis=0) - size, stacked.max(axis=0) + size
    largest = max((float(np.linalg.norm(c.force)) for s in trajectory.steps for c in s.contacts), default=0.0)
    return _Camera(projection, low, high, FORCE_LENGTH * size / largest if largest > 0 else 0.0, size)


def _write(trajectory: Run, world: AnyWorld, frames: list[int], camera: _Camera, output: Path, fps: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import animation
    from matplotlib.figure import Figure

    with styled():
        figure = Figure(figsize=(6.4, 4.8))
        ax = figure.add_subplot()

        def draw(k: int) -> list[Any]:
            ax.clear()
            index = frames[k]
            _draw_state(ax, trajectory.states[index].applied(world), trajectory.steps[index], camera)
            return []

        movie = animation.FuncAnimation(figure, draw, frames=len(frames), blit=False)
        writer = animation.PillowWriter(fps=fps) if output.suffix.lower() == ".gif" else animation.FFMpegWriter(fps=fps)
        movie.save(str(output), writer=writer)


def _draw_state(ax: Axes, world: AnyWorld, step: StepResult, camera: _Camera) -> None:
    centre = np.mean([b.pose.position for b in world.bodies], axis=0) if world.bodies else np.zeros(3)
    if isinstance(world, PlanarWorld):
        reach = float(np.linalg.norm(camera.high - camera.low))  # the centre is in view: a strip this long crosses it
        draw_planar_parts(ax, world.bodies, world.movers, centre, reach)
    else:
        _draw_world(ax, world, centre, camera)
    _draw_contacts(ax, step, camera)
    ax.set_xlim(camera.low[0], camera.high[0])
    ax.set_ylim(camera.low[1], camera.high[1])
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    events = ", ".join(sorted({e.kind for e in step.events}))
    proof = "" if step.certified else ", NOT certified"
    ax.set_title(f"t = {step.time:.4g} s: {step.status}{proof}" + (f" ({events})" if events else ""))


def _draw_world(ax: Axes, world: World, centre: FloatArray, camera: _Camera) -> None:
    """A 3-D world's robot links and shapes, projected."""
    from matplotlib.patches import Polygon

    projection = camera.projection
    for collider in (c for r in world.robots for c in r.colliders):
        outline = shape_outline(collider.shape, collider.pose, projection)
        if outline is not None:
            ax.add_patch(Polygon(outline, closed=True, facecolor=ROBOT_FILL, edgecolor=EDGE_COLOUR, linewidth=0.5, alpha=0.6, zorder=0.5))
    parts = [(m, MOVER_FILL) for m in world.movers] + [(b, BODY_FILL) for b in world.bodies]
    for part, fill in parts:
        if isinstance(part.shape, Halfspace):
            patch = plane_patch(part.shape, part.pose, centre, 3.0 * camera.size, projection)
            ax.add_patch(Polygon(patch, closed=True, facecolor="#F4F4F4", edgecolor=EDGE_COLOUR, linewidth=0.5, zorder=0))
        elif part.shape is not None:
            outline = shape_outline(part.shape, part.pose, projection)
            if outline is not None:
                ax.add_patch(Polygon(outline, closed=True, facecolor=fill, edgecolor=EDGE_COLOUR, linewidth=0.8, zorder=1))


def _draw_contacts(ax: Axes, step: StepResult, camera: _Camera) -> None:
    projection = camera.projection
    for contact in step.contacts:
        where = projection(contact.point[None, :])[0]
        colour = MODE_COLOURS.get(contact.mode or "", NO_MOTION_COLOUR)
        ax.plot(*where, marker="o", markersize=5, color=colour, zorder=4)
        force = projection(contact.force[None, :])[0] * camera.force_scale
        if camera.force_scale > 0 and math.hypot(*force) > 0:
            ax.annotate("", xy=where + force, xytext=where, arrowprops={"arrowstyle": "->", "color": FORCE_COLOUR, "lw": 1.2}, zorder=5)
