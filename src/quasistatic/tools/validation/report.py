"""The results table and the one-line text descriptions of expectations, solutions and motions."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table
from rich.text import Text

import quasistatic as qs

from .cases import Case, CaseResult
from .scenes import to_spatial

_STYLES = {"pass": "bold green", "known": "bold yellow", "FAIL": "bold red", "FIXED": "bold red"}
_SUMMARY_LABELS = {"known": "known disagreements (docs/validation.md)", "FAIL": "failed", "FIXED": "documented to fail but passed"}


def render_results(results: Sequence[CaseResult], console: Console | None = None) -> None:
    """Print the table: case, source, expected, got, verdict and time, then a summary line.

    Parameters
    ----------
    results : sequence of CaseResult
    console : Console, optional
        Where to print; a new ``rich`` console on stdout by default.
    """
    console = console or Console()
    table = Table(title="quasistatic validation", show_lines=False)
    table.add_column("case", no_wrap=True)
    table.add_column("source")
    table.add_column("expected")
    table.add_column("got")
    table.add_column("result", no_wrap=True)
    table.add_column("time", justify="right", no_wrap=True)
    for r in results:
        table.add_row(r.case.id, r.case.ref, r.expected, _got(r), Text(r.verdict, style=_STYLES[r.verdict]), f"{r.seconds:.2f} s")
    console.print(table)
    console.print(_summary(results))


def _got(r: CaseResult) -> Text:
    """The table's ``got`` cell: the summary, with the failures or the documented reason under it."""
    if r.verdict == "known":
        return Text(r.got + "\nknown: " + str(r.case.known), style="yellow")
    return Text(r.got) if r.passed else Text(r.got + "\n" + "\n".join(r.failures), style="red")


def _summary(results: Sequence[CaseResult]) -> Text:
    """The line under the table: how many passed in what time, then the ids of the other verdicts."""
    total = sum(r.seconds for r in results)
    passed = sum(r.verdict == "pass" for r in results)
    parts = [f"{passed} of {len(results)} cases passed in {total:.1f} s"]
    for verdict, label in _SUMMARY_LABELS.items():
        ids = [r.case.id for r in results if r.verdict == verdict]
        if ids:
            parts.append(f"{label}: {', '.join(ids)}")
    return Text("; ".join(parts), style="green" if all(r.ok for r in results) else "red")


def describe_expectation(case: Case) -> str:
    """One line of what a case expects, for the table's ``expected`` column."""
    e = case.expect
    if case.check == "bisect":
        return f"threshold {e['threshold']:g} +- {case.tolerance['threshold']:g}"
    if case.check == "whitney-grid":
        return "every point on the side of Whitney's line it is on"
    prescribed = f" ({', '.join(m or 'free' for m in case.modes)} prescribed)" if case.modes else ""
    parts = [e["status"] + prescribed]
    parts += [_twist_text(name, to_spatial(t) if case.depth else t) for name, t in e.get("twists", {}).items()]
    if "modes" in e:
        parts.append(_mode_text(e["modes"]))
    if "normal_forces" in e:
        parts.append(f"N {format_vector(e['normal_forces'])}")
    if "normal_force_ranges" in e and case.depth is None:
        parts.append(f"N in {format_ranges(e['normal_force_ranges'])}")
    for kind in e.get("solutions", []):
        parts.append(f"lists {describe_kind(kind)}")
    return "; ".join(parts)


def describe_solution(solution: qs.Solution, groups: list[list[int]]) -> str:
    """One line of a solution, for the table's ``got`` column.

    Parameters
    ----------
    solution : Solution
    groups : list of list of int
        Indices of the contacts that stand for each planar contact (a pair when extruded).
    """
    if solution.motion is None:
        return solution.status
    if solution.status == "ambiguous":
        kinds = "; ".join(f"({describe_motion(m, groups)})" for m in solution.solutions)
        return f"ambiguous, {len(solution.solutions)} listed: {kinds}"
    ranges = solution.forces_indeterminate and len(groups[0]) == 1
    text = f"{solution.status}; {describe_motion(solution.motion, groups, forces=not ranges)}"
    if ranges:
        text += f"; N in {format_ranges([c.normal_force_range for c in solution.contacts])}"
    return text


def describe_motion(motion: qs.Motion, groups: list[list[int]], forces: bool = True) -> str:
    """Twists, modes, normal forces (summed over each group, unless ``forces`` is false) and continuum flags of a motion."""
    parts = [_twist_text(name, t) for name, t in motion.twists.items()]
    parts.append(format_modes(motion, groups))
    if forces:
        parts.append(f"N {format_vector([sum(motion.contacts[j].normal_force for j in group) for group in groups])}")
    if motion.continuum:
        parts.append("continuum, unbounded" if motion.unbounded else "continuum")
    return "; ".join(parts)


def describe_kind(kind: Mapping[str, Any]) -> str:
    """The kind of motion an ``ambiguous`` case expects listed, in parentheses."""
    parts = [_mode_text(kind["modes"])] if "modes" in kind else []
    if "twists" in kind:
        parts += [_twist_text(name, t) for name, t in kind["twists"].items()]
    if "normal_forces" in kind:
        parts.append(f"N {format_vector(kind['normal_forces'])}")
    if "min_normal_forces" in kind:
        parts.append(f"N >= {format_vector(kind['min_normal_forces'])}")
    if kind.get("continuum"):
        parts.append("continuum")
    return "(" + "; ".join(parts) + ")"


def format_modes(motion: qs.Motion, groups: list[list[int]]) -> str:
    """The modes of a motion, one per group (``a/b`` when a group's contacts differ)."""
    return _mode_text(["/".join(sorted({motion.modes[j] for j in group})) for group in groups])


def format_vector(values: Sequence[float] | np.ndarray) -> str:
    """``[a, b, ...]`` with six significant digits and no negative zero."""
    return "[" + ", ".join(_number(x) for x in np.asarray(values, dtype=float).ravel()) + "]"


def format_ranges(ranges: Sequence[Sequence[float | None] | None]) -> str:
    """Normal force ranges as ``[lo, hi]``, ``inf`` for no upper bound and ``?`` for an unknown range."""
    shown = []
    for r in ranges:
        if r is None:
            shown.append("?")
            continue
        lo, hi = r
        shown.append(f"[{_number(lo)}, {'inf' if hi is None else _number(hi)}]")  # type: ignore[arg-type]
    return ", ".join(shown)


def _twist_text(name: str, twist: Sequence[float] | np.ndarray) -> str:
    """``name at rest`` or ``v name [..]``."""
    return f"{name} at rest" if not np.any(np.asarray(twist, dtype=float)) else f"v {name} {format_vector(twist)}"


def _mode_text(modes: Sequence[str]) -> str:
    """Modes separated by commas, or ``n x mode`` when they are all the same."""
    if len(modes) > 1 and len(set(modes)) == 1:
        return f"{len(modes)} x {modes[0]}"
    return ", ".join(modes)


def _number(x: float) -> str:
    """Six significant digits, ``0`` for zero of either sign."""
    text = f"{float(x):.6g}"
    return "0" if float(text) == 0.0 else text
