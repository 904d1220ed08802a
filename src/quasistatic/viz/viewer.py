"""The interactive 3-D viewer: a viser server showing a Solution on its scene, with live re-solves.

:func:`view` starts a server on localhost and returns a :class:`Viewer`
handle (nothing blocks: :meth:`Viewer.wait` does, until Ctrl-C). The page
shows the scene drawn by :func:`quasistatic.viz.scene3d.draw_frame`, the
answer's status, a control to switch between the motions of an ambiguous
answer, and one slider per robot joint velocity and mover twist entry: moving
one re-solves the scene with the new velocities (through :func:`quasistatic.solve`,
audited like every answer) and redraws it. :meth:`Viewer.export_html`
writes the current view as one self-contained HTML file (viser's static
client with the scene embedded), which opens without a server.
"""

from __future__ import annotations

import dataclasses
import os
import threading
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, overload

import numpy as np

from ..adapters import World
from ..errors import QuasistaticError, SceneError
from ..model import Robot, Scene
from ..sim import Trajectory
from ..solution import Motion, Solution
from ..solve import solve, with_detection
from .geometry import VIEWS
from .scene3d import ArrowScales, DrawnFrame, draw_frame
from .server import VIEWER_INSTALL_HINT, place_camera, require_viser, serve_until_interrupted, start_server, stop_server, url_of
from .style import headline
from .timeline import TrajectoryViewer, view_trajectory

__all__ = ["VIEWER_INSTALL_HINT", "Velocities", "Viewer", "require_viser", "view"]

_SLIDER_STEPS = 200  # steps across a slider's range


@dataclass(frozen=True)
class Velocities:
    """What the viewer's sliders set: each robot's joint velocities and each free-moving mover's twist (world frame)."""

    robots: Mapping[str, np.ndarray]
    movers: Mapping[str, np.ndarray]

    @classmethod
    def of(cls, scene: Scene | World) -> Velocities:
        if isinstance(scene, World):
            robots = {r.name: np.asarray(r.joint_velocities, dtype=float) for r in scene.robots}
            robots |= {r.name: np.asarray(r.joint_velocities, dtype=float) for r in scene.explicit_robots}
            movers = {m.name: _twist(m.twist, 3) for m in scene.movers}
        else:
            robots = {r.name: np.array(r.joint_velocities, dtype=float) for r in scene.robots}
            movers = {m.name: _twist(m.twist, scene.dimension) for m in scene.movers if m.robot is None}
        return cls(robots, movers)

    def applied(self, scene: Scene | World) -> Scene | World:
        """The same scene with these velocities (names not listed keep theirs)."""
        if isinstance(scene, World):
            return dataclasses.replace(
                scene,
                robots=tuple(r.at(joint_velocities=self.robots.get(r.name, r.joint_velocities)) for r in scene.robots),
                explicit_robots=tuple(self._robot(r) for r in scene.explicit_robots),
                movers=tuple(dataclasses.replace(m, twist=self.movers.get(m.name, m.twist)) for m in scene.movers),
            )
        # Everything else (springs, closing time, joint stiffness, limits) is kept: the live answer is the scene's.
        return dataclasses.replace(
            scene,
            movers=tuple(dataclasses.replace(m, twist=self.movers.get(m.name, m.twist)) for m in scene.movers),
            robots=tuple(self._robot(r) for r in scene.robots),
        )

    def _robot(self, robot: Robot) -> Robot:
        return dataclasses.replace(robot, joint_velocities=self.robots.get(robot.name, robot.joint_velocities))


def _twist(twist: Any, dimension: int) -> np.ndarray:
    return np.zeros(3 if dimension == 2 else 6) if twist is None else np.array(twist, dtype=float)


