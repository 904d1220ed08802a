"""Reading scenes: a YAML/JSON file or a dict of the file's keys becomes a validated :class:`Scene`.

The file's structure is checked by a pydantic schema (unknown keys, missing
keys and wrong types are reported with their path and a suggestion); the
values are then checked by the :class:`Scene` they build.

Hostile input costs little: a file is read up to :data:`MAX_FILE_BYTES` only;
YAML is composed by a loader that counts what its aliases expand to
(:data:`MAX_VALUES`), limits nesting (:data:`MAX_DEPTH`) and rejects duplicate
keys as it goes, so a "billion laughs" file never expands in memory; and any
data (JSON or a dict) is walked once without recursion for the same limits
before pydantic or numpy look at it.
"""

from __future__ import annotations

import difflib
import itertools
import json
import re
import typing
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import pydantic
import yaml

from ..errors import MISSING, SceneError
from ..tolerances import MAX_DEPTH, MAX_FILE_BYTES, MAX_VALUES
from .scene import Body, Contact, Mover, Robot, Scene, Stiffness

__all__ = [
    "read_scene_data",
    "read_scene_file",
    "read_text",
    "scene_from_file",
    "scene_to_dict",
    "plain_robot",
    "body_from_file",
    "mover_from_file",
    "contact_from_file",
    "stiffness_of",
    "SceneFile",
    "StiffnessFile",
    "FORMAT_VERSION",
]

FORMAT_VERSION = 1

_LONGEST_INTEGER = 300  # digits: longer integers exceed any allowed magnitude; they are read as inf (Python's int() refuses > 4300)
_SNIPPET = 40  # characters of the source shown for a value rejected while it is parsed
_MERGE_TAG = "tag:yaml.org,2002:merge"
_YAML_EVENTS: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's parser when built with it: 3x faster


def _not_bool_or_text(value: Any) -> Any:
    """YAML's ``true`` or ``"0.1"`` is not a number here, whatever pydantic's lax mode says."""
    if isinstance(value, (bool, str)):
        raise ValueError("expected a number")
    return value


_Number = Annotated[float, pydantic.BeforeValidator(_not_bool_or_text)]


class _FileModel(pydantic.BaseModel):
    model_config = pydantic.ConfigDict(extra="forbid", allow_inf_nan=True, strict=False)


class PoseFile(_FileModel):
    """``{position: [x, y, z], rotation: {rpy: [...]} | {quaternion: [w, x, y, z]} | {matrix: [[...], ...]}}``;
    in a planar scene (``dimension: 2``) ``{position: [x, y], angle: theta}`` (radians, counter-clockwise)."""

    position: list[_Number] = [0.0, 0.0, 0.0]
    rotation: RotationFile | None = None
    angle: _Number | None = None


class RotationFile(_FileModel):
    """Exactly one of roll-pitch-yaw angles [rad], a unit quaternion (w first) or a 3x3 rotation matrix."""

    rpy: list[_Number] | None = None
    quaternion: list[_Number] | None = None
    matrix: list[list[_Number]] | None = None


class CylinderFile(_FileModel):
    radius: _Number
    length: _Number


class HalfspaceFile(_FileModel):
    """Points x with ``normal . x <= offset`` are inside (the solid side)."""

    normal: list[_Number]
    offset: _Number = 0.0


class ShapeFile(_FileModel):
    """Exactly one shape: ``box`` (3 full edge lengths), ``sphere`` (radius), ``cylinder``/``capsule`` (along the local z
    axis), ``halfspace``, or ``mesh`` (a file path, relative to the scene file) with an optional ``scale``.
    In a planar scene: ``disk`` (radius), ``box`` ([width, height]), ``polygon`` (convex, [[x, y], ...]) or ``halfplane``."""

    box: list[_Number] | None = None
    sphere: _Number | None = None
    cylinder: CylinderFile | None = None
    capsule: CylinderFile | None = None
    halfspace: HalfspaceFile | None = None
    mesh: str | None = None
    scale: _Number | list[_Number] | None = None
    disk: _Number | None = None
    polygon: list[list[_Number]] | None = None
    halfplane: HalfspaceFile | None = None


