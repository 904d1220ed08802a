"""Reading scenes: a YAML/JSON file or a dict of the file's keys becomes a validated :class:`Scene`.

The file's structure is checked by a pydantic schema (unknown keys, missing
keys and wrong types are reported with their path and a suggestion); the
values are then checked by the :class:`Scene` they build.
"""

from __future__ import annotations

import difflib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import pydantic
import yaml

from ..errors import MISSING, SceneError
from .scene import Body, Contact, Mover, Robot, Scene

__all__ = ["load_scene", "FORMAT_VERSION"]

FORMAT_VERSION = 1


def _not_bool_or_text(value: Any) -> Any:
    """YAML's ``true`` or ``"0.1"`` is not a number here, whatever pydantic's lax mode says."""
    if isinstance(value, (bool, str)):
        raise ValueError("expected a number")
    return value


_Number = Annotated[float, pydantic.BeforeValidator(_not_bool_or_text)]


class _FileModel(pydantic.BaseModel):
    model_config = pydantic.ConfigDict(extra="forbid", allow_inf_nan=True, strict=False)


class _BodyFile(_FileModel):
    mass: _Number
    com: list[_Number]
    wrench: list[_Number] | None = None


class _MoverFile(_FileModel):
    twist: list[_Number] | None = None
    origin: list[_Number] | None = None
    robot: str | None = None


class _RobotFile(_FileModel):
    joint_velocities: list[_Number]


class _ContactFile(_FileModel):
    body: str
    other: str
    point: list[_Number]
    normal: list[_Number]
    mu: _Number = 0.0
    jacobian: list[list[_Number]] | None = None


class _SceneFile(_FileModel):
    quasistatic: int
    dimension: Literal[2, 3] = 3
    gravity: list[_Number] | None = None
    friction: str = "exact"
    bodies: dict[str, _BodyFile]
    movers: dict[str, _MoverFile | None] = {}
    robots: dict[str, _RobotFile] = {}
    contacts: list[_ContactFile]


def load_scene(source: str | Path | Mapping[str, Any]) -> Scene:
    """Load and validate a scene from a YAML/JSON file path or a dict of the file's keys.

    Raises
    ------
    SceneError
        Naming the field path and the offending value.
    """
    data = _read(source) if isinstance(source, (str, Path)) else source
    if not isinstance(data, Mapping):
        raise SceneError("", type(data).__name__, "a scene must be a mapping of keys (quasistatic, bodies, contacts, ...)")
    version = data.get("quasistatic")
    if "quasistatic" in data and version != FORMAT_VERSION:
        raise SceneError("quasistatic", version, f"unsupported format version; this library reads version {FORMAT_VERSION}")
    try:
        parsed = _SceneFile.model_validate(dict(data))
    except pydantic.ValidationError as exc:
        raise _scene_error(exc) from None
    return Scene(
        dimension=parsed.dimension,
        gravity=parsed.gravity,
        friction=parsed.friction,
        bodies=tuple(Body(name, b.mass, b.com, b.wrench) for name, b in parsed.bodies.items()),
        movers=tuple(Mover(name, m.twist, m.origin, m.robot) if m is not None else Mover(name) for name, m in parsed.movers.items()),
        robots=tuple(Robot(name, r.joint_velocities) for name, r in parsed.robots.items()),
        contacts=tuple(_contact(c, index) for index, c in enumerate(parsed.contacts)),
    )


def _contact(entry: _ContactFile, index: int) -> Contact:
    """A contact of the file; an error in it names the contact by its index."""
    try:
        return Contact(entry.body, entry.other, entry.point, entry.normal, entry.mu, entry.jacobian)
    except SceneError as exc:
        raise SceneError(exc.field.replace("contact", f"contacts[{index}]", 1), exc.value, exc.reason) from None


def _read(path: str | Path) -> Any:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError("", str(path), f"cannot read the scene file: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise SceneError("", str(path), "the scene file is not UTF-8 text") from None
    try:
        if path.suffix.lower() == ".json":
            return json.loads(text)
        return yaml.safe_load(text)
    except json.JSONDecodeError as exc:
        raise SceneError("", str(path), f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise SceneError("", str(path), f"not valid YAML{where}: {getattr(exc, 'problem', None) or exc}") from None


_MODELS_BY_DEPTH: dict[str, type[pydantic.BaseModel]] = {
    "": _SceneFile,
    "bodies": _BodyFile,
    "movers": _MoverFile,
    "robots": _RobotFile,
    "contacts": _ContactFile,
}


def _scene_error(exc: pydantic.ValidationError) -> SceneError:
    errors = exc.errors()
    # A misspelt key shows as both "missing" and "extra": report the extra one, with a hint.
    error = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = [part for part in error["loc"] if part not in ("_MoverFile",)]
    path = _format_path(loc)
    kind = error["type"]
    if kind == "extra_forbidden":
        key = str(loc[-1])
        model = _MODELS_BY_DEPTH.get(str(loc[0]) if len(loc) > 1 else "", _SceneFile)
        close = difflib.get_close_matches(key, list(model.model_fields), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(model.model_fields)}"
        return SceneError(path, key, f"unknown key{hint}")
    if kind == "missing":
        return SceneError(path, MISSING, "required key is missing")
    return SceneError(path, error.get("input"), error["msg"].lower())


def _format_path(loc: Sequence[Any]) -> str:
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text
