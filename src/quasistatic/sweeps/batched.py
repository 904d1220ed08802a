"""A chunk's points solved together, where they share one planar shape and the default certified method runs.

Why: a small planar certified solve is ~1 ms of Python calls on arrays of a few entries (the scene at the point,
assembly, Lemke, the vertex certificate, the audit, the Solution). The points of a sweep's chunk differ only in
the swept numbers, so here those numbers are written into stacked arrays (:class:`~quasistatic.model.stacked.PlanarStack`,
no Scene per point), assembled together (:func:`~quasistatic.laws.stacked.assemble_stack`, bit for bit as
``assemble``), decided together (:func:`~quasistatic.solvers.batched.certify_stack`: Lemke's kernel over the stack, then the
vertex certificate and what is known of the forces for all points at once), and audited together on each point's
own numbers (:func:`~quasistatic.check.stacked.audit_stack`). A point the batch does not decide (another swept
path, a value a Scene might reject, an answer other than one proven motion, forces neither test settles, a value
near a threshold, a failed audit) is left to the per-point :func:`~quasistatic.solve`, so the batch never changes an
answer: it decides faster what it can decide exactly. Its records equal the per-point ones (status, message,
twists, forces, modes; tested on random grids).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..check import DEFAULT_TOLERANCE
from ..check.stacked import MODE_CODES, audit_stack
from ..laws.stacked import assemble_stack
from ..model import Scene
from ..model.stacked import PlanarStack, stackable
from ..solvers.batched import certify_stack, solved_message
from ..tolerances import BATCH_CONTACTS, BATCH_POINTS, MAX_FRICTION, MAX_MAGNITUDE, ROUNDOFF
from .result import SweepPoint
from .scenes import PointScenes

__all__ = ["batched_points"]

Task = tuple[int, tuple[float, ...], bool]


def batched_points(scenes: PointScenes, tasks: Sequence[Task], options: Mapping[str, Any]) -> dict[int, SweepPoint]:
    """The points of ``tasks`` the batch decides, by position in ``tasks``; the others are not in the result."""
    started = time.perf_counter()
    setters = _setters(scenes, options)
    if setters is None or len(tasks) < 2:
        return {}
    assert scenes.base is not None
    values = np.array([task[1] for task in tasks], dtype=float).reshape(len(tasks), len(setters))
    valid = _valid(values, setters)
    stack = PlanarStack.tiled(scenes.base, len(tasks))
    for column, setter in enumerate(setters):
        setter.apply(stack, values[:, column])
    answers: list[_Answer] = []
    frictional = stack.mu > 0.0
    tolerance = float(options.get("tolerance", DEFAULT_TOLERANCE))
    for mask in np.unique(frictional[valid & frictional.any(axis=1)], axis=0):  # one shape of the laws per group
        members = np.flatnonzero(valid & (frictional == mask).all(axis=1))
        for start in range(0, members.size, BATCH_POINTS):  # bounded arrays, whatever the chunk's size
            part = members[start : start + BATCH_POINTS]
            answers += _decided(stack.taken(part), part, tolerance)
    seconds = (time.perf_counter() - started) / max(len(answers), 1)  # a batched point's share of the batch's time
    body = scenes.base.bodies[0].name
    return {answer.position: answer.record(tasks[answer.position], body, seconds) for answer in answers}


@dataclass(frozen=True)
class _Answer:
    """A decided point: its position in the chunk, twist, world forces (round-off shown as 0), mode names and message."""

    position: int
    twist: tuple[float, ...]
    forces: tuple[tuple[float, ...], ...]
    modes: tuple[str, ...]
    message: str

    def record(self, task: Task, body: str, seconds: float) -> SweepPoint:
        """The sweep's record, as :func:`~.result.point_from_solution` makes it of the per-point Solution."""
        index, values, refinement = task
        return SweepPoint(
            index=index,
            values=tuple(float(v) for v in values),
            refinement=refinement,
            status="solved",
            certified=True,
            message=self.message,
            motions=1,
            twists=((body, self.twist),),
            forces=self.forces,
            modes=self.modes,
            seconds=seconds,
        )


Place = tuple[str, tuple[Any, ...], str]
"""Where a path's number goes in a stack: the array's name, the index after the point axis, and the kind of number
(``mu``, ``mass`` or any other ``number``) that says which values a Scene accepts."""


class _Setter:
    """Where one parameter's value goes in a stack: each of its paths' place."""

    def __init__(self, places: list[Place]) -> None:
        self.places = places

    def apply(self, stack: PlanarStack, values: np.ndarray) -> None:
        for name, index, _ in self.places:
            array = getattr(stack, name)
            where = (slice(None), *index)
            array[where] = values.reshape(-1, *([1] * (array[where].ndim - 1)))