class BodyFile(_FileModel):
    """A free body. With a ``pose``, ``com`` is in the body's frame (default: its origin); without, in the world's."""

    mass: _Number
    com: list[_Number] | None = None
    wrench: list[_Number] | None = None
    shape: ShapeFile | None = None
    pose: PoseFile | None = None


class MoverFile(_FileModel):
    """A prescribed body: fixed, a rigid ``twist`` (about ``origin``, or the pose's position), or a robot link."""

    twist: list[_Number] | None = None
    origin: list[_Number] | None = None
    robot: str | None = None
    shape: ShapeFile | None = None
    pose: PoseFile | None = None


class RobotFile(_FileModel):
    """Joint velocities (a list, or by joint name for a URDF robot); a URDF robot also has its file, base and joints.

    Optional: torque limits (one magnitude per joint); joint names for a robot without a URDF (its own otherwise).
    """

    joint_velocities: list[_Number] | dict[str, _Number] | None = None
    torque_limits: list[_Number] | dict[str, _Number] | None = None
    joint_stiffness: list[_Number] | dict[str, _Number] | None = None
    joint_names: list[str] | None = None
    urdf: str | None = None
    package_dirs: list[str] = []
    base: PoseFile | None = None
    q: list[_Number] | dict[str, _Number] | None = None


class StiffnessFile(_FileModel):
    """A contact's springs [force/length]; ``tangential`` defaults to ``normal``."""

    normal: _Number
    tangential: _Number | None = None


class ContactFile(_FileModel):
    body: str
    other: str
    point: list[_Number]
    normal: list[_Number]
    mu: _Number = 0.0
    jacobian: list[list[_Number]] | None = None
    stiffness: StiffnessFile | None = None


class FrictionPairFile(_FileModel):
    between: list[str]
    mu: _Number


class DetectionFrictionFile(_FileModel):
    default: _Number = 0.0
    pairs: list[FrictionPairFile] = []


class StiffnessPairFile(_FileModel):
    between: list[str]
    normal: _Number
    tangential: _Number | None = None


class DetectionStiffnessFile(_FileModel):
    default: StiffnessFile | None = None
    pairs: list[StiffnessPairFile] = []


class DetectionFile(_FileModel):
    """Gaps up to ``margin`` count as contacts (default: relative to the bodies' size); friction and stiffness by pair of names."""

    margin: _Number | None = None
    friction: DetectionFrictionFile = DetectionFrictionFile()
    stiffness: DetectionStiffnessFile = DetectionStiffnessFile()


class SceneFile(_FileModel):
    """A scene file's keys, checked for structure and types (the values are checked by what they build)."""

    quasistatic: pydantic.StrictInt
    dimension: Literal[2, 3] = 3
    gravity: list[_Number] | None = None
    friction: str = "exact"
    bodies: dict[str, BodyFile]
    movers: dict[str, MoverFile | None] = {}
    robots: dict[str, RobotFile] = {}
    contacts: list[ContactFile] = []
    contact_detection: DetectionFile | None = None
    stiffness: StiffnessFile | None = None
    closing_time: _Number | None = None

    @property
    def is_geometric(self) -> bool:
        """Whether contacts are to be found from shapes and robot models (rather than all listed)."""
        return (
            self.contact_detection is not None
            or any(b.shape is not None or b.pose is not None for b in self.bodies.values())
            or any(m is not None and (m.shape is not None or m.pose is not None) for m in self.movers.values())
            or any(r.urdf is not None for r in self.robots.values())
        )


PoseFile.model_rebuild()