class Viewer:
    """A running viewer: its server, the answer shown, and what the last frame drew.

    Attributes
    ----------
    server : viser.ViserServer
    solution : Solution
        The answer shown (after a re-solve, the new one).
    scene : Scene
        The point-contact scene it answers.
    world : World or None
        The World of shapes it came from, if any.
    velocities : Velocities
        The robot and mover velocities of the scene shown.
    drawn : DrawnFrame
        The scene-tree names of the frame on show.
    """

    def __init__(self, server: Any, solution: Solution, scene: Scene | World, method: str, camera: str = "iso") -> None:
        self.server = server
        self.method = method
        self.world = scene if isinstance(scene, World) else None
        self._detection = None if self.world is None else self.world.detect()
        self.scene = scene if isinstance(scene, Scene) else scene.scene(self._detection)
        self.velocities = Velocities.of(scene)
        self.solution = solution
        self._lock = threading.RLock()  # a re-solve and the motion control both redraw, from viser's worker threads
        self._status = server.gui.add_markdown("")
        self._motion_choice = server.gui.add_dropdown("motion", ("motion 1",))
        self._motion_choice.on_update(lambda _: self._redraw())
        joints = {r.name: r.joint_labels() for r in self.scene.robots}
        self._sliders = _add_sliders(server, self.velocities, joints, self._on_slider)
        self._place_camera(camera)
        self.drawn = self._show(solution)

    @property
    def url(self) -> str:
        """The address to open in a browser."""
        return url_of(self.server)

    @property
    def motions(self) -> list[Motion]:
        """The motions the control switches between: an ambiguous answer's list, or the one motion."""
        return list(self.solution.solutions) or ([self.solution.motion] if self.solution.motion is not None else [])

    @property
    def sliders(self) -> dict[str, tuple[Any, ...]]:
        """The velocity sliders (viser handles) by robot or mover name, in joint or twist order: setting one's
        ``value`` re-solves, as moving it in the browser does."""
        return {name: tuple(row) for group in (self._sliders.robots, self._sliders.movers) for name, row in group.items()}

    def show_motion(self, index: int) -> DrawnFrame:
        """Draw motion ``index`` (0-based) of the answer, as the motion control does."""
        labels = self._motion_choice.options
        if not 0 <= index < len(labels):
            raise ValueError(f"motion {index} is not one of the {len(labels)} motions shown")
        self._motion_choice.value = labels[index]
        return self._redraw()

    def resolve(self, velocities: Velocities) -> Solution:
        """Solve the scene again with new velocities, as moving a slider does, and show the answer."""
        with self._lock:
            self._status.content = "**solving...**"
            source: Scene | World = self.world if self.world is not None else self.scene
            changed = velocities.applied(source)
            scene = changed.scene(self._detection) if isinstance(changed, World) else changed
            solution = solve(scene, method=self.method)
            if self._detection is not None:
                solution = with_detection(solution, self._detection)
            self.velocities = velocities
            self.world = changed if isinstance(changed, World) else None
            self.scene = scene
            self.solution = solution
            self.drawn = self._show(solution)
            return solution

    def export_html(self, path: str | os.PathLike[str]) -> Path:
        """Write the current view as one HTML file that opens without a server (the scene only: no controls)."""
        target = Path(path)
        target.write_text(self.server.scene.as_html(), encoding="utf-8")
        return target

    def wait(self) -> None:
        """Block until Ctrl-C, then stop the server."""
        serve_until_interrupted(self.stop)

    def stop(self) -> None:
        stop_server(self.server)

    # ----------------------------------------------------------------- drawing

    def _show(self, solution: Solution) -> DrawnFrame:
        """A new answer: its scales, the motion control's choices, the status text, and its first motion drawn."""
        self._scales = ArrowScales.of(solution, self.scene, self.world)
        count = len(self.motions)
        labels = tuple(f"motion {i + 1} of {count}" + (" (a continuum)" if m.continuum else "") for i, m in enumerate(self.motions))
        self._motion_choice.options = labels or ("no motion",)
        self._motion_choice.value = self._motion_choice.options[0]
        self._motion_choice.visible = count > 1
        self._status.content = _status_text(solution, self._scales)
        return self._redraw()

    def _redraw(self) -> DrawnFrame:
        with self._lock:
            options = list(self._motion_choice.options)
            index = options.index(self._motion_choice.value) if self._motion_choice.value in options else 0
            motion = self.motions[index] if index < len(self.motions) else None
            self.drawn = draw_frame(self.server.scene, self.scene, motion, self._scales, self.world)
            return self.drawn

    def _place_camera(self, view: str) -> None:
        scales = ArrowScales.of(self.solution, self.scene, self.world)
        place_camera(self.server, scales.centre, scales.size, self.scene.dimension, view)

    def _on_slider(self) -> None:
        """A slider moved: re-solve; a failure is shown in the status text (the server keeps running)."""
        try:
            self.resolve(self._slider_velocities())
        except (QuasistaticError, ValueError) as exc:
            self._status.content = f"**error**: {exc}"

    def _slider_velocities(self) -> Velocities:
        robots = {name: np.array([s.value for s in sliders]) for name, sliders in self._sliders.robots.items()}
        movers = {name: np.array([s.value for s in sliders]) for name, sliders in self._sliders.movers.items()}
        return Velocities(robots, movers)


