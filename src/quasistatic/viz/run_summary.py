"""A Trajectory in a notebook (``Trajectory._repr_html_``): how the run ended, whether every step is proven,
its events as a table, and a small GIF of the run on its scene when matplotlib is there.

It imports no Trajectory (``sim/trajectory.py`` calls it): the run is read through what it holds
(:class:`.animation.Run`), so the pictures make no import cycle with the simulator.
"""

from __future__ import annotations

import base64
import html
import tempfile
from pathlib import Path
from typing import Any

from ..adapters import AnyWorld
from ..errors import BackendUnavailableError, QuasistaticError
from .animation import animate
from .style import FIGURES_INSTALL_HINT, require_matplotlib

__all__ = ["NOTEBOOK_FRAMES", "trajectory_html"]

NOTEBOOK_FRAMES = 24  # frames of a notebook's GIF (a longer run is drawn at this many even times): a few hundred kB
_FPS = 8  # its frames per second: the run plays in about 3 s


def trajectory_html(trajectory: Any, world: AnyWorld | None, no_world: str = "") -> str:
    """The run's verdict, proof, length and events, and its GIF on ``world`` (``no_world``: why there is none)."""
    parts = [
        f"<p><b>{html.escape(trajectory.status)}</b>: {html.escape(trajectory.message)}</p>",
        f"<p>{html.escape(_summary_line(trajectory))}</p>",
        _events_table(trajectory),
        _picture(trajectory, world, no_world),
    ]
    return '<div class="quasistatic-trajectory">' + "".join(parts) + "</div>"


def _summary_line(trajectory: Any) -> str:
    steps = trajectory.steps
    uncertified = sum(1 for s in steps if not s.certified)
    proof = "every step proven" if uncertified == 0 else f"NOT proven: {uncertified} of {len(steps)} steps uncertified"
    return (
        f"{len(trajectory.states)} states to t = {trajectory.times[-1]:.4g} s; {proof}; "
        f"deepest penetration before correction {trajectory.max_penetration:.3g}"
    )


def _events_table(trajectory: Any) -> str:
    events = trajectory.events
    if not events:
        return "<p>no events (no contact made or broken, no mode or status change)</p>"
    rows = "".join(
        f"<tr><td>{e.time:.6g}</td><td>{html.escape(e.kind)}</td><td>{html.escape(' / '.join(p for p in e.pair if p))}</td>"
        f"<td>{html.escape(e.detail)}</td></tr>"
        for e in events
    )
    return f"<table><tr><th>time [s]</th><th>event</th><th>between</th><th>what</th></tr>{rows}</table>"


def _picture(trajectory: Any, world: AnyWorld | None, no_world: str) -> str:
    """The run as a GIF (``viz.animate``), or one line saying why it is not drawn."""
    try:
        require_matplotlib()
    except BackendUnavailableError:
        return f"<p>no animation: {html.escape(FIGURES_INSTALL_HINT)}</p>"
    if world is None:
        return f"<p>no animation: {html.escape(no_world)}</p>"
    with tempfile.TemporaryDirectory(prefix="quasistatic-") as folder:
        path = Path(folder) / "run.gif"
        try:
            animate(trajectory, world, path, fps=_FPS, max_frames=NOTEBOOK_FRAMES)
        except QuasistaticError as error:
            return f"<p>no animation: {html.escape(str(error))}</p>"
        data = base64.b64encode(path.read_bytes()).decode()
    return f'<img alt="the run on its scene" src="data:image/gif;base64,{data}"/>'
