"""Pictures: figures of a Solution on its scene and animations of a Trajectory (matplotlib), the interactive 3-D viewer (viser).

- :func:`plot`: a Solution drawn on its Scene (or World of shapes), one panel per motion.
- :func:`animate`: a Trajectory drawn on its World, frame by frame (GIF, or MP4 with ffmpeg).
- :func:`view`: the viewer, a viser server with live re-solves (:mod:`.viewer`); one frame is drawn by
  :func:`.scene3d.draw_frame`. Given a Trajectory, a timeline scrubbing its states (:mod:`.timeline`,
  each drawn by :func:`.scene3d.draw_state`).
- :func:`phase_diagram`: a sweep's phase regions over one or two parameters, boundaries refined.
- :data:`MODE_COLOURS` and the other colours: fixed, colour-blind safe (see ``style``).

Rules:

- It reads Solutions, Scenes, Worlds and Trajectories only; it computes no physics
  (a slip arrow is ``ContactResult.slip``, not a new velocity; the
  instantaneous centre and the screw axis are the twist, drawn).
- matplotlib and viser are optional extras, imported inside the functions
  that need them; a missing one raises an error that says how to install it.
- Nothing in the core imports it; the CLI calls it lazily, and
  ``Solution._repr_png_`` calls ``chart`` (which imports nothing of the package but the style).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

if TYPE_CHECKING:
    from .animation import animate
    from .chart import summary_png
    from .choices import ANIMATION_FORMATS, VIEWS, animation_output
    from .figures import MAX_PANELS, plot
    from .phase import STATUS_COLOURS, phase_diagram
    from .scene3d import ArrowScales, DrawnFrame, draw_frame, draw_state
    from .style import FORCE_COLOUR, MODE_COLOURS, NO_MOTION_COLOUR, SLIP_COLOUR, TWIST_COLOUR, require_matplotlib, save
    from .timeline import TrajectoryViewer, view_trajectory
    from .viewer import VIEWER_INSTALL_HINT, Velocities, Viewer, require_viser, view

# Each public name and the module (relative to this package) that defines it, imported when first read (PEP 562):
# the CLI checks ``--view`` against VIEWS, or a picture's suffix, before matplotlib, sim/ and the solvers load.
_MODULES: dict[str, tuple[str, ...]] = {
    "animation": ("animate",),
    "chart": ("summary_png",),
    "figures": ("MAX_PANELS", "plot"),
    "choices": ("ANIMATION_FORMATS", "VIEWS", "animation_output"),
    "phase": ("STATUS_COLOURS", "phase_diagram"),
    "scene3d": ("ArrowScales", "DrawnFrame", "draw_frame", "draw_state"),
    "style": ("FORCE_COLOUR", "MODE_COLOURS", "NO_MOTION_COLOUR", "SLIP_COLOUR", "TWIST_COLOUR", "require_matplotlib", "save"),
    "timeline": ("TrajectoryViewer", "view_trajectory"),
    "viewer": ("VIEWER_INSTALL_HINT", "Velocities", "Viewer", "require_viser", "view"),
}
__getattr__, __dir__ = lazy_exports(__name__, _MODULES)


__all__ = [
    "ANIMATION_FORMATS",
    "ArrowScales",
    "DrawnFrame",
    "FORCE_COLOUR",
    "MAX_PANELS",
    "MODE_COLOURS",
    "NO_MOTION_COLOUR",
    "SLIP_COLOUR",
    "STATUS_COLOURS",
    "TWIST_COLOUR",
    "VIEWER_INSTALL_HINT",
    "VIEWS",
    "animation_output",
    "animate",
    "Velocities",
    "Viewer",
    "TrajectoryViewer",
    "draw_frame",
    "phase_diagram",
    "draw_state",
    "plot",
    "require_matplotlib",
    "require_viser",
    "save",
    "summary_png",
    "view",
    "view_trajectory",
]