def read_scene_file(source: str | Path | Mapping[str, Any]) -> tuple[SceneFile, Path]:
    """The checked keys of a scene file (or of a dict of its keys), and the folder its relative paths start from.

    Raises
    ------
    SceneError
        Naming the field path and the offending value; also for a file too large, nested too deep,
        expanding past :data:`MAX_VALUES` values, or holding a key twice.
    """
    data = _read(source) if isinstance(source, (str, Path)) else source
    folder = Path(source).parent if isinstance(source, (str, Path)) else Path.cwd()
    if not isinstance(data, Mapping):
        raise SceneError("", type(data).__name__, "a scene must be a mapping of keys (quasistatic, bodies, contacts, ...)")
    _check_structure(data)
    _check_version(data)
    try:
        return SceneFile.model_validate(dict(data)), folder
    except pydantic.ValidationError as exc:
        raise _scene_error(exc) from None


def read_scene_data(path: str | Path) -> dict[str, Any]:
    """The keys of a scene file as written (aliases expanded, nothing filled in), checked against the schema.

    Raises
    ------
    SceneError
        As :func:`read_scene_file` does.
    """
    data = _read(path)
    read_scene_file(data)
    return dict(data)


def scene_from_file(parsed: SceneFile) -> Scene:
    """The Scene of a file that lists its contacts."""
    if "contacts" not in parsed.model_fields_set:
        raise SceneError("contacts", MISSING, "required key is missing (or describe shapes and let the contacts be found)")
    return Scene(
        dimension=parsed.dimension,
        gravity=parsed.gravity,
        friction=parsed.friction,
        bodies=tuple(body_from_file(name, b) for name, b in parsed.bodies.items()),
        movers=tuple(mover_from_file(name, m) for name, m in parsed.movers.items()),
        robots=tuple(plain_robot(name, r) for name, r in parsed.robots.items()),
        contacts=tuple(contact_from_file(c, index) for index, c in enumerate(parsed.contacts)),
        stiffness=stiffness_of(parsed.stiffness, "stiffness"),
        closing_time=parsed.closing_time,
    )


def body_from_file(name: str, body: BodyFile) -> Body:
    """The Body of a file entry that lists its contacts (its com in the world frame)."""
    return Body(name, body.mass, _com(name, body), body.wrench)


def mover_from_file(name: str, mover: MoverFile | None) -> Mover:
    """The Mover of a file entry (None: a fixed mover)."""
    return Mover(name) if mover is None else Mover(name, mover.twist, mover.origin, mover.robot)


def plain_robot(name: str, robot: RobotFile) -> Robot:
    """The Robot of a file entry without a URDF: joint velocities and torque limits as lists."""
    reason = "joints can be named only for a robot with a urdf; give a list, one per Jacobian column"
    if isinstance(robot.torque_limits, dict):
        raise SceneError(f"robots.{name}.torque_limits", robot.torque_limits, reason)
    if isinstance(robot.joint_stiffness, dict):
        raise SceneError(f"robots.{name}.joint_stiffness", robot.joint_stiffness, reason)
    return Robot(
        name,
        _velocity_list(name, robot),
        joint_names=robot.joint_names,
        torque_limits=robot.torque_limits,
        joint_stiffness=robot.joint_stiffness,
    )


def stiffness_of(entry: StiffnessFile | None, field: str) -> Stiffness | None:
    """The Stiffness of a file entry at ``field`` (None when absent); an error names that field."""
    if entry is None:
        return None
    try:
        return Stiffness(entry.normal, entry.tangential)
    except SceneError as exc:
        raise SceneError(exc.field.replace("stiffness", field, 1), exc.value, exc.reason) from None


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The scene file (format version 1) that lists this scene's contacts; ``quasistatic.load_scene`` reads it back equal."""
    return {
        "quasistatic": FORMAT_VERSION,
        "dimension": scene.dimension,
        "gravity": scene.gravity.tolist(),
        "friction": str(scene.friction),
        "bodies": {b.name: {"mass": b.mass, "com": b.com.tolist(), "wrench": _listed(b.wrench)} for b in scene.bodies},
        "movers": {m.name: _mover_entry(m) for m in scene.movers},
        "robots": {r.name: _robot_entry(r) for r in scene.robots},
        "contacts": [_contact_entry(c) for c in scene.contacts],
        **({} if scene.stiffness is None else {"stiffness": _stiffness_entry(scene.stiffness)}),
        **({} if scene.closing_time is None else {"closing_time": scene.closing_time}),
    }


