"""The scene at each point of a sweep: the file validated once, and at each point only the parts the parameters reach.

Reading the whole file again at every point (a deep copy of its data, the schema, every part of the Scene)
cost more than the rest of a small 2-D solve but the proof. :class:`PointScenes` validates the file once; at a
point it copies the entries the swept paths lead into (a contact, a body, a mover, gravity), sets the values,
checks those entries with the schema and builds them as :func:`~quasistatic.model.io.scene_from_file` does,
and checks the new parts against the scene (:meth:`~quasistatic.model.Scene.replaced`). A path elsewhere (a
robot, the stiffness, a scene of shapes, whose contacts are found at every point) reads the whole file, and so
does a point whose parts are rejected, so that its error is the one a fresh read gives.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pydantic

from ..adapters import world_from_file
from ..errors import SceneError
from ..model import Scene
from ..model.io import (
    BodyFile,
    ContactFile,
    MoverFile,
    body_from_file,
    contact_from_file,
    mover_from_file,
    read_scene_file,
    scene_from_file,
)
from .params import SweepParam, apply_values, resolved_path

__all__ = ["PointScenes", "scene_at"]

Part = tuple[str, str | int]
"""A part of the scene file a path leads into: ``("contacts", 2)``, ``("bodies", "box")``, ``("movers", "pusher")``,
``("gravity", "")``."""


def scene_at(data: Mapping[str, Any], folder: str | Path, params: Sequence[SweepParam], values: Sequence[float]) -> Scene:
    """The Scene with each parameter set to its value, the whole file read again (contacts found when it describes shapes)."""
    parsed, _ = read_scene_file(apply_values(data, params, values))
    return world_from_file(parsed, Path(folder)).scene() if parsed.is_geometric else scene_from_file(parsed)


class PointScenes:
    """The scenes of one sweep's points, each equal to :func:`scene_at`'s, the file validated once.

    Parameters
    ----------
    data : mapping
        The scene file's keys, before any parameter is set (not changed).
    folder : str or Path
        The folder the file's relative paths start from.
    params : sequence of SweepParam
        The grid's axes.
    """

    def __init__(self, data: Mapping[str, Any], folder: str | Path, params: Sequence[SweepParam]) -> None:
        self.data, self.folder, self.params = data, folder, tuple(params)
        self.parts = _swept_parts(self.params)
        self.steps: list[tuple[tuple[str | int, ...], ...]] = []  # each parameter's paths as keys and indices
        self.base = self._base() if self.parts is not None else None

    def at(self, values: Sequence[float]) -> Scene:
        """The scene with each parameter set to its value.

        Raises
        ------
        SceneError
            Exactly as :func:`scene_at` raises it.
        """
        if self.base is None or self.parts is None:
            return scene_at(self.data, self.folder, self.params, values)
        try:
            return self._rebuilt(self.base, self.parts, values)
        except (SceneError, pydantic.ValidationError):
            return scene_at(self.data, self.folder, self.params, values)  # raises the error a fresh read gives

    def _base(self) -> Scene | None:
        """The file's own scene; None for a scene of shapes, or a file each point must read to say why it fails."""
        try:
            parsed, _ = read_scene_file(self.data)
            if parsed.is_geometric:
                return None
            self.steps = [tuple(resolved_path(self.data, path, p.name) for path in p.paths) for p in self.params]
            return scene_from_file(parsed)
        except SceneError:
            return None

    def _rebuilt(self, base: Scene, parts: tuple[Part, ...], values: Sequence[float]) -> Scene:
        entries = _copied(self.data, parts)
        for paths, value in zip(self.steps, values, strict=True):
            for path in paths:
                _set(entries, path, float(value))
        contacts, bodies, movers = {}, {}, {}
        for key, name in parts:
            if key == "contacts":
                assert isinstance(name, int)
                contacts[name] = contact_from_file(ContactFile.model_validate(entries["contacts"][name]), name)
            elif key == "bodies":
                bodies[str(name)] = body_from_file(str(name), BodyFile.model_validate(entries["bodies"][name]))
            elif key == "movers":
                entry = entries["movers"][name]
                movers[str(name)] = mover_from_file(str(name), None if entry is None else MoverFile.model_validate(entry))
        gravity = entries["gravity"] if ("gravity", "") in parts else None
        return base.replaced(bodies=bodies, movers=movers, contacts=contacts, gravity=gravity)


def _set(data: dict[str, Any], path: tuple[str | int, ...], value: float) -> None:
    node: Any = data
    for step in path[:-1]:
        node = node[step]
    node[path[-1]] = value


def _swept_parts(params: Sequence[SweepParam]) -> tuple[Part, ...] | None:
    """The parts the paths lead into, each once; None when one leads elsewhere (then every point reads the file)."""
    parts: dict[Part, None] = {}
    for param in params:
        for path in param.paths:
            part = _part(path)
            if part is None:
                return None
            parts[part] = None
    return tuple(parts)


def _part(path: tuple[str | int, ...]) -> Part | None:
    if len(path) >= 3 and path[0] == "contacts" and isinstance(path[1], int):
        return ("contacts", path[1])
    if len(path) >= 3 and path[0] in ("bodies", "movers") and isinstance(path[1], str):
        return (str(path[0]), path[1])
    if len(path) == 2 and path[0] == "gravity" and isinstance(path[1], int):
        return ("gravity", "")
    return None


def _copied(data: Mapping[str, Any], parts: tuple[Part, ...]) -> dict[str, Any]:
    """``data`` with the containers down to each part copied (each part's entry deeply), the rest shared."""
    out = dict(data)
    for key, name in parts:
        if key == "gravity":
            out["gravity"] = _plain_copy(data["gravity"])
            continue
        if out[key] is data[key]:
            out[key] = list(data[key]) if isinstance(data[key], list) else dict(data[key])
        out[key][name] = _plain_copy(data[key][name])
    return out


def _plain_copy(value: Any) -> Any:
    """A deep copy of a file's data (mappings, lists, numbers, text): ``copy.deepcopy`` costs 5x more per point."""
    if type(value) in _LEAVES:  # most entries: numbers (the exact type: an ABC check costs more than the copy)
        return value
    if isinstance(value, list):
        return [_plain_copy(item) for item in value]
    if isinstance(value, Mapping):
        return {key: _plain_copy(item) for key, item in value.items()}
    return value  # text, None, or a tuple (immutable: a path cannot set into it, as in a deep copy)


_LEAVES = frozenset({float, int, str, bool, type(None)})
