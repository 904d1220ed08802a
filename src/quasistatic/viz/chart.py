"""The picture of a Solution without its scene: each contact's normal force, coloured by its mode.

A Solution holds no geometry (points, normals, shapes live in the Scene), so
this is what a notebook shows for a bare Solution (``Solution._repr_png_``)
and what :func:`quasistatic.viz.plot` draws when given no scene. It imports
nothing of the package but the style, so that ``solution.py`` may call it.
"""

from __future__ import annotations

import base64
import html
import io
from typing import TYPE_CHECKING, Any

from ..errors import BackendUnavailableError
from .style import MODE_COLOURS, headline, require_matplotlib, styled, wrapped

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["draw_summary", "summary_figure", "summary_html", "summary_png"]

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


def summary_html(solution: Any) -> str:
    """A notebook's view of a Solution: the verdict and whether it is proven, a table of the reported motion's
    contacts (mode in its colour, normal force, slip), each body's twist, and the bar chart when matplotlib is there."""
    parts = [f"<p><b>{html.escape(headline(solution))}</b></p>", f"<p>{html.escape(_proof_line(solution))}</p>"]
    if solution.motion is not None:
        parts += [_twists_table(solution), _contacts_table(solution)]
    png = summary_png(solution)
    if png is not None:
        parts.append(f'<img alt="normal force per contact" src="data:image/png;base64,{base64.b64encode(png).decode()}"/>')
    return '<div class="quasistatic-solution">' + "".join(parts) + "</div>"


def _proof_line(solution: Any) -> str:
    count = len(solution.solutions)
    shown = f"motion 1 of {count} shown; " if count > 1 else ""
    if solution.motion is None:
        return f"{shown}no motion; {'proven' if solution.certified else 'not proven'}"
    audit = "passed" if solution.motion.audit.passed else "FAILED"
    proof = "proven" if solution.certified else "not proven (the motion may not be unique)"
    return f"{shown}{proof}; audit of the laws: {audit}"


def _twists_table(solution: Any) -> str:
    rows = "".join(
        f"<tr><td>{html.escape(name)}</td><td>{html.escape(_numbers(twist))}</td></tr>" for name, twist in solution.motion.twists.items()
    )
    return f"<table><tr><th>body</th><th>twist (v, w)</th></tr>{rows}</table>"


def _contacts_table(solution: Any) -> str:
    header = "<tr><th>#</th><th>body</th><th>other</th><th>mode</th><th>normal force</th><th>slip</th></tr>"
    rows = "".join(
        f"<tr><td>{index}</td><td>{html.escape(c.body)}</td><td>{html.escape(c.other)}</td>"
        f'<td><span style="color:{MODE_COLOURS[c.mode]}">&#9679;</span> {c.mode}</td>'
        f"<td>{_force_text(c)}</td><td>{html.escape(_numbers(c.slip)) if c.mode == 'sliding' else ''}</td></tr>"
        for index, c in enumerate(solution.contacts)
    )
    return f"<table>{header}{rows}</table>"


def _force_text(contact: Any) -> str:
    """The normal force, and its range when the forces are indeterminate (an open range: no upper bound)."""
    text = f"{contact.normal_force:.4g}"
    if contact.normal_force_range is not None:
        low, high = contact.normal_force_range
        text += f" (range {low:.4g} to {'unbounded' if high is None else f'{high:.4g}'})"
    return text


def _numbers(values: Any) -> str:
    return "[" + ", ".join(f"{float(v):.4g}" for v in values) + "]"


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
