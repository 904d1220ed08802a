"""The run: steps from a scene for a duration, with events located in time and the reason a run ends."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..adapters import AnyWorld, PlanarWorld, World
from ..errors import SceneError
from ..loading import load_world
from ..model import Scene
from ..solution import CertificateKind, Diagnosis
from ..tolerances import SIM_EVENT_TIME, ZERO
from ..wedging import wedging_friction
from .state import InputSource, InputTable, State, inputs_at
from .step import AmbiguityPolicy, Evaluation, Event, SimModel, StepOptions, StepResult, advance, evaluate, moving, safe_step
from .trajectory import RunStatus, Trajectory

__all__ = ["simulate", "Signature", "signature", "events_between", "UNDECIDED_MESSAGES"]

UNDECIDED_MESSAGES = 1000
"""Most recorded steps whose message (its claim about the forces) is left to be worked out when read: each keeps
its solve's Problem until then (about 10 KiB on the planar push), so an older step's message is worked out as the
run goes on, and a run of any length holds at most this many."""

Signature = tuple[str, tuple[tuple[tuple[str, str], tuple[str, ...]], ...]]
"""What an event changes: the status, and per touching pair the set of its contacts' modes."""


def simulate(
    scene: AnyWorld | Scene | str | Path | dict[str, Any],
    duration: float,
    dt: float = 0.01,
    inputs: InputSource = None,
    *,
    ambiguous: AmbiguityPolicy = "stop",
    method: str = "auto",
    certify: bool = True,
    event_tolerance: float | None = None,
    max_steps: int = 100_000,
    progress: Callable[[float, float], None] | None = None,
    reuse: bool = True,
) -> Trajectory:
    """Follow the quasi-static motion of a scene of shapes for ``duration`` seconds.

    Parameters
    ----------
    scene : World, or a scene file (path or dict) with shapes or URDF robots
        Contacts are found again at every step, so listed ``contacts:`` are refused.
    duration, dt : float
        Length of the run and the largest step [s]. A step is shortened where a surface closes in
        (so thin parts cannot be passed through) and bisected where an event happens.
    inputs : Inputs, InputTable, function (time, state) -> Inputs, or None
        Joint velocities and mover twists over time; None keeps the scene's own.
    ambiguous : "stop" or "min_power"
        At an ambiguous answer, end the run (default), or go on with the motion of least input
        power and record the choice in that step.
    method, certify : passed to :func:`quasistatic.solve` at every step.
    event_tolerance : float, optional
        Width of the time window that locates an event [s]; ``dt`` times :data:`SIM_EVENT_TIME` by default.
    progress : function (time, duration), optional
        Called after every step.
    reuse : bool
        True (default): a step whose scene-relative laws equal the previous solve's bit for bit takes its
        certified answer again, audited anew (:class:`~quasistatic.sim.StepOptions`); False proves every step
        anew. The run is the same either way.

    Returns
    -------
    Trajectory
        Ends ``completed``, or with the status that stopped it (``jammed``, ``unstable``, ``ambiguous``,
        ``failed``) and its message; ``max_steps`` if the step limit was reached first.
    """
    world = _world(scene)
    _check_run(duration, dt, event_tolerance, max_steps)
    model = SimModel(world, StepOptions(dt, ambiguous, method, certify, reuse=reuse))
    tolerance = dt * SIM_EVENT_TIME if event_tolerance is None else event_tolerance
    state = State.of(world)
    current = evaluate(model, state, inputs_at(inputs, state))
    states: list[State] = []
    steps: list[StepResult] = []
    pending: tuple[Event, ...] = _status_events(None, current, (0.0, 0.0))
    while moving(current) and current.state.time < duration * (1 - 1e-12) and len(steps) < max_steps:
        h = _step_length(current, dt, duration, inputs)
        taken, following, located = _located(model, inputs, current, h, tolerance)
        states.append(current.state)
        steps.append(StepResult.of(current, taken, pending))
        if len(steps) > UNDECIDED_MESSAGES:
            _ = steps[-UNDECIDED_MESSAGES - 1].message  # worked out now, so its Problem is let go
        pending = located
        current = following
        if progress is not None:
            progress(current.state.time, duration)
    states.append(current.state)
    steps.append(StepResult.of(current, 0.0, pending))
    status, message = _ending(current, duration, len(steps) > max_steps)
    scene_file = str(Path(scene).resolve()) if isinstance(scene, str | Path) else ""
    return Trajectory(tuple(states), tuple(steps), status, message, scene_file)