@dataclass(frozen=True)
class _Sliders:
    robots: dict[str, list[Any]]
    movers: dict[str, list[Any]]


def _add_sliders(server: Any, velocities: Velocities, joints: Mapping[str, tuple[str, ...]], on_change: Any) -> _Sliders:
    """One slider per joint velocity and twist entry, grouped by robot and mover; each re-solves when moved."""
    sliders = _Sliders({}, {})
    for group, values, labels in [
        *((sliders.robots, (name, v), list(joints[name])) for name, v in velocities.robots.items()),
        *((sliders.movers, (name, v), _twist_labels(v.size)) for name, v in velocities.movers.items()),
    ]:
        name, vector = values
        with server.gui.add_folder(name):
            group[name] = [_slider(server, label, value, vector) for label, value in zip(labels, vector, strict=True)]
    for handle in [s for group in (sliders.robots, sliders.movers) for row in group.values() for s in row]:
        handle.on_update(lambda _: on_change())
    return sliders


def _twist_labels(size: int) -> list[str]:
    return ["vx", "vy", "w"] if size == 3 else ["vx", "vy", "vz", "wx", "wy", "wz"]


def _slider(server: Any, label: str, value: float, group: np.ndarray) -> Any:
    """A slider over +-2 times the group's largest entry (+-1 when all are zero), starting at ``value``."""
    reach = 2.0 * float(np.max(np.abs(group))) or 1.0
    return server.gui.add_slider(label, min=-reach, max=reach, step=reach / _SLIDER_STEPS * 2, initial_value=float(value))


def _status_text(solution: Solution, scales: ArrowScales) -> str:
    proven = (
        "" if solution.certified or solution.status not in ("solved", "ambiguous") else " **(not proven: the motion may not be unique)**"
    )
    lines = [
        f"**{headline(solution)}**{proven}",
        f"forces: {scales.force:.3g} length per unit force; slips and com velocities: {scales.velocity:.3g} length per unit velocity",
        "colours: rolling green, sliding vermillion, separating sky blue; force blue, slip orange, com velocity purple",
    ]
    return "\n\n".join(lines)


@overload
def view(
    answer: Solution,
    scene: Scene | World,
    *,
    host: str = ...,
    port: int = ...,
    method: str = ...,
    camera: str = ...,
    verbose: bool = ...,
) -> Viewer: ...
@overload
def view(
    answer: Trajectory,
    scene: World | None = None,
    *,
    host: str = ...,
    port: int = ...,
    method: str = ...,
    camera: str = ...,
    verbose: bool = ...,
) -> TrajectoryViewer: ...
def view(
    answer: Solution | Trajectory,
    scene: Scene | World | None = None,
    *,
    host: str = "127.0.0.1",
    port: int = 8080,
    method: str = "auto",
    camera: str = "iso",
    verbose: bool = False,
) -> Viewer | TrajectoryViewer:
    """Show a solution on its scene, or a simulated run with a timeline, in a viser server (returns at once;
    ``.wait()`` blocks, ``.stop()`` ends it).

    Parameters
    ----------
    answer : Solution or Trajectory
        The answer to show, or a run (:func:`quasistatic.viz.timeline.view_trajectory`: a timeline of its states).
    scene : Scene or World
        The scene it answers; a World's shapes and URDF robot links are drawn too. For a Trajectory: the World
        it was run on (by default the scene file it names, read again).
    host, port : str, int
        Where the server listens (viser takes the next free port when ``port`` is taken: see :attr:`Viewer.url`).
    method : str
        The solver used when a slider re-solves (a Trajectory is drawn, never solved).
    camera : str
        Where the camera starts, for a 3-D scene: one of the pictures' views (``iso``, ``xy``, ``xz``, ``yz``).
    verbose : bool
        Let viser print its own banner.

    Raises
    ------
    BackendUnavailableError
        When viser (the ``viewer`` extra) is not installed.
    """
    if isinstance(answer, Trajectory):
        if scene is not None and not isinstance(scene, World):
            raise SceneError("scene", type(scene).__name__, "a trajectory is drawn on the World of shapes it was run on")
        return view_trajectory(answer, scene, host=host, port=port, camera=camera, verbose=verbose)
    if scene is None:
        raise SceneError("scene", "None", "a Solution is drawn on the Scene or World it answers")
    if camera not in VIEWS:
        raise ValueError(f"view: {camera!r} is not one of {', '.join(VIEWS)}")
    return Viewer(start_server(host, port, verbose), answer, scene, method, camera)
