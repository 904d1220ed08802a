"""``phase_diagram``: a sweep's phases (statuses, or statuses and contact modes) over one or two parameters.

It draws a :class:`quasistatic.sweeps.PhaseMap` (read through its attributes,
so this module imports no sweep type): each grid cell coloured by its phase,
and the refinement points, where bisection located the boundaries, as dots
in the colour of their phase.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .style import require_matplotlib, styled, wrapped

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["PhaseMapLike", "STATUS_COLOURS", "phase_diagram"]

STATUS_COLOURS = {"solved": "#0072B2", "ambiguous": "#CC79A7", "jammed": "#D55E00", "unstable": "#E69F00", "failed": "#808080"}
"""Fixed colours of the statuses (Okabe & Ito); phases that also name modes take the palette below in turn."""

_MORE_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#56B4E9", "#CC79A7", "#F0E442", "#000000", "#808080")


class PhaseMapLike(Protocol):
    """What is drawn: ``quasistatic.sweeps.PhaseMap`` (names, grid values, labels, refinement points, kind)."""

    @property
    def names(self) -> tuple[str, ...]: ...
    @property
    def axes(self) -> tuple[np.ndarray, ...]: ...
    @property
    def labels(self) -> np.ndarray: ...
    @property
    def refined(self) -> tuple[tuple[tuple[float, ...], str], ...]: ...
    @property
    def kind(self) -> str: ...


def phase_diagram(phases: PhaseMapLike, ax: Axes | None = None, title: str | None = None) -> Figure:
    """Draw the phase regions of a sweep and return the matplotlib Figure (nothing is shown or saved).

    Parameters
    ----------
    phases : PhaseMap
        ``SweepResult.phase_map()``: one or two parameters.
    ax : matplotlib Axes, optional
        Draw here instead of on a new figure; artists already on it with a label (an analytic
        boundary, say) join the legend.
    title : str, optional
        Default: the parameters and the number of points.

    Raises
    ------
    BackendUnavailableError
        When matplotlib (the ``figures`` extra) is not installed.
    """
    require_matplotlib()
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    with styled():
        if ax is None:
            figure = Figure(figsize=(7.0, 5.5 if len(phases.names) == 2 else 2.8))
            ax = figure.add_subplot()
        else:
            figure = ax.figure  # type: ignore[assignment]
        colours = _colours(phases)
        _cells(ax, phases, colours)
        _refined(ax, phases, colours)
        ax.set_xlabel(phases.names[0])
        if len(phases.names) == 2:
            ax.set_ylabel(phases.names[1])
        else:
            ax.set_yticks([])
        count = phases.labels.size + len(phases.refined)
        ax.set_title(wrapped(title or f"{phases.kind} over {' and '.join(phases.names)}: {count} solves"))
        drawn, _ = ax.get_legend_handles_labels()
        handles = [Patch(facecolor=colour, label=label) for label, colour in colours.items()] + drawn
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
        figure.tight_layout()
    return figure


def _colours(phases: PhaseMapLike) -> dict[str, str]:
    """A fixed colour per phase: the status colours when phases are statuses, else the palette in sorted order."""
    labels = sorted(set(phases.labels.ravel().tolist()) | {label for _, label in phases.refined})
    if all(label in STATUS_COLOURS for label in labels):
        return {label: STATUS_COLOURS[label] for label in labels}
    return {label: _MORE_COLOURS[k % len(_MORE_COLOURS)] for k, label in enumerate(labels)}


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges halfway between grid values (a single value gets a unit-wide cell)."""
    values = np.asarray(values, dtype=float)
    if values.size == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    middle = (values[:-1] + values[1:]) / 2
    return np.concatenate([[2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]])


def _cells(ax: Axes, phases: PhaseMapLike, colours: dict[str, str]) -> None:
    from matplotlib.colors import ListedColormap

    order = list(colours)
    codes = np.vectorize(order.index, otypes=[float])(phases.labels)
    cmap = ListedColormap([colours[label] for label in order])
    x = _edges(phases.axes[0])
    if len(phases.names) == 2:
        y = _edges(phases.axes[1])
        ax.pcolormesh(x, y, codes.T, cmap=cmap, vmin=-0.5, vmax=len(order) - 0.5, alpha=0.55, shading="flat")
    else:
        ax.pcolormesh(x, [0.0, 1.0], codes[np.newaxis, :], cmap=cmap, vmin=-0.5, vmax=len(order) - 0.5, alpha=0.55)


def _refined(ax: Axes, phases: PhaseMapLike, colours: dict[str, str]) -> None:
    """Refinement points as dots in their phase's colour, edged black so they show on any cell."""
    if not phases.refined:
        return
    coords: Sequence[Any] = [values for values, _ in phases.refined]
    xy = np.array([(v[0], v[1]) if len(v) == 2 else (v[0], 0.5) for v in coords])
    ax.scatter(xy[:, 0], xy[:, 1], s=9, c=[colours[label] for _, label in phases.refined], edgecolors="k", linewidths=0.4, zorder=3)