def _setters(scenes: PointScenes, options: Mapping[str, Any]) -> list[_Setter] | None:
    """One setter per parameter, or None when the batch does not apply (method, scene shape or a swept path)."""
    method = options.get("method", "auto")
    certify = options.get("certify", True) if options.get("all_solutions") is None else options.get("all_solutions")
    if method not in ("auto", "certified") or (method == "auto" and not certify):
        return None
    base = scenes.base
    if base is None or scenes.parts is None or not stackable(base) or len(base.contacts) > BATCH_CONTACTS:
        return None
    setters = []
    for paths in scenes.steps:
        places = [_place(base, path) for path in paths]
        known = [place for place in places if place is not None]
        if len(known) < len(places):
            return None
        setters.append(_Setter(known))
    return setters


def _place(base: Scene, path: tuple[str | int, ...]) -> Place | None:
    """The stack array and index a file path sets, and the kind of number it is; None where the batch cannot set it."""
    if path[0] == "contacts" and len(path) == 3 and path[2] == "mu":
        return ("mu", (path[1],), "mu")
    if path[0] == "contacts" and len(path) == 4 and path[2] == "point" and path[3] in (0, 1):
        return ("point", (path[1], path[3]), "number")
    body = base.bodies[0].name
    if path[:3] == ("bodies", body, "mass") and len(path) == 3:
        return ("mass", (), "mass")
    if path[:3] == ("bodies", body, "com") and len(path) == 4 and path[3] in (0, 1):
        return ("com", (path[3],), "number")
    if path[:3] == ("bodies", body, "wrench") and len(path) == 4 and path[3] in (0, 1, 2):
        return ("wrench", (path[3],), "number")
    if path[0] == "gravity" and len(path) == 2 and path[1] in (0, 1):
        return ("gravity", (path[1],), "number")
    if path[0] == "movers" and len(path) == 4 and path[2] == "twist" and path[3] in (0, 1, 2):
        rows = tuple(i for i, c in enumerate(base.contacts) if c.other == path[1])
        return ("twist", (list(rows), path[3]), "number") if rows else None
    return None


def _valid(values: np.ndarray, setters: list[_Setter]) -> np.ndarray:
    """Points whose every value a Scene accepts (finite, within ``MAX_MAGNITUDE``; mu and mass as ``Contact`` and
    ``Body`` check them), wherever each goes: any other is solved alone, which reports its error as a fresh read does."""
    valid = np.isfinite(values).all(axis=1) & (np.abs(values) <= MAX_MAGNITUDE).all(axis=1)
    for column, setter in enumerate(setters):
        kinds = {kind for _, _, kind in setter.places}
        if "mu" in kinds:
            valid &= (values[:, column] >= 0.0) & (values[:, column] <= MAX_FRICTION)
        if "mass" in kinds:
            valid &= values[:, column] >= 0.0
    return valid


def _decided(stack: PlanarStack, positions: np.ndarray, tolerance: float) -> list[_Answer]:
    """The points of ``stack`` proven and audited here (``positions``: theirs in the chunk)."""
    laws = assemble_stack(stack)
    if laws is None:
        return []
    motions = certify_stack(laws)
    if not motions.decided.any():
        return []
    units = laws.twist_units()
    twists = motions.q * units
    frames, c, force = laws.frames, motions.c, laws.force[:, None, None]
    forces = ((0.0 + c[..., 0, None] * frames[..., 0, :]) + c[..., 1, None] * frames[..., 1, :]) * force  # as to_world
    audit = audit_stack(stack, twists, forces, (laws.length, laws.force, laws.velocity), tolerance)
    twists = np.where(np.abs(twists) <= ROUNDOFF * units, 0.0, twists)  # round-off shown as 0, as the report does
    forces = np.where(np.abs(forces) <= ROUNDOFF * force, 0.0, forces)
    # Whole arrays to Python floats at once (adding 0.0 turns -0.0 into 0.0, as the per-point record does).
    twist_rows, force_rows, mode_rows = (twists + 0.0).tolist(), (forces + 0.0).tolist(), audit.modes.tolist()
    messages = (solved_message(False), solved_message(True))
    places, indeterminate = positions.tolist(), motions.indeterminate.tolist()
    names = {row: tuple(MODE_CODES[code] for code in row) for row in set(map(tuple, mode_rows))}
    return [
        _Answer(places[k], tuple(twist_rows[k]), tuple(map(tuple, force_rows[k])), names[tuple(mode_rows[k])], messages[indeterminate[k]])
        for k in np.flatnonzero(motions.decided & audit.passed).tolist()
    ]