def _world(scene: AnyWorld | Scene | str | Path | dict[str, Any]) -> AnyWorld:
    world = load_world(scene) if isinstance(scene, str | Path | dict) else scene
    if not isinstance(world, World | PlanarWorld):
        raise SceneError(
            "bodies", "listed contacts", "a simulation needs a scene of shapes or URDF robots, whose contacts it finds again at every step"
        )
    return world


def _check_run(duration: float, dt: float, event_tolerance: float | None, max_steps: int) -> None:
    if not (math.isfinite(duration) and duration > 0):
        raise SceneError("duration", duration, "must be a positive number of seconds")
    if event_tolerance is not None and not (math.isfinite(event_tolerance) and event_tolerance > 0):
        raise SceneError("event_tolerance", event_tolerance, "must be a positive number of seconds")
    if max_steps < 1:
        raise SceneError("max_steps", max_steps, "must be at least 1")
    # Steps are never longer than dt, so such a run could only end at the step limit, minutes and
    # gigabytes later; refused at once instead (dt itself is checked by StepOptions).
    if math.isfinite(dt) and dt > 0 and duration * (1 - 1e-12) / dt > max_steps:
        raise SceneError(
            "duration",
            duration,
            f"needs more than max_steps = {max_steps} steps of dt = {dt:g} s; shorten the run or lengthen dt",
        )


def _step_length(current: Evaluation, dt: float, duration: float, inputs: InputSource) -> float:
    """The step: ``dt``, shortened to end the run on time, at a change of tabled inputs, and by :func:`safe_step`."""
    time = current.state.time
    h = min(dt, duration - time)
    if isinstance(inputs, InputTable):
        change = inputs.changes_after(time)
        if change is not None:
            h = min(h, change - time)
    return safe_step(current, h)


def _located(
    model: SimModel, inputs: InputSource, current: Evaluation, h: float, tolerance: float
) -> tuple[float, Evaluation, tuple[Event, ...]]:
    """Step ``h``; where that changes the signature, bisect until the change lies within ``tolerance``.

    Returns the step taken, the evaluation at its end, and the events found in it.
    """
    following = _evaluated(model, inputs, current, h)
    before = signature(current)
    if signature(following) == before:
        return h, following, ()
    low, high = 0.0, h
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        trial = _evaluated(model, inputs, current, middle)
        if signature(trial) == before:
            low = middle
        else:
            high, following = middle, trial
    start = current.state.time
    return high, following, events_between(current, following, (start + low, start + high))


def _evaluated(model: SimModel, inputs: InputSource, current: Evaluation, h: float) -> Evaluation:
    state = advance(current, h)
    return evaluate(model, state, inputs_at(inputs, state))


def signature(evaluation: Evaluation) -> Signature:
    modes: dict[tuple[str, str], set[str]] = {}
    for record in evaluation.contact_records():
        modes.setdefault((record.body, record.other), set()).add(record.mode or "")
    return evaluation.status, tuple(sorted((pair, tuple(sorted(m))) for pair, m in modes.items()))


