"""A simulated run in the 3-D viewer: a timeline slider (and play/pause) scrubbing the states of a Trajectory.

:func:`view_trajectory` starts a viser server and returns a :class:`TrajectoryViewer`. Each state is drawn
by :func:`quasistatic.viz.scene3d.draw_state`: the World placed at the state (``State.applied``: bodies,
movers and URDF links), the contacts the trajectory recorded there in the colour of their mode, force
arrows and com velocities on one scale for the whole run. The panel shows the run's verdict and the
step's time, status, proof, choice and events. Nothing is solved: everything drawn was recorded.

:meth:`TrajectoryViewer.export_html` writes the whole run as one HTML file: viser's static client plays
a recording of every frame (sampled to :data:`MAX_EXPORT_FRAMES`) in simulated time, with its own
play/pause button and time bar.
"""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..adapters import World
from ..errors import SceneError
from ..sim import State, StepResult, Trajectory
from .animation import check_run_names, frame_indices
from .geometry import VIEWS
from .scene3d import ArrowScales, DrawnFrame, draw_state
from .server import place_camera, serve_until_interrupted, start_server, stop_server, url_of

__all__ = ["MAX_EXPORT_FRAMES", "TrajectoryViewer", "view_trajectory"]

MAX_EXPORT_FRAMES = 240  # a longer run is exported at this many even times (the live timeline shows every state)
_TICK = 0.05  # seconds between the frames of the live playback
_SPEEDS = ("0.1x", "0.25x", "0.5x", "1x", "2x", "4x", "10x")  # simulated seconds per second of playback
_HOLD_SHARE = 0.1  # an exported recording holds its last frame for this share of the run before it loops
_MAX_MARKS = 12  # the timeline marks at most this many states with events (more would be unreadable)


class TrajectoryViewer:
    """A running viewer of a Trajectory: its server, the state on show, and what its frame drew.

    Attributes
    ----------
    server : viser.ViserServer
    trajectory : Trajectory
    world : World
        The World the run was made on (the states place it).
    scales : ArrowScales
        The arrow scales of the whole run.
    index : int
        The state on show (0-based).
    drawn : DrawnFrame
        The scene-tree names of its frame.
    """

    def __init__(self, server: Any, trajectory: Trajectory, world: World, camera: str = "iso") -> None:
        check_run_names(trajectory, world)
        self.server = server
        self.trajectory = trajectory
        self.world = world
        self.scales = ArrowScales.of_run(world, trajectory.states, trajectory.steps)
        self._times = trajectory.times
        self._lock = threading.RLock()  # the timeline, the play thread and the caller all redraw
        self._stop_playing = threading.Event()
        self._player: threading.Thread | None = None
        self.index = -1
        server.gui.add_markdown(_run_text(trajectory, self.scales))
        self._timeline = _add_timeline(server, trajectory)
        self._timeline.on_update(lambda _: self.go_to(int(self._timeline.value)))
        self._speed = server.gui.add_dropdown("speed", _SPEEDS, initial_value="1x")
        server.gui.add_button("play").on_click(lambda _: self.play())
        server.gui.add_button("pause").on_click(lambda _: self.pause())
        self._step_text = server.gui.add_markdown("")
        place_camera(server, self.scales.centre, self.scales.size, 3, camera)
        self.drawn = self.go_to(0)

    @property
    def url(self) -> str:
        """The address to open in a browser."""
        return url_of(self.server)

    @property
    def timeline(self) -> Any:
        """The timeline slider (a viser handle): setting its ``value`` shows that state, as dragging it does."""
        return self._timeline

    @property
    def state(self) -> State:
        return self.trajectory.states[self.index]

    @property
    def step(self) -> StepResult:
        return self.trajectory.steps[self.index]

    @property
    def playing(self) -> bool:
        return self._player is not None and self._player.is_alive()

    def go_to(self, index: int) -> DrawnFrame:
        """Show state ``index`` (0-based; negative counts from the end), as moving the timeline does."""
        count = len(self.trajectory.states)
        if not -count <= index < count:
            raise ValueError(f"step {index} is not one of the {count} states of the run (0 to {count - 1})")
        index %= count
        with self._lock:
            if index != self.index:
                self.index = index
                self.drawn = draw_state(self.server.scene, self.state.applied(self.world), self.step, self.scales, _label(self.step))
                self._step_text.content = _step_text(self.trajectory, index)
                self._timeline.value = index  # its callback finds this state already shown
            return self.drawn

    def play(self) -> None:
        """Step through the states in simulated time (times the speed chosen), from here, or from the start at the end."""
        with self._lock:
            if self.playing:
                return
            if self.index == len(self.trajectory.states) - 1:
                self.go_to(0)
            self._stop_playing.clear()
            self._player = threading.Thread(target=self._play, name="quasistatic-timeline", daemon=True)
            self._player.start()

    def pause(self) -> None:
        """Stop the playback where it is."""
        self._stop_playing.set()
        player = self._player
        if player is not None and player is not threading.current_thread():
            player.join()

    def export_html(self, path: str | os.PathLike[str]) -> Path:
        """Write the whole run as one HTML file that opens without a server: viser's player shows the frames in
        simulated time (play/pause, a time bar, its speed), the step's time and status above the scene."""
        target = Path(path)
        with self._lock:
            shown = self.index
            frames = frame_indices(self.trajectory, MAX_EXPORT_FRAMES)
            self.go_to(frames[0])
            recording = self.server.get_scene_serializer()
            try:
                for previous, index in zip(frames, frames[1:], strict=False):
                    recording.insert_sleep(max(float(self._times[index] - self._times[previous]), 0.0))
                    self.go_to(index)
                recording.insert_sleep(_HOLD_SHARE * max(float(self._times[-1] - self._times[0]), 0.0))
            finally:
                page = recording.as_html()  # also ends the recording
            self.go_to(shown)
        target.write_text(page, encoding="utf-8")
        return target

    def wait(self) -> None:
        """Block until Ctrl-C, then stop the server."""
        serve_until_interrupted(self.stop)

    def stop(self) -> None:
        self.pause()
        stop_server(self.server)

    def _play(self) -> None:
        start_wall, start_time = time.monotonic(), float(self._times[self.index])
        last = len(self._times) - 1
        while not self._stop_playing.wait(_TICK):
            speed = float(str(self._speed.value).rstrip("x"))
            now = start_time + speed * (time.monotonic() - start_wall)
            index = min(int(np.searchsorted(self._times, now, side="right")) - 1, last)
            self.go_to(max(index, 0))
            if index == last:
                return


