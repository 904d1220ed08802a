"""The fixed look of every picture: colours (colour-blind safe), the matplotlib style, and the extra it needs.

Colours are Okabe & Ito's palette (2008), distinguishable under the common
colour-vision deficiencies; each meaning keeps one colour in every picture so
that a reader (and a test) can find it:

- contact modes: rolling ``#009E73`` (bluish green), sliding ``#D55E00``
  (vermillion), separating ``#56B4E9`` (sky blue); a contact of an answer
  without a motion (jammed, unstable) is grey ``#808080``;
- force arrows ``#0072B2`` (blue), slip arrows ``#E69F00`` (orange), the
  twist (instantaneous centre, screw axis, velocity of the com) ``#CC79A7``
  (reddish purple).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from ..errors import BackendUnavailableError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "FIGURES_INSTALL_HINT",
    "FORCE_COLOUR",
    "MODE_COLOURS",
    "NO_MOTION_COLOUR",
    "SLIP_COLOUR",
    "TWIST_COLOUR",
    "headline",
    "require_matplotlib",
    "save",
    "styled",
    "wrapped",
]

MODE_COLOURS = {"rolling": "#009E73", "sliding": "#D55E00", "separating": "#56B4E9"}
NO_MOTION_COLOUR = "#808080"
FORCE_COLOUR = "#0072B2"
SLIP_COLOUR = "#E69F00"
TWIST_COLOUR = "#CC79A7"
BODY_FILL = "#E4E4E4"
MOVER_FILL = "#B0B0B0"
ROBOT_FILL = "#9FB4CC"  # robot links: a bluish grey, told apart from movers and drawn translucent behind them
EDGE_COLOUR = "#404040"
FIGURES_INSTALL_HINT = 'install matplotlib with pip install "quasistatic[figures]"'

# Fixed, whatever the user's matplotlib settings: the same scene gives the same picture (the reference test relies on it).
_RC: dict[str, Any] = {
    "figure.dpi": 100,
    "savefig.dpi": 100,
    "font.family": "DejaVu Sans",
    "font.size": 9,
    "axes.titlesize": 9,
    "legend.fontsize": 8,
    "svg.hashsalt": "quasistatic",
    "path.simplify": False,
}
_TITLE_WIDTH = 90


def require_matplotlib() -> None:
    """Raise :class:`BackendUnavailableError` with the install line when matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError as exc:
        raise BackendUnavailableError("matplotlib", FIGURES_INSTALL_HINT, needed_for="pictures") from exc


@contextmanager
def styled() -> Iterator[None]:
    """matplotlib's default style plus ours, for the drawing inside (artists read the style when created)."""
    import matplotlib.style

    with matplotlib.style.context(["default", _RC]):
        yield


def save(figure: Figure, path: str | os.PathLike[str]) -> None:
    """Write a figure in the format its extension names (png, svg, pdf...), in the fixed style (dpi, svg ids)."""
    with styled():
        figure.savefig(path)


def headline(solution: Any) -> str:
    """The status and message of a Solution, the status said once (most messages start with it)."""
    status, message = str(solution.status), str(solution.message)
    return message if message.startswith(status) else f"{status}: {message}"


def wrapped(text: str, width: int = _TITLE_WIDTH) -> str:
    """``text`` broken into lines of at most ``width`` characters, for titles."""
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text
