"""The picture of a Solution without its scene: each contact's normal force, coloured by its mode.

A Solution holds no geometry (points, normals, shapes live in the Scene), so
this is what a notebook shows for a bare Solution (``Solution._repr_png_``)
and what :func:`quasistatic.viz.plot` draws when given no scene. It imports
nothing of the package but the style, so that ``solution.py`` may call it.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from ..errors import BackendUnavailableError
from .style import MODE_COLOURS, headline, require_matplotlib, styled, wrapped

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["draw_summary", "summary_figure", "summary_png"]

_SIZE = (6.4, 3.6)  # inches


def summary_png(solution: Any) -> bytes | None:
    """PNG bytes of :func:`summary_figure`, or None when matplotlib is missing (a notebook then shows the text)."""
    try:
        require_matplotlib()
    except BackendUnavailableError:
        return None
    with styled():
        figure = summary_figure(solution)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png")
    return buffer.getvalue()


def summary_figure(solution: Any, ax: Axes | None = None) -> Figure:
    """A bar per contact of the reported motion: its normal force [force], coloured by mode; the status as the title."""
    from matplotlib.figure import Figure

    if ax is None:
        figure = Figure(figsize=_SIZE, layout="constrained")
        ax = figure.add_subplot()
    draw_summary(ax, solution)
    figure_of = ax.get_figure()
    assert isinstance(figure_of, Figure)  # a subplot's figure, never a subfigure here
    return figure_of


def draw_summary(ax: Axes, solution: Any) -> None:
    """Draw the bars (or, without a motion, the message alone) into ``ax``."""
    ax.set_title(wrapped(headline(solution), 80), loc="left")
    contacts = solution.contacts
    if not contacts:
        ax.text(0.5, 0.5, "no motion: nothing to draw per contact", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    heights = [c.normal_force for c in contacts]
    colours = [MODE_COLOURS[c.mode] for c in contacts]
    ax.bar(range(len(contacts)), heights, color=colours, edgecolor="#404040", linewidth=0.6)
    ax.set_xticks(range(len(contacts)), [f"{c.body}-{c.other}" for c in contacts], rotation=30, ha="right")
    ax.set_ylabel("normal force [N]")
    _mode_legend(ax, [c.mode for c in contacts])
    if len(solution.solutions) > 1:
        ax.text(0.99, 0.98, f"motion 1 of {len(solution.solutions)}", ha="right", va="top", transform=ax.transAxes)


def _mode_legend(ax: Axes, modes: list[str]) -> None:
    from matplotlib.patches import Patch

    present = [mode for mode in MODE_COLOURS if mode in modes]
    ax.legend(handles=[Patch(color=MODE_COLOURS[mode], label=mode) for mode in present], loc="upper left")