def events_between(before: Evaluation, after: Evaluation, window: tuple[float, float]) -> tuple[Event, ...]:
    """What changed from ``before`` to ``after``: contacts made and broken, modes changed, the status."""
    time = window[1]
    old, new = dict(signature(before)[1]), dict(signature(after)[1])
    events = [
        Event(time, "contact made", pair, f"{pair[0]} touches {pair[1]}" + _modes_text(new[pair]), window)
        for pair in new
        if pair not in old
    ]
    events += [Event(time, "contact broken", pair, f"{pair[0]} leaves {pair[1]}", window) for pair in old if pair not in new]
    if moving(before) and moving(after):  # modes exist only where there is a motion
        events += [
            Event(time, "mode change", pair, f"{pair[0]} on {pair[1]}: {', '.join(old[pair])} -> {', '.join(new[pair])}", window)
            for pair in new
            if pair in old and old[pair] != new[pair]
        ]
    return tuple(events) + _status_events(before, after, window)


def _status_events(before: Evaluation | None, after: Evaluation, window: tuple[float, float]) -> tuple[Event, ...]:
    """An event when the status becomes one other than ``solved``, or a choice among motions is made."""
    if after.status == "solved" or (before is not None and before.status == after.status):
        return ()
    detail = after.choice or after.solution.message
    if after.status == "unstable" and before is not None:
        detail += _fall(before)
    if after.status == "jammed":
        detail += _blocking(after)
    return (Event(window[1], after.status, ("", ""), detail, window),)


def _fall(before: Evaluation) -> str:
    """Which bodies fall, and which way: each moving body's last motion, which it goes on with as it falls."""
    parts = []
    for body in before.world.bodies:
        twist = before.twist(body.name)
        if np.any(twist):
            dim = before.world.dimension
            v, w = twist[:dim], twist[dim:]
            turning = f"about {_unit(w)}" if dim == 3 else _sense(float(w[0]))
            parts.append(f"{body.name!r} (its centre of mass was moving along {_unit(v)}, turning {turning})")
    return "; it falls as it last moved: " + ", ".join(parts) if parts else ""


def _modes_text(modes: tuple[str, ...]) -> str:
    shown = [m for m in modes if m]  # "" marks an answer without a motion: no modes
    return f" ({', '.join(shown)})" if shown else ""


def _blocking(evaluation: Evaluation) -> str:
    """The contacts a kinematic jam's certificate (Farkas multipliers, one per contact) puts weight on; for a
    wedged jam, the contacts whose friction wedges it (:mod:`quasistatic.wedging`: a few re-solves, once a run)."""
    certificate = evaluation.solution.certificate
    contacts = evaluation.detection.contacts
    if evaluation.solution.diagnosis is Diagnosis.WEDGED and evaluation.certified:
        found = wedging_friction(evaluation.world.scene(evaluation.detection), evaluation.model.options.time_limit)
        wedging = sorted({f"{contacts[i].body}/{contacts[i].other}" for i in found or ()})
        return f"; friction wedges it at: {', '.join(wedging)}" if wedging else ""
    if certificate is None or certificate.kind is not CertificateKind.FARKAS or len(certificate.data) != len(contacts):
        return ""
    weights = np.asarray(certificate.data)
    blocking = sorted(
        {f"{contacts[i].body}/{contacts[i].other}" for i in np.flatnonzero(weights > ZERO * max(float(weights.max()), 1e-300))}
    )
    return f"; blocking contacts: {', '.join(blocking)}" if blocking else ""


def _sense(w: float) -> str:
    """How a planar body turns."""
    return "counter-clockwise" if w > 0 else "clockwise" if w < 0 else "not at all"


def _unit(vector: np.ndarray) -> str:
    norm = float(np.linalg.norm(vector))
    return "[0, 0, 0]" if norm == 0 else "[" + ", ".join(f"{x:.3f}" for x in vector / norm) + "]"


def _ending(current: Evaluation, duration: float, out_of_steps: bool) -> tuple[RunStatus, str]:
    if not moving(current):
        status: RunStatus = current.status  # type: ignore[assignment]  # jammed, unstable, failed or ambiguous
        return status, f"stopped at t = {current.state.time:.6g} s: {current.solution.message}"
    if current.state.time < duration * (1 - 1e-12):
        return "max_steps", f"stopped at t = {current.state.time:.6g} s after the largest number of steps allowed"
    return "completed", f"ran the whole {duration:.6g} s"