def _stiffness_entry(stiffness: Stiffness) -> dict[str, float]:
    return {"normal": stiffness.normal, "tangential": stiffness.tangential}


def _robot_entry(robot: Robot) -> dict[str, Any]:
    entry: dict[str, Any] = {"joint_velocities": robot.joint_velocities.tolist()}
    if robot.joint_names is not None:
        entry["joint_names"] = list(robot.joint_names)
    if robot.torque_limits is not None:
        entry["torque_limits"] = robot.torque_limits.tolist()
    if robot.joint_stiffness is not None:
        entry["joint_stiffness"] = robot.joint_stiffness.tolist()
    return entry


def _mover_entry(mover: Mover) -> dict[str, Any]:
    if mover.robot is not None:
        return {"robot": mover.robot}
    return {"twist": _listed(mover.twist), "origin": _listed(mover.origin)}


def _contact_entry(contact: Contact) -> dict[str, Any]:
    entry = {"body": contact.body, "other": contact.other, "point": contact.point.tolist(), "normal": contact.normal.tolist()}
    entry["mu"] = contact.mu
    if contact.jacobian is not None:
        entry["jacobian"] = contact.jacobian.tolist()
    if contact.stiffness is not None:
        entry["stiffness"] = _stiffness_entry(contact.stiffness)
    return entry


def _listed(values: Any) -> Any:
    return None if values is None else values.tolist()


def _com(name: str, body: BodyFile) -> list[float]:
    if body.com is None:
        raise SceneError(f"bodies.{name}.com", MISSING, "required key is missing")
    return body.com


def _velocity_list(name: str, robot: RobotFile) -> list[float]:
    """Joint velocities of a robot with no model: a list (names mean nothing without a URDF)."""
    if robot.joint_velocities is None:
        raise SceneError(f"robots.{name}.joint_velocities", MISSING, "required key is missing")
    if isinstance(robot.joint_velocities, dict):
        reason = "joints can be named only for a robot with a urdf; give a list, one per Jacobian column"
        raise SceneError(f"robots.{name}.joint_velocities", robot.joint_velocities, reason)
    return robot.joint_velocities


def _check_version(data: Mapping[str, Any]) -> None:
    """The format version, if given, is the integer 1: not ``true`` (which equals 1), ``1.0`` or ``"1"``."""
    if "quasistatic" not in data:
        return  # the schema reports it missing
    version = data["quasistatic"]
    reason = f"unsupported format version; this library reads version {FORMAT_VERSION}"
    if isinstance(version, bool) or not isinstance(version, int):
        raise SceneError("quasistatic", version, f"{reason}, written as the integer {FORMAT_VERSION}")
    if version != FORMAT_VERSION:
        raise SceneError("quasistatic", version, reason)


def contact_from_file(entry: ContactFile, index: int) -> Contact:
    """A contact of the file; an error in it names the contact by its index."""
    stiffness = stiffness_of(entry.stiffness, f"contacts[{index}].stiffness")
    try:
        return Contact(entry.body, entry.other, entry.point, entry.normal, entry.mu, entry.jacobian, stiffness)
    except SceneError as exc:
        raise SceneError(exc.field.replace("contact", f"contacts[{index}]", 1), exc.value, exc.reason) from None


# --------------------------------------------------------------------------- files


def _read(path: str | Path) -> Any:
    """The data of a scene file: JSON for ``.json``, YAML otherwise."""
    path = Path(path)
    text = read_text(path)
    try:
        if path.suffix.lower() == ".json":
            return _parse_json(text)
        _check_yaml_volume(text)
        return _SceneYamlLoader(text).load()
    except SceneError:
        raise
    except json.JSONDecodeError as exc:
        raise SceneError("", path, f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}") from None
    except yaml.YAMLError as exc:
        raise _yaml_error(path, text, exc) from None
    except RecursionError:  # a parser's own recursion (e.g. a YAML merge chain); nesting is limited before it
        raise SceneError("", path, f"nested deeper than {MAX_DEPTH} levels") from None
    except (ValueError, TypeError, OverflowError) as exc:  # a YAML tag's constructor, e.g. !!timestamp 2001-13-45
        raise SceneError("", path, f"not valid {'JSON' if path.suffix.lower() == '.json' else 'YAML'}: {exc}") from None


