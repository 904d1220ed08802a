"""Pictures: figures of a Solution on its scene, animations of a Trajectory (matplotlib).

- :func:`plot`: a Solution drawn on its Scene (or World of shapes), one panel per motion.
- :func:`animate`: a Trajectory drawn on its World, frame by frame (GIF, or MP4 with ffmpeg).
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

from .animation import ANIMATION_FORMATS, animate
from .chart import summary_png
from .figures import MAX_PANELS, plot
from .geometry import VIEWS
from .style import FORCE_COLOUR, MODE_COLOURS, NO_MOTION_COLOUR, SLIP_COLOUR, TWIST_COLOUR, require_matplotlib, save

__all__ = [
    "ANIMATION_FORMATS",
    "FORCE_COLOUR",
    "MAX_PANELS",
    "MODE_COLOURS",
    "NO_MOTION_COLOUR",
    "SLIP_COLOUR",
    "TWIST_COLOUR",
    "VIEWS",
    "animate",
    "plot",
    "require_matplotlib",
    "save",
    "summary_png",
]
