"""Terminal report of a Solution: rich tables, no physics.

Everything here only formats what a :class:`~quasistatic.solution.Solution`
already holds; numbers are shown in the scene's own units.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from .model import Contact
from .solution import Bounds, Certificate, CertificateKind, CompliantStep, Motion, MoverWrench, RobotLoad, Solution
from .tolerances import DISPLAY_ZERO

if TYPE_CHECKING:
    from .sim import Trajectory

__all__ = ["render_solution", "render_contacts", "make_console", "format_float", "format_vector"]

_STATUS_STYLE = {
    "solved": "bold green",
    "ambiguous": "bold yellow",
    "jammed": "bold magenta",
    "unstable": "bold magenta",
    "failed": "bold red",
}
_MODE_STYLE = {"rolling": "green", "sliding": "yellow", "separating": "cyan"}
_PIPE_WIDTH = 120


def format_float(value: float, scale: float = 0.0) -> str:
    """Compact text for one number (``{:.6g}``), never ``-0``.

    Values within ``1e-12 * scale`` of zero (solver round-off next to the
    column's largest entry) are shown as ``0``.
    """
    value = float(value)
    if abs(value) <= DISPLAY_ZERO * scale:
        value = 0.0
    text = f"{value:.6g}"
    if text.startswith("-") and float(text) == 0.0:
        return text[1:]
    return text


def format_vector(values: Sequence[float] | np.ndarray, scale: float | None = None) -> str:
    """``[a, b, c]``; entries within ``1e-12 * scale`` of zero shown as 0 (scale: the largest entry by default)."""
    array = np.asarray(values, dtype=float).ravel()
    if scale is None:
        scale = float(np.max(np.abs(array), initial=0.0))
    return "[" + ", ".join(format_float(x, scale) for x in array) + "]"


def make_console() -> Console:
    """A console on stdout; 120 columns when it is not a terminal (a pipe, a file) unless ``COLUMNS`` is set."""
    console = Console()
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(width=_PIPE_WIDTH)
    return console


def render_solution(solution: Solution, console: Console) -> None:
    """Print a solution: status, method, twists, contacts, power balance and audit.

    Parameters
    ----------
    solution : Solution
        What :func:`quasistatic.solve` returned.
    console : rich.console.Console
        Where to print.
    """
    status = Text(solution.status, style=_STATUS_STYLE.get(solution.status, "bold"))
    console.print(Text.assemble("status: ", status))
    console.print(Text(solution.message))
    console.print(Text(f"method: {solution.method}   friction model: {solution.friction}   {_proof(solution)}"))
    console.print(Text("units: those of the scene file (forces, lengths and times as given there)"))
    if solution.compliant_forces:
        console.print(Text("forces: compliant (of the forces the rigid motion allows, the least elastic energy; unique and audited)"))
    if solution.certificate is not None:
        console.print(Text(f"certificate: {solution.certificate.text}"))
        explanation = _explain(solution.certificate)
        if explanation:
            console.print(Text(explanation))
    if solution.compliant_step is not None:
        _render_step(solution.compliant_step, console)
    motion = solution.motion
    if motion is None:
        return
    ambiguous = solution.status == "ambiguous" and bool(solution.solutions)
    if ambiguous:
        _render_solutions(solution.solutions, console)
    suffix = " (motion 1)" if ambiguous else ""
    tables = [
        _twist_table(motion.twists, f"body twists{suffix}"),
        _contact_table(motion, solution.forces_indeterminate, f"contacts{suffix}"),
    ]
    if motion.robot_loads:
        tables.append(_torque_table(motion.robot_loads, f"robot joint torques{suffix}"))
    if motion.mover_wrenches:
        tables.append(_wrench_table(motion.mover_wrenches, f"mover wrenches{suffix}"))
    for table in (*tables, _power_table(motion), _audit_table(motion)):
        console.print()
        console.print(table)
    # On exact 3-D cones the force set searched is the inscribed pyramid's: a verdict, not a proof.
    spatial = any(np.asarray(t).size == 6 for t in motion.twists.values())
    caveat = " (forces of the inscribed 8-edge pyramid; not proven for the exact cones)" if spatial and solution.friction == "exact" else ""
    for robot, joints in motion.torque_limits_exceeded.items():
        console.print(
            Text(
                f"infeasible for robot {robot}: no consistent force distribution keeps {', '.join(joints)} within the torque limits"
                + caveat
            )
        )


def render_contacts(contacts: Sequence[Contact], gaps: Sequence[float], notes: Sequence[str], console: Console) -> None:
    """Print detected contacts: the pair, the point, the normal into the body, the gap, mu, and whose Jacobian."""
    table = _table(f"{len(contacts)} contacts found")
    table.caption = "normal: into body; gap: > 0 apart, < 0 overlapping (scene units)"
    table.caption_justify = "left"
    for name in ("#", "body", "other", "point", "normal", "gap", "mu", "jacobian"):
        table.add_column(name, justify="right" if name in ("#", "gap", "mu") else "left", overflow="fold")
    length = max((float(np.max(np.abs(c.point), initial=0.0)) for c in contacts), default=0.0)
    for index, (contact, gap) in enumerate(zip(contacts, gaps, strict=False)):
        joints = "" if contact.jacobian is None else f"{contact.jacobian.shape[1]} joints"
        row: list[str | Text] = [str(index), Text(contact.body), Text(contact.other), format_vector(contact.point, length)]
        table.add_row(*row, format_vector(contact.normal, 1.0), format_float(gap, length), format_float(contact.mu), joints)
    console.print(table)
    for line in notes:
        console.print(Text(line))


def _explain(certificate: Certificate) -> str:
    """What a certificate says a person should look at: the blocking contacts, or the direction of the fall."""
    if certificate.kind is CertificateKind.FARKAS:
        weights = np.asarray(certificate.data)
        blocking = np.flatnonzero(weights > 1e-9 * max(float(weights.max(initial=0.0)), 1e-300))
        listed = ", ".join(f"#{i}" for i in blocking)
        return f"blocking contacts: {listed} (the commanded motion would push the movers into the bodies there)"
    if certificate.kind is CertificateKind.RAY:
        return f"it falls or accelerates along the twist (v, ω of each body, largest entry 1): {format_vector(certificate.data)}"
    if certificate.kind is CertificateKind.INFEASIBLE_EQUILIBRIUM and certificate.data:
        twist = format_vector(certificate.data)
        return f"the load does work along the twist (v, ω of each body, largest entry 1) {twist}, which no force in the cones resists"
    return ""


def _proof(solution: Solution) -> str:
    """Whether the answer is proven, in words: an unproven answer says so in every output."""
    if solution.status == "failed":
        return "proof: none (failed)"
    if solution.certified:
        return "proof: certified"
    if solution.friction == "exact" and solution.search_complete is False and solution.status in ("solved", "ambiguous"):
        return "proof: NOT certified (complete for the inscribed pyramid, not proven for the exact cones; see the message)"
    return "proof: NOT certified (a motion found, not proven the only one; solve with certify=True)"


def _twist_table(twists: Mapping[str, np.ndarray], title: str) -> Table:
    table = _table(title)
    table.add_column("body")
    table.add_column("v (velocity of com)", justify="right")
    table.add_column("ω (angular velocity)", justify="right")
    for name, twist in twists.items():
        linear, angular = _split_twist(twist)
        spin = format_float(angular[0]) if angular.size == 1 else format_vector(angular)
        table.add_row(Text(name), format_vector(linear), spin)
    return table


def _table(title: str | Text) -> Table:
    return Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False)


def _split_twist(twist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    twist = np.asarray(twist, dtype=float)
    linear = 2 if twist.size == 3 else 3
    return twist[:linear], twist[linear:]


def _contact_table(motion: Motion, with_ranges: bool, title: str) -> Table:
    table = _table(title)
    table.caption = "f_n: normal force on body; force: on body; slip, u_n: velocity of body relative to other"
    table.caption_justify = "left"
    for name, justify in (
        ("#", "right"),
        ("body", "left"),
        ("other", "left"),
        ("mode", "left"),
        ("f_n", "right"),
        ("force", "right"),
        ("slip", "right"),
        ("u_n", "right"),
    ):
        table.add_column(name, justify=justify, overflow="fold")  # type: ignore[arg-type]
    boxes = motion.force_ranges if with_ranges else None
    if with_ranges:
        table.add_column("f_n range", justify="right")
    if boxes is not None and any(box is not None for box in boxes):
        table.add_column("force range", justify="right")
    contacts = motion.contacts
    force_scale = max((float(np.max(np.abs(c.force), initial=0.0)) for c in contacts), default=0.0)
    speed_scale = max((max(float(np.max(np.abs(c.slip), initial=0.0)), abs(c.normal_velocity)) for c in contacts), default=0.0)
    for index, contact in enumerate(contacts):
        row: list[str | Text] = [
            str(index),
            Text(contact.body),
            Text(contact.other),
            Text(contact.mode, style=_MODE_STYLE.get(contact.mode, "")),
            format_float(contact.normal_force, force_scale),
            format_vector(contact.force, force_scale),
            format_vector(contact.slip, speed_scale),
            format_float(contact.normal_velocity, speed_scale),
        ]
        if with_ranges:
            row.append(_format_range(contact.normal_force_range))
        if boxes is not None and any(box is not None for box in boxes):
            row.append(_format_box(boxes[index]))
        table.add_row(*row)
    return table


def _format_box(bounds: tuple[Bounds, ...] | None) -> str:
    """A force's component ranges, ``x [lo, hi] y [lo, hi]`` (``-`` for a frictionless contact)."""
    if bounds is None:
        return "-"
    ends = ["-inf" if lo is None else format_float(lo) for lo, _ in bounds], ["inf" if hi is None else format_float(hi) for _, hi in bounds]
    return " ".join(f"{axis} [{lo}, {hi}]" for axis, lo, hi in zip("xyz", *ends, strict=False))


def _format_range(bounds: tuple[float, float | None] | None) -> str:
    if bounds is None:
        return "-"
    lo, hi = bounds
    return f"[{format_float(lo)}, inf)" if hi is None else f"[{format_float(lo)}, {format_float(hi)}]"


def _torque_table(loads: Sequence[RobotLoad], title: str) -> Table:
    table = _table(title)
    table.caption = "J^T f: what each joint supplies"
    table.caption_justify = "left"
    with_ranges = any(load.torque_ranges is not None for load in loads)
    with_limits = any(load.torque_limits is not None for load in loads)
    columns = ["robot", "joint", "torque", *(["range"] if with_ranges else []), *(["limit"] if with_limits else [])]
    for name in columns:
        table.add_column(name, justify="left" if name in ("robot", "joint") else "right", overflow="fold")
    for load in loads:
        scale = float(np.max(np.abs(load.torques), initial=0.0))
        for j, joint in enumerate(load.joints):
            row: list[str | Text] = [Text(load.robot), Text(joint), format_float(load.torques[j], scale)]
            if with_ranges:
                row.append(_format_bounds(None if load.torque_ranges is None else load.torque_ranges[j]))
            if with_limits:
                over = joint in load.limits_exceeded
                limit = "-" if load.torque_limits is None else format_float(load.torque_limits[j])
                row.append(Text(f"{limit} EXCEEDED" if over else limit, style="bold red" if over else ""))
            table.add_row(*row)
    return table


def _wrench_table(wrenches: Sequence[MoverWrench], title: str) -> Table:
    table = _table(title)
    table.caption = "applied to the bodies; moment about origin"
    table.caption_justify = "left"
    with_ranges = any(w.ranges is not None for w in wrenches)
    for name in ("mover", "origin", "force", "moment", *(["ranges (force, moment)"] if with_ranges else [])):
        table.add_column(name, justify="left" if name == "mover" else "right", overflow="fold")
    for wrench in wrenches:
        moment = format_float(wrench.moment[0]) if wrench.moment.size == 1 else format_vector(wrench.moment)
        row: list[str | Text] = [Text(wrench.mover), format_vector(wrench.origin), format_vector(wrench.force), moment]
        if with_ranges:
            row.append("-" if wrench.ranges is None else ", ".join(_format_bounds(b) for b in wrench.ranges))
        table.add_row(*row)
    return table


def _format_bounds(bounds: Bounds | None) -> str:
    if bounds is None:
        return "-"
    lo, hi = bounds
    return f"{'(-inf' if lo is None else '[' + format_float(lo)}, {'inf)' if hi is None else format_float(hi) + ']'}"


def _render_step(step: CompliantStep, console: Console) -> None:
    """The compliant step: its verdict, each contact's force and state, each body's displacement, its audit."""
    verdict = Text("valid", style="green") if step.valid else Text("NOT AN ANSWER", style="bold red")
    table = _table(Text.assemble(f"compliant step ({step.closing_time:g}): ", verdict))
    for name in ("#", "state", "f_n", "force"):
        table.add_column(name, justify="left" if name == "state" else "right")
    scale = float(np.max(np.abs(step.forces), initial=0.0))
    for index, (force, normal, state) in enumerate(zip(step.forces, step.normal_forces, step.states, strict=True)):
        table.add_row(str(index), state, format_float(normal, scale), format_vector(force, scale))
    audit = step.audit
    residuals = (
        f"equilibrium {format_float(audit.equilibrium)}, cone {format_float(audit.cone)}, compatibility {format_float(audit.compatibility)}"
    )
    console.print()
    console.print(table)
    console.print(Text(f"step audit (scene-relative, tolerance {format_float(audit.tolerance)}): {'passed' if audit.passed else 'FAILED'}"))
    console.print(Text(f"  residuals: {residuals}"))
    for name, displacement in step.displacements.items():
        console.print(Text(f"{name} displacement (com, then rotation): {format_vector(displacement)}"))


def _power_table(motion: Motion) -> Table:
    table = _table("power balance")
    for name in ("input", "gravity", "dissipation", "residual"):
        table.add_column(name, justify="right")
    power = motion.power
    scale = max(abs(power.input), abs(power.gravity), abs(power.dissipation))
    table.add_row(*(format_float(x, scale) for x in (power.input, power.gravity, power.dissipation, power.residual)))
    return table


def _audit_table(motion: Motion) -> Table:
    audit = motion.audit
    verdict = Text("passed", style="green") if audit.passed else Text("FAILED", style="bold red")
    title = Text.assemble("audit (scene-relative residuals, tolerance ", format_float(audit.tolerance), "): ", verdict)
    table = _table(title)
    residuals = audit.residuals()
    failures = set(audit.failures())
    for name in residuals:
        table.add_column(name, justify="right")
    table.add_row(*(Text(format_float(v), style="bold red" if k in failures else "") for k, v in residuals.items()))
    return table


def _render_solutions(motions: Sequence[Motion], console: Console) -> None:
    console.print()
    console.print(Text(f"motions that satisfy the laws: {len(motions)} listed (a continuum of motions is one entry)"))
    for number, motion in enumerate(motions, start=1):
        modes = ", ".join(motion.modes)
        kind = ""
        if motion.continuum:
            free = ", ".join(motion.free_directions)
            kind = f" continuum (unbounded: {free})" if motion.unbounded else " continuum (bounded)"
        console.print(Text(f"  motion {number}:{kind} modes [{modes}]"))
        for name, twist in motion.twists.items():
            console.print(Text(f"    {name}: twist {format_vector(twist)}"))
        if motion.forces_indeterminate:
            ranges = ", ".join(_format_range(c.normal_force_range) for c in motion.contacts)
            console.print(Text(f"    forces indeterminate; normal-force ranges: {ranges}"))
        for load in motion.robot_loads:
            exceeded = f" (torque limits exceeded: {', '.join(load.limits_exceeded)})" if load.limits_exceeded else ""
            console.print(Text(f"    {load.robot} joint torques: {format_vector(load.torques)}{exceeded}"))
        if motion.continuum and motion.extreme_twists:
            console.print(Text("    extreme twists (each audited with forces found at it):"))
            for extreme in motion.extreme_twists:
                text = "; ".join(f"{name} {format_vector(t)}" for name, t in extreme.items())
                console.print(Text(f"      {text}"))
        if motion.unproven_extremes:
            count = len(motion.unproven_extremes)
            console.print(Text(f"    {count} more extreme twist{'s' if count > 1 else ''} failed the audit: not motions, not listed"))


def render_trajectory(trajectory: Trajectory, console: Console, saved: str = "") -> None:
    """A run's ending, its proof, the deepest penetration and a table of its events."""
    steps = trajectory.steps
    taken = sum(1 for s in steps if s.dt > 0)
    console.print(Text(f"{trajectory.status}: {trajectory.message}", style="bold"))
    proof = (
        "every step certified"
        if trajectory.certified
        else f"NOT certified: {sum(not s.certified for s in steps)} of {len(steps)} answers unproven"
    )
    console.print(Text(f"{taken} steps to t = {trajectory.final.time:.6g} s; proof: {proof}"))
    choices = sum(1 for s in steps if s.choice)
    if choices:
        console.print(Text(f"{choices} steps chose one motion among several (ambiguous answers; see the events)"))
    console.print(Text(f"deepest penetration before correction: {format_float(trajectory.max_penetration)} (length units of the scene)"))
    table = _table("events")
    for column in ("time", "event", "between", "what"):
        table.add_column(column)
    for event in trajectory.events:
        between = " / ".join(event.pair) if event.pair[0] else "scene"
        table.add_row(f"{event.time:.6g}", event.kind, between, event.detail)
    if trajectory.events:
        console.print(table)
    else:
        console.print(Text("no events: the contacts and their modes stayed the same"))
    if saved:
        console.print(Text(f"wrote {saved}"))