def _yaml_error(path: Path, text: str, exc: yaml.YAMLError) -> SceneError:
    """The error of a YAML file PyYAML refused. libyaml (0.2.6 on) stops at its own nesting depth, reading ahead of
    the events, before the composer's :data:`MAX_DEPTH` check can name the path; the pure-Python parser reads no
    deeper than a simple key's 1024 characters, so parsed again with it the check names the path and the value."""
    problem = str(getattr(exc, "problem", None) or exc)
    if "nesting depth" in problem and _YAML_EVENTS is not yaml.SafeLoader:
        try:
            _SceneYamlLoader(text, yaml.SafeLoader).load()
        except SceneError as named:
            return named
        except (yaml.YAMLError, RecursionError, ValueError, TypeError, OverflowError):
            pass
    mark = getattr(exc, "problem_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    return SceneError("", path, f"not valid YAML{where}: {problem}")


def read_text(path: Path, field: str = "", what: str = "the scene file") -> str:
    """A text file read up to one byte past :data:`MAX_FILE_BYTES` (a device or pipe may never end), as UTF-8.

    ``what`` names the file in the messages ("the URDF"); ``field`` is where it was named.
    """
    try:
        with path.open("rb") as stream:
            raw = stream.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise SceneError(field, path, f"cannot read {what}: {exc.strerror or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise SceneError(field, path, f"{what} is larger than {MAX_FILE_BYTES // 2**20} MiB")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise SceneError(field, path, f"{what} is not UTF-8 text") from None


def _huge_integer(text: str) -> float | None:
    """``inf`` (signed) for an integer literal too long for Python's ``int()``, None otherwise: the Scene rejects it by field."""
    if len(text) <= _LONGEST_INTEGER:
        return None
    return float("-inf") if text.lstrip().startswith("-") else float("inf")


# --------------------------------------------------------------------------- JSON


class _DuplicateKey(dict[str, Any]):
    """A JSON object that gave ``key`` twice; :func:`_check_structure` reports it with its path."""

    key: str = ""


def _json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``object_pairs_hook``: a dict, marked when a key came twice (the path is known only later)."""
    result = dict(pairs)
    if len(result) == len(pairs):
        return result
    marked = _DuplicateKey(result)
    marked.key = _first_repeated(key for key, _ in pairs)
    return marked


def _first_repeated(keys: Iterable[str]) -> str:
    """The first key that was seen before (there is one)."""
    seen: set[str] = set()
    for key in keys:
        if key in seen:
            return key
        seen.add(key)
    raise AssertionError("unreachable: the caller found a repeated key")


def _json_integer(text: str) -> int | float:
    """``parse_int``: Python's int, or inf for a literal too long for it."""
    huge = _huge_integer(text)
    return int(text) if huge is None else huge


def _parse_json(text: str) -> Any:
    """JSON with duplicate keys marked and huge integers read as inf; nesting past the parser's recursion names its path."""
    try:
        return json.loads(text, object_pairs_hook=_json_object, parse_int=_json_integer)
    except RecursionError:
        path, start = _json_too_deep(text)
        raise SceneError(_format_path(path), _snippet(text, start), f"nested deeper than {MAX_DEPTH} levels") from None


_JSON_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"\s*:?|[\[\]{},]')


def _json_too_deep(text: str) -> tuple[list[Any], int]:
    """The path (keys and indices) to the first container of JSON text nested deeper than :data:`MAX_DEPTH`, and
    where it starts: a flat scan of the text, for when the parser's own recursion gave up."""
    stack: list[Any] = []  # per open container: its current index (array) or key (object)
    for match in _JSON_TOKEN.finditer(text):
        token = match.group()
        if token in ("[", "{"):
            if len(stack) >= MAX_DEPTH:
                return stack, match.start()
            stack.append(0 if token == "[" else "")
        elif token in ("]", "}") and stack:
            stack.pop()
        elif token == "," and stack and isinstance(stack[-1], int):
            stack[-1] += 1
        elif token.endswith(":") and stack:
            stack[-1] = json.loads(token[:-1].rstrip())
    return stack, 0


def _snippet(text: str, start: int) -> str:
    """The source text from ``start`` to the end of its line, at most ``_SNIPPET`` characters: what the file wrote there."""
    line = text[start : start + _SNIPPET + 1].split("\n", 1)[0]
    return line if len(line) <= _SNIPPET else line[:_SNIPPET] + "..."


# --------------------------------------------------------------------------- YAML


# Where a YAML value starts: a flow item, a block sequence entry, a mapping value. In the structure of a file each
# is a value of its own; inside quoted text, comments or long plain text they are not, which only a hostile file
# (megabytes of such text) holds a million of.
_YAML_ITEM = re.compile(r"[\[{,][ \t]*[^\s\]},]|^[ \t]*- |: ", re.MULTILINE)


def _check_yaml_volume(text: str) -> None:
    """Refuse a YAML text that starts more than :data:`MAX_VALUES` values, before composing any.

    PyYAML composes a value in ~10 us of Python (its resolver and composer, not libyaml's parser), so a million of
    them took 10 s to reach the count the loader stops at; a regular expression finds them in ~0.3 us each. Its
    character counts first bound the matches: a scene of 10,000 contacts is nowhere near and pays ~10 ms.
    """
    bound = sum(text.count(mark) for mark in ("[", "{", ",", "- ", ": "))
    if bound <= MAX_VALUES:
        return
    past = next(itertools.islice(_YAML_ITEM.finditer(text), MAX_VALUES, None), None)
    if past is None:
        return
    start = past.start()
    line, column = text.count("\n", 0, start) + 1, start - text.rfind("\n", 0, start)
    reason = f"the file holds more than {MAX_VALUES:,} values by line {line}, column {column}; a scene needs far fewer"
    raise SceneError("", _snippet(text, start), reason)


class _SceneYamlLoader(yaml.composer.Composer, yaml.constructor.SafeConstructor, yaml.resolver.Resolver):
    """PyYAML's safe loading, composed by hand from parser events with the limits checked per node.

    Every composed node records how many values it holds once its aliases are expanded (an alias
    costs its anchor's count, not its text), so an expansion past :data:`MAX_VALUES` is rejected
    before anything is built. Nesting deeper than :data:`MAX_DEPTH`, an alias inside its own
    anchor and a key given twice in one mapping are rejected too, each naming its path.
    """

    def __init__(self, text: str, events: type = _YAML_EVENTS) -> None:
        yaml.composer.Composer.__init__(self)
        yaml.constructor.SafeConstructor.__init__(self)
        yaml.resolver.Resolver.__init__(self)
        self._text = text
        self._events: Iterator[Any] = yaml.parse(text, Loader=events)
        self._next: Any = None
        self._sizes: dict[Any, int] = {}  # node -> values it holds, aliases expanded; absent while it is composed
        self._composed = 0  # values composed so far: past MAX_VALUES the file is refused before its collection closes
        self._path: list[Any] = []

    def load(self) -> Any:
        """The document's data (None for an empty file)."""
        return self.get_single_data()

    # The event source PyYAML's Composer reads (its Parser's three methods).
    def check_event(self, *choices: type) -> bool:
        event = self.peek_event()
        return event is not None and (not choices or isinstance(event, choices))

    def peek_event(self) -> Any:
        if self._next is None:
            self._next = next(self._events, None)
        return self._next

    def get_event(self) -> Any:
        event = self.peek_event()
        self._next = None
        return event

    def compose_node(self, parent: Any, index: Any) -> Any:
        """Compose one node as PyYAML does, with its path, depth, expanded size and keys checked."""
        if parent is not None:
            self._path.append(_yaml_part(parent, index))
        try:
            return self._checked_node(parent, index)
        finally:
            if parent is not None:
                self._path.pop()

    def _checked_node(self, parent: Any, index: Any) -> Any:
        """The node PyYAML composes, once its limits are checked (its path is already on ``_path``)."""
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = super().compose_node(parent, index)
            if node not in self._sizes:
                raise SceneError(_format_path(self._path), f"*{event.anchor}", "an alias cannot refer to a value that contains it")
            return node
        start = event.start_mark.index
        self._composed += 1
        if self._composed > MAX_VALUES:
            reason = f"the file holds more than {MAX_VALUES:,} values by this point; a scene needs far fewer"
            raise SceneError(_format_path(self._path), _snippet(self._text, start), reason)
        collection = isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent))
        if collection and len(self._path) >= MAX_DEPTH:
            raise SceneError(_format_path(self._path), _snippet(self._text, start), f"nested deeper than {MAX_DEPTH} levels")
        node = super().compose_node(parent, index)
        size = 1 + sum(self._sizes[child] for child in _yaml_children(node))
        if size > MAX_VALUES:
            reason = f"holds more than {MAX_VALUES:,} values, counting what its aliases expand to; a scene needs far fewer"
            raise SceneError(_format_path(self._path), _snippet(self._text, start), reason)
        self._sizes[node] = size
        if isinstance(node, yaml.MappingNode):
            self._check_keys(node)
        return node

    def _check_keys(self, node: Any) -> None:
        """No key twice in one mapping (YAML's ``<<`` merge keys may be overridden, as YAML intends)."""
        seen: set[Any] = set()
        for key_node, _ in node.value:
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag == _MERGE_TAG:
                continue
            key = self.construct_object(key_node)
            if key in seen:
                raise SceneError(_format_path([*self._path, key]), key, "key given twice in the same mapping; give it once")
            seen.add(key)

    def construct_yaml_int(self, node: Any) -> int | float:
        """PyYAML's integers, with a literal too long for ``int()`` read as inf (rejected by its field)."""
        huge = _huge_integer(self.construct_scalar(node))
        return super().construct_yaml_int(node) if huge is None else huge


_SceneYamlLoader.add_constructor("tag:yaml.org,2002:int", _SceneYamlLoader.construct_yaml_int)


def _yaml_part(parent: Any, index: Any) -> Any:
    """The path part of a child node: its index in a sequence, its key's text in a mapping (``?`` for a key itself)."""
    if isinstance(parent, yaml.SequenceNode):
        return index
    return index.value if isinstance(index, yaml.ScalarNode) else "?"


def _yaml_children(node: Any) -> Iterator[Any]:
    """The nodes a node holds: a sequence's items, a mapping's keys and values."""
    if isinstance(node, yaml.SequenceNode):
        yield from node.value
    elif isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            yield key
            yield value


# --------------------------------------------------------------------------- any data


def _check_structure(data: Any) -> None:
    """Depth, size and duplicate keys of any data, walked once with a stack (no recursion, shared values counted per use).

    Raises
    ------
    SceneError
        Past :data:`MAX_DEPTH` levels or :data:`MAX_VALUES` values, or for a JSON key given twice; naming the path.
    """
    stack: list[tuple[Any, tuple[Any, ...]]] = [(data, ())]
    count = 1
    while stack:
        value, path = stack.pop()
        if not isinstance(value, _CONTAINERS):
            continue
        if len(path) >= MAX_DEPTH:
            raise SceneError(_format_path(path), value, f"nested deeper than {MAX_DEPTH} levels")
        if isinstance(value, _DuplicateKey):
            raise SceneError(_format_path([*path, value.key]), value.key, "key given twice in the same mapping; give it once")
        count += len(value)
        if count > MAX_VALUES:
            reason = f"holds more than {MAX_VALUES:,} values (a shared list counts each time it is used); a scene needs far fewer"
            raise SceneError(_format_path(path), value, reason)
        items = value.items() if isinstance(value, Mapping) else enumerate(value)
        stack.extend((child, (*path, key)) for key, child in items)


_CONTAINERS = (Mapping, list, tuple, set, frozenset)


# --------------------------------------------------------------------------- pydantic's errors in the library's words

_MODEL_NAMES = {
    model.__name__
    for model in (SceneFile, BodyFile, MoverFile, RobotFile, ContactFile, ShapeFile, PoseFile, RotationFile)
    + (CylinderFile, HalfspaceFile, DetectionFile, DetectionFrictionFile, FrictionPairFile)
}
_UNION_TAG = re.compile(r"^(list|dict)\[")  # pydantic's name for one branch of a union, e.g. 'list[float]'
_WORDS = {
    "list_type": "expected a list",
    "dict_type": "expected a mapping of names to entries",
    "string_type": "expected a string",
    "float_type": "expected a number",
    "float_parsing": "expected a number",
    "finite_number": "expected a finite number",
    "int_type": "expected an integer",
    "literal_error": "must be 2 or 3",
}


def _scene_error(exc: pydantic.ValidationError) -> SceneError:
    """The first of pydantic's errors as a SceneError in this library's words (never its internal class names)."""
    errors = exc.errors()
    # A misspelt key shows as both "missing" and "extra": report the extra one, with a hint.
    error = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = [part for part in error["loc"] if part not in _MODEL_NAMES and not _UNION_TAG.match(str(part))]
    kind = error["type"]
    if loc and loc[-1] == "[key]":
        return SceneError(_format_path(loc[:-2]), loc[-2], "names (keys) must be strings")
    path = _format_path(loc)
    if kind == "extra_forbidden":
        return SceneError(path, loc[-1], f"unknown key{_key_hint(str(loc[-1]), _model_at(loc[:-1]))}")
    if kind == "missing":
        return SceneError(path, MISSING, "required key is missing")
    if kind == "model_type":
        keys = ", ".join(_model_at(loc).model_fields)
        return SceneError(path, error.get("input"), f"expected a mapping with keys {keys}")
    return SceneError(path, error.get("input"), _WORDS.get(kind) or _plain(error["msg"]))


def _model_at(loc: Sequence[Any]) -> type[pydantic.BaseModel]:
    """The schema model that checks the value at ``loc`` (``bodies.cube.shape`` -> ShapeFile), for the allowed keys."""
    model: type[pydantic.BaseModel] = SceneFile
    parts = list(loc)
    while parts:
        field = model.model_fields.get(str(parts.pop(0)))
        inner = None if field is None else _inner_model(field.annotation)
        if inner is None:
            return model
        model, keyed = inner
        if keyed and parts:
            parts.pop(0)  # the entry's name or index
    return model


def _inner_model(annotation: Any) -> tuple[type[pydantic.BaseModel], bool] | None:
    """The schema model inside a field's type, and whether it sits in a dict or list (so one path part names the entry)."""
    if isinstance(annotation, type) and issubclass(annotation, pydantic.BaseModel):
        return annotation, False
    origin = typing.get_origin(annotation)
    for argument in typing.get_args(annotation):
        inner = _inner_model(argument)
        if inner is not None:
            return inner[0], inner[1] or origin in (dict, list)
    return None


def _key_hint(key: str, model: type[pydantic.BaseModel]) -> str:
    """'; did you mean ...?' for a misspelt key, else the allowed keys (no fuzzy matching of a huge key)."""
    close = difflib.get_close_matches(key, list(model.model_fields), n=1) if len(key) <= 100 else []
    return f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(model.model_fields)}"


def _plain(message: str) -> str:
    """pydantic's message without its 'Value error, ' prefix or class names, starting in lower case."""
    message = re.sub(r"^value error, ", "", message, flags=re.IGNORECASE)
    message = re.sub(r"\b_?\w+File\b", "mapping", message)
    return message[:1].lower() + message[1:]


def _format_path(loc: Sequence[Any]) -> str:
    """``bodies.box.com``, ``contacts[1].normal``; a key that is not plain printable text is shown quoted."""
    text = ""
    for part in loc:
        if isinstance(part, int) and not isinstance(part, bool):
            text += f"[{part}]"
        elif isinstance(part, str) and part.isprintable() and part:
            text += f".{part}" if text else part
        else:
            text += f"[{part!r}]"
    return text
