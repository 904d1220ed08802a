"""Swept parameters: a path into a scene file's keys (``contacts[2].mu``) and the values it takes.

A parameter names one number of the scene file (the keys ``quasistatic.load_scene``
reads), as dotted keys and ``[index]`` steps: ``contacts[2].mu``,
``bodies.box.mass``, ``movers.pusher.twist[0]``, ``robots.hand.joint_velocities.j1``
(a joint by name, when the robot names its joints). Several paths joined by
commas move together: ``contacts[0].mu,contacts[1].mu`` sets both floor contacts
to each value.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SceneError

__all__ = ["Step", "SweepParam", "apply_values", "resolved_path", "set_values", "parse_param_spec", "parse_path", "sweep_params"]

Step = str | int
"""One step of a path: a mapping key or a list index."""

_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_\-]*)?((?:\[\d+\])*)")
_INDEX = re.compile(r"\[(\d+)\]")
_MAX_POINTS = 10_000_000


@dataclass(frozen=True)
class SweepParam:
    """One axis of the grid.

    Attributes
    ----------
    name : str
        As given: one path, or several joined by commas (set together).
    paths : tuple of tuple of Step
        The parsed paths (keys and indices into the scene file's data).
    values : ndarray, shape (k,)
        The values along this axis, finite, in the given order [the field's unit].
    """

    name: str
    paths: tuple[tuple[Step, ...], ...]
    values: np.ndarray


def parse_path(text: str) -> tuple[Step, ...]:
    """``"contacts[2].point[1]"`` -> ``("contacts", 2, "point", 1)``.

    Raises
    ------
    SceneError
        Naming the path, when it is not dotted keys with optional ``[index]`` steps.
    """
    steps: list[Step] = []
    for token in text.strip().split("."):
        match = _TOKEN.fullmatch(token)
        if not token or match is None or (not match.group(1) and not steps):
            raise SceneError(text, text, "not a parameter path: write dotted keys with [index] steps, e.g. contacts[2].mu")
        if match.group(1):
            steps.append(match.group(1))
        steps += [int(i) for i in _INDEX.findall(match.group(2))]
    return tuple(steps)


def sweep_params(data: Mapping[str, Any], params: Mapping[str, Any]) -> tuple[SweepParam, ...]:
    """The grid's axes, each path checked against the scene file's data.

    Parameters
    ----------
    data : mapping
        The scene file's keys.
    params : mapping
        Path (or comma-joined paths) -> 1-D sequence of numbers.

    Raises
    ------
    SceneError
        Naming the bad path: one that does not lead to a number of the scene, an empty or
        non-finite list of values, or a grid of more than ten million points.
    """
    if not params:
        raise SceneError("params", dict(params), "give at least one parameter path and its values")
    axes = tuple(_param(data, str(name), values) for name, values in params.items())
    count = math.prod(len(axis.values) for axis in axes)
    if count > _MAX_POINTS:
        raise SceneError("params", count, f"the grid has more than {_MAX_POINTS:,} points")
    return axes


def apply_values(data: Mapping[str, Any], params: Sequence[SweepParam], values: Sequence[float]) -> dict[str, Any]:
    """A deep copy of the scene file's data with each parameter's paths set to its value."""
    return set_values(copy.deepcopy(dict(data)), params, values)


def resolved_path(data: Mapping[str, Any], path: tuple[Step, ...], name: str) -> tuple[Step, ...]:
    """``path`` with a joint's name turned into its index: the keys and indices that reach the number in ``data``.

    Raises
    ------
    SceneError
        As :func:`sweep_params` does, when the path does not lead into ``data``.
    """
    node: Any = data
    steps: list[Step] = []
    for depth, step in enumerate(path):
        steps.append(_resolved(node, step, path[:depth], data, name))
        if depth < len(path) - 1:
            node = node[steps[-1]]
    return tuple(steps)


def set_values(data: dict[str, Any], params: Sequence[SweepParam], values: Sequence[float]) -> dict[str, Any]:
    """``data`` itself with each parameter's paths set to its value (the caller copied what the paths reach)."""
    for param, value in zip(params, values, strict=True):
        for path in param.paths:
            container, step = _parent(data, path, param.name)
            container[step] = float(value)
    return data


def parse_param_spec(text: str) -> tuple[str, np.ndarray]:
    """``'contacts[2].mu=0:1:101'`` -> the path and its values (the command line's ``--param``).

    The values are ``start:stop:count`` (evenly spaced, both ends included), a comma-separated list,
    or one number.

    Raises
    ------
    SceneError
        Naming the ``--param`` text, when it is not ``PATH=VALUES`` or its values are not numbers.
    """
    name, sep, spec = text.partition("=")
    if not sep or not name.strip():
        raise SceneError("--param", text, "expected PATH=START:STOP:COUNT or PATH=V1,V2,..., e.g. contacts[2].mu=0:1:101")
    field = f"--param {name.strip()}"
    try:
        if ":" in spec:
            start, stop, count = spec.split(":")
            number = int(count)
            if number < 1:
                raise ValueError
            if number > _MAX_POINTS:  # refused before the values are made: a COUNT of 1e9 would take 8 GB
                raise OverflowError
            with np.errstate(all="ignore"):  # ends beyond a float's range: left to the values' finiteness check
                return name.strip(), np.linspace(float(start), float(stop), number)
        return name.strip(), np.array([float(v) for v in spec.split(",")])
    except OverflowError:
        raise SceneError(field, number, f"the grid has more than {_MAX_POINTS:,} points") from None
    except ValueError:
        reason = "values must be START:STOP:COUNT (COUNT an integer >= 1) or numbers separated by commas"
        raise SceneError(field, spec, reason) from None


def _param(data: Mapping[str, Any], name: str, values: Any) -> SweepParam:
    paths = tuple(parse_path(part) for part in name.split(","))
    for path in paths:
        _check_leaf(data, path, name)
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(name, values, "the values must be numbers") from None
    if array.ndim != 1 or array.size == 0 or not np.all(np.isfinite(array)):
        raise SceneError(name, values, "the values must be a non-empty 1-D list of finite numbers")
    return SweepParam(name, paths, array.copy())


def _check_leaf(data: Mapping[str, Any], path: tuple[Step, ...], name: str) -> None:
    container, step = _parent(data, path, name)
    if isinstance(container, Mapping) and step not in container:
        return  # an optional key not written in the file (a contact's mu): loading the first point checks it
    leaf = container[step]
    if isinstance(leaf, bool) or not isinstance(leaf, (int, float)):
        raise SceneError(name, leaf, f"{_shown(path)} is not a number of the scene; a parameter must name one number")


def _parent(data: Any, path: tuple[Step, ...], name: str) -> tuple[Any, Step]:
    """The container holding the path's last step, and that step (a joint name turned into its index)."""
    node = data
    for depth, step in enumerate(path):
        step = _resolved(node, step, path[:depth], data, name)
        if depth == len(path) - 1:
            return node, step
        node = node[step]
    raise SceneError(name, name, "empty parameter path")  # parse_path never returns an empty path


def _resolved(node: Any, step: Step, before: tuple[Step, ...], data: Any, name: str) -> Step:
    """The step into ``node``; an error names the whole parameter (``name``) and the step that fails."""
    if isinstance(node, Mapping):
        if isinstance(step, int):
            raise SceneError(name, step, f"{_where(before)} is a mapping (keys: {', '.join(map(str, node))}), not a list")
        if step not in node and not _optional_leaf(before):
            known = ", ".join(map(str, node)) or "none"
            raise SceneError(name, step, f"{_where(before)} has no key {step!r} (keys: {known})")
        return step
    if isinstance(node, list):
        if isinstance(step, str):
            return _joint_index(node, step, before, data, name)
        if step >= len(node):
            raise SceneError(name, step, f"{_where(before)} has {len(node)} entries; the index must be below {len(node)}")
        return step
    reason = "is empty in the scene: write its full value in the file first, then sweep an entry"
    raise SceneError(name, node, f"{_where(before)} {reason}")


def _where(before: tuple[Step, ...]) -> str:
    """The path walked so far, for an error (made only then: every sweep point walks its paths)."""
    return _shown(before) or "the scene"


def _optional_leaf(before: tuple[Step, ...]) -> bool:
    """A contact's key (mu) may be absent from the file: the schema checks the name."""
    return len(before) == 2 and before[0] == "contacts"


def _joint_index(node: list[Any], joint: str, before: tuple[Step, ...], data: Any, name: str) -> int:
    """``robots.R.joint_velocities.J`` on a list: J's index among the robot's ``joint_names``."""
    names = None
    if len(before) == 3 and before[0] == "robots" and before[2] == "joint_velocities":
        robot = data["robots"][before[1]]
        names = robot.get("joint_names") if isinstance(robot, Mapping) else None
    if not names:
        raise SceneError(name, joint, f"{_shown(before)} is a list without names: use an index, e.g. {_shown(before)}[0]")
    if joint not in names:
        raise SceneError(name, joint, f"no joint {joint!r} (joint_names: {', '.join(names)})")
    return list(names).index(joint)


def _shown(path: Sequence[Step]) -> str:
    text = ""
    for step in path:
        text += f"[{step}]" if isinstance(step, int) else (f".{step}" if text else step)
    return text