def _add_timeline(server: Any, trajectory: Trajectory) -> Any:
    """The step slider over every state; the states where an event happened are marked on it."""
    last = len(trajectory.states) - 1
    marked = [i for i, s in enumerate(trajectory.steps) if s.events][:_MAX_MARKS]
    marks = tuple((i, "") for i in marked) or None
    return server.gui.add_slider("step", min=0, max=max(last, 1), step=1, initial_value=0, marks=marks, disabled=last == 0)


def _proof(certified: bool) -> str:
    return "proven" if certified else "NOT proven (the motion may not be unique)"


def _label(step: StepResult) -> str:
    proof = "" if step.certified or step.status not in ("solved", "ambiguous") else ", not proven"
    return f"t = {step.time:.4g} s: {step.status}{proof}"


def _run_text(trajectory: Trajectory, scales: ArrowScales) -> str:
    uncertified = sum(1 for s in trajectory.steps if not s.certified)
    proof = "every step proven" if uncertified == 0 else f"**NOT proven**: {uncertified} of {len(trajectory.steps)} steps uncertified"
    return "\n\n".join(
        [
            f"**run: {trajectory.status}**: {trajectory.message}",
            f"{len(trajectory.states)} states to t = {trajectory.times[-1]:.4g} s; {proof}",
            f"forces: {scales.force:.3g} length per unit force; com velocities: {scales.velocity:.3g} length per unit velocity",
            "colours: rolling green, sliding vermillion, separating sky blue, no motion grey; force blue, com velocity purple",
        ]
    )


def _step_text(trajectory: Trajectory, index: int) -> str:
    step = trajectory.steps[index]
    lines = [f"**step {index} of {len(trajectory.steps) - 1}: t = {step.time:.6g} s**", f"{step.status}, {_proof(step.certified)}"]
    if step.message:
        lines.append(step.message)
    if step.choice:
        lines.append(f"motion chosen: {step.choice}")
    modes = [c.mode or "none" for c in step.contacts]
    lines.append(f"{len(step.contacts)} contacts: " + ", ".join(f"{modes.count(m)} {m}" for m in dict.fromkeys(modes)))
    lines += [f"event at t = {e.time:.6g} s: {e.kind}" + (f" ({e.detail})" if e.detail else "") for e in step.events]
    return "\n\n".join(lines)


def view_trajectory(
    trajectory: Trajectory,
    world: World | None = None,
    *,
    host: str = "127.0.0.1",
    port: int = 8080,
    camera: str = "iso",
    verbose: bool = False,
) -> TrajectoryViewer:
    """Show a simulated run in a viser server with a timeline (returns at once; ``.wait()`` blocks, ``.stop()`` ends it).

    Parameters
    ----------
    trajectory : Trajectory
        The run to show.
    world : World, optional
        The World it was run on; by default the scene file the trajectory names, read again.
    host, port : str, int
        Where the server listens (viser takes the next free port when ``port`` is taken: see :attr:`TrajectoryViewer.url`).
    camera : str
        Where the camera starts: one of the pictures' views (``iso``, ``xy``, ``xz``, ``yz``).
    verbose : bool
        Let viser print its own banner.

    Raises
    ------
    SceneError
        When the World is not the one the run was made on, or none is given and the trajectory names no scene file.
    BackendUnavailableError
        When viser (the ``viewer`` extra) is not installed.
    """
    source = trajectory.scene_world() if world is None else world
    if not isinstance(source, World):
        raise SceneError(
            "scene", trajectory.scene_file, "the 3-D viewer does not draw runs of planar scenes of shapes yet (viz.animate does)"
        )
    check_run_names(trajectory, source)
    if camera not in VIEWS:
        raise ValueError(f"view: {camera!r} is not one of {', '.join(VIEWS)}")
    return TrajectoryViewer(start_server(host, port, verbose), trajectory, source, camera)
