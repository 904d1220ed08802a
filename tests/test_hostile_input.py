"""Input that cannot hurt: hostile scene files give one ``error:`` line and exit code 2, fast.

Every case runs through the installed ``quasistatic`` console script in a
subprocess (``check`` and ``solve``): exit code 2, nothing on stdout, exactly
one stderr line starting with ``error:`` that names the field, and no hang (a
timeout fails the test). The same files through ``qs.load_scene`` raise
:class:`qs.SceneError`, never a RecursionError, MemoryError or the like. A
hypothesis test then writes YAML and JSON text with hostile structures and
checks that loading returns a Scene or raises SceneError, quickly.
"""

from __future__ import annotations

import importlib
import json
import math
import subprocess
import sys
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import quasistatic as qs
from console_script import run_console
from quasistatic import cli
from quasistatic.tolerances import MAX_DEPTH, MAX_FILE_BYTES, MAX_FRICTION, MAX_MAGNITUDE, MAX_VALUES

# the module (the package's attribute `solve` is the function): the CLI imports `solve` from it when a command solves
solve_module = importlib.import_module("quasistatic.solve")

QUASISTATIC = Path(sys.executable).parent / "quasistatic"
HANG = 10.0  # [s] wall time: a subprocess still running after this has hung, and the test fails
# [s] bound on one rejection's CPU time, the whole process included. Typically 0.8 s, nearly all of it Python's
# imports (numpy, pydantic, HiGHS); before these fixes the alias bomb ran past 90 s and 2 GB.
FAST = 5.0

GOOD_YAML = """\
quasistatic: 1
dimension: 2
gravity: [0.0, -9.81]
bodies:
  box: {mass: 1.0, com: [0.0, 0.05]}
movers:
  table:
  hand: {robot: arm}
robots:
  arm: {joint_velocities: [0.01]}
contacts:
  - {body: box, other: table, point: [-0.05, 0.0], normal: [0.0, 1.0]}
  - {body: box, other: table, point: [0.05, 0.0], normal: [0.0, 1.0]}
  - {body: box, other: hand, point: [-0.05, 0.05], normal: [1.0, 0.0], jacobian: [[1.0], [0.0]]}
"""


def good_data() -> dict[str, Any]:
    """The scene of GOOD_YAML as a dict (what a JSON file holds)."""
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [0.0, -9.81],
        "bodies": {"box": {"mass": 1.0, "com": [0.0, 0.05]}},
        "movers": {"table": None, "hand": {"robot": "arm"}},
        "robots": {"arm": {"joint_velocities": [0.01]}},
        "contacts": [
            {"body": "box", "other": "table", "point": [-0.05, 0.0], "normal": [0.0, 1.0]},
            {"body": "box", "other": "table", "point": [0.05, 0.0], "normal": [0.0, 1.0]},
            {"body": "box", "other": "hand", "point": [-0.05, 0.05], "normal": [1.0, 0.0], "jacobian": [[1.0], [0.0]]},
        ],
    }


def alias_bomb(levels: int = 10, width: int = 9) -> str:
    """Nested YAML anchors, each a list of ``width`` aliases of the one before: ~600 bytes, ``width ** levels`` numbers."""
    text = "&a0 [" + ",".join(["1.0"] * width) + "]"
    for level in range(1, levels):
        text = f"&a{level} [{text}, " + ", ".join([f"*a{level - 1}"] * (width - 1)) + "]"
    return text


DEEP = 100_000
BOMB = alias_bomb()
JSON_DATA = json.dumps(good_data())


def _yaml(old: str, new: str) -> Callable[[Path], Path]:
    """A case: GOOD_YAML with one piece of text replaced."""
    assert old in GOOD_YAML, old
    return lambda folder: _write(folder / "scene.yaml", GOOD_YAML.replace(old, new, 1))


def _json(old: str, new: str) -> Callable[[Path], Path]:
    """A case: the JSON of good_data() with one piece of text replaced."""
    assert old in JSON_DATA, old
    return lambda folder: _write(folder / "scene.json", JSON_DATA.replace(old, new, 1))


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def _sparse_file(folder: Path) -> Path:
    """A file one byte past the size limit (sparse: no time spent writing it)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "huge.yaml"
    with path.open("wb") as stream:
        stream.truncate(MAX_FILE_BYTES + 1)
    return path


def _million_vertex_polygon(folder: Path) -> Path:
    """A planar polygon of a million vertices in YAML's flow style (14 MB: under the size limit)."""
    corners = ", ".join(f"[{math.cos(k * 2e-6 * math.pi):.2f}, {math.sin(k * 2e-6 * math.pi):.2f}]" for k in range(1_000_000))
    return _write(folder / "polygon.yaml", f"quasistatic: 1\ndimension: 2\nbodies:\n  a: {{mass: 1, shape: {{polygon: [{corners}]}}}}\n")


def _million_entry_list(folder: Path) -> Path:
    """A block-style YAML list of 1.1 million entries (4.4 MB)."""
    return _write(folder / "list.yaml", "quasistatic: 1\ngravity:\n" + "- 0\n" * 1_100_000)


# case -> (how to make the file, the field the error names, fragments of the error line)
CASES: dict[str, tuple[Callable[[Path], Path], str, tuple[str, ...]]] = {
    # 1. alias bombs ("billion laughs"): never expanded, rejected as they are composed
    "bomb-gravity": (_yaml("gravity: [0.0, -9.81]", f"gravity: {BOMB}"), "gravity", (f"{MAX_VALUES:,} values", "aliases")),
    "bomb-com": (_yaml("com: [0.0, 0.05]", f"com: {BOMB}"), "bodies.box.com", (f"{MAX_VALUES:,} values",)),
    "bomb-joints": (_yaml("joint_velocities: [0.01]", f"joint_velocities: {BOMB}"), "robots.arm.joint_velocities", ("values",)),
    "alias-cycle": (_yaml("gravity: [0.0, -9.81]", "gravity: &g [0.0, *g]"), "gravity[1]", ("alias", "'*g'")),
    # 2. nesting 100,000 deep
    "deep-json": (_json('"gravity": [0.0, -9.81]', '"gravity": ' + "[" * DEEP + "]" * DEEP), "gravity[0]", (f"deeper than {MAX_DEPTH}",)),
    "deep-yaml": (_yaml("gravity: [0.0, -9.81]", "gravity: " + "[" * DEEP + "]" * DEEP), "gravity[0]", (f"deeper than {MAX_DEPTH}",)),
    "deep-yaml-map": (_yaml("gravity: [0.0, -9.81]", "gravity: " + "{a: " * DEEP + "1" + "}" * DEEP), "gravity.a.a", ("deeper",)),
    # 3. numbers beyond what the numerics carry
    "mu-1e308": (_json('"normal": [0.0, 1.0]}', '"normal": [0.0, 1.0], "mu": 1e308}'), "contacts[0].mu", (f"{MAX_FRICTION:g}", "1e+308")),
    "mu-1e6": (_yaml("normal: [0.0, 1.0]}", "normal: [0.0, 1.0], mu: 1.0e+6}"), "contacts[0].mu", (f"{MAX_FRICTION:g}",)),
    "mass-1e308": (_yaml("mass: 1.0", "mass: 1.0e+308"), "bodies.box.mass", (f"{MAX_MAGNITUDE:g}", "1e+308")),
    "gravity-1e200": (_json('"gravity": [0.0, -9.81]', '"gravity": [0.0, -1e200]'), "gravity", (f"{MAX_MAGNITUDE:g}",)),
    "point-1e31": (_yaml("point: [0.05, 0.0]", "point: [1.0e+31, 0.0]"), "contacts[1].point", (f"{MAX_MAGNITUDE:g}",)),
    "integer-5000-digits": (_json('"mass": 1.0', '"mass": ' + "9" * 5000), "bodies.box.mass", ("finite",)),
    "pyramid-1e8": (_yaml("dimension: 2", "dimension: 3\nfriction: pyramid:100000000"), "friction", ("3 to 64 edges",)),
    "pyramid-superscript": (_yaml("dimension: 2", "dimension: 3\nfriction: pyramid:\u00b2"), "friction", ("integer number of edges",)),
    # 4. files without end
    "dev-zero": (lambda folder: Path("/dev/zero"), "", ("larger than 16 MiB", "/dev/zero")),
    "file-too-large": (_sparse_file, "", ("larger than 16 MiB",)),
    # 4b. a million values in a YAML file under the size limit: refused before PyYAML composes them (10 s)
    "yaml-polygon-1e6": (_million_vertex_polygon, "", (f"more than {MAX_VALUES:,} values by line 4", "[")),
    "yaml-list-1e6": (_million_entry_list, "", (f"more than {MAX_VALUES:,} values by line {MAX_VALUES + 2}", "'- 0'")),
    # 5. duplicate keys
    "duplicate-json": (_json('"mass": 1.0', '"mass": 1.0, "mass": 2.0'), "bodies.box.mass", ("given twice", "'mass'")),
    "duplicate-yaml": (_yaml("dimension: 2\n", "dimension: 2\ndimension: 3\n"), "dimension", ("given twice", "'dimension'")),
    "duplicate-yaml-nested": (_yaml("normal: [0.0, 1.0]}", "normal: [0.0, 1.0], normal: [0.0, 1.0]}"), "contacts[0].normal", ("twice",)),
    # 6. the format version is the integer 1
    "version-true": (_yaml("quasistatic: 1", "quasistatic: true"), "quasistatic", ("version", "integer 1", "True")),
    "version-float": (_json('"quasistatic": 1', '"quasistatic": 1.0'), "quasistatic", ("version", "integer 1", "1.0")),
    "version-text": (_yaml("quasistatic: 1", "quasistatic: '1'"), "quasistatic", ("version", "'1'")),
    # 7. names are printable
    "name-newline": (_yaml("  box: {mass", '  "bo\\nx": {mass'), "bodies", ("printable", "'bo\\nx'")),
    "name-escape": (_json('"other": "table"', '"other": "ta\\u001b[31mble"'), "contacts[0].other", ("printable", "\\x1b")),
    "name-tab": (_yaml("table:\n", '"ta\\tble":\n'), "movers", ("printable",)),
    # 9. the library's words, not its class names
    "contact-not-a-mapping": (_yaml("contacts:\n", "contacts:\n  - 1\n"), "contacts[0]", ("mapping with keys body, other",)),
}  # fmt: skip

# The cases run through the console script too (each process takes ~0.6 s, so not all of them: the rest differ
# only in the field, which the library tests below cover); the others run through qs.load_scene only.
CLI_CASES = [
    "bomb-gravity", "bomb-com", "bomb-joints", "deep-json", "deep-yaml", "mu-1e308", "mass-1e308", "gravity-1e200",
    "integer-5000-digits", "dev-zero", "file-too-large", "yaml-polygon-1e6", "yaml-list-1e6",
    "duplicate-json", "duplicate-yaml", "version-true",
    "name-newline", "name-escape", "contact-not-a-mapping",
]  # fmt: skip


def run_cli(*args: str) -> tuple[subprocess.CompletedProcess[str], float]:
    """Run the installed console script; its result and CPU time [s]. Past HANG seconds the test fails."""
    run = run_console([str(QUASISTATIC), *args], HANG)
    return run.result, run.cpu_seconds


@pytest.fixture(scope="module")
def case_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("hostile")
    return {name: make(root / name) for name, (make, _, _) in CASES.items()}


@pytest.fixture(scope="module")
def cli_runs(case_files: dict[str, Path]) -> dict[tuple[str, str], tuple[subprocess.CompletedProcess[str], float]]:
    """Every CLI case through ``check`` and ``solve``, two processes at a time (the file's budget is ~30 s)."""
    jobs = [(name, command) for name in CLI_CASES for command in ("check", "solve")]
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda job: run_cli(job[1], str(case_files[job[0]])), jobs))
    return dict(zip(jobs, results, strict=True))


def assert_one_error_line(result: subprocess.CompletedProcess[str], cpu_seconds: float, field: str, *fragments: str) -> str:
    """Exit 2, empty stdout, one ``error:`` line naming ``field`` (first) and every fragment, within FAST CPU seconds."""
    assert "Traceback" not in result.stderr, result.stderr[-2000:]
    assert result.returncode == 2, (result.returncode, result.stderr[-2000:])
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr[-2000:]
    line = lines[0]
    assert line.startswith(f"error: {field}"), line
    for fragment in fragments:
        assert fragment in line, (fragment, line)
    assert len(line) < 400, line
    assert cpu_seconds < FAST, f"{cpu_seconds:.1f} s of CPU"
    return line


# --------------------------------------------------------------------------- the console script


@pytest.mark.parametrize("case", ["yaml-polygon-1e6", "yaml-list-1e6"])
def test_a_yaml_file_of_a_million_values_is_refused_in_well_under_the_old_ten_seconds(cli_runs: dict[Any, Any], case: str) -> None:
    """Composed by PyYAML up to the value limit, a million-vertex polygon took 10 s of CPU (17 s on a busy machine);
    counted by a regular expression first, 0.8 s, nearly all of it the process's imports."""
    for command in ("check", "solve"):
        _, cpu_seconds = cli_runs[(case, command)]
        assert cpu_seconds < FAST, f"{command}: {cpu_seconds:.1f} s of CPU"


@pytest.mark.parametrize("command", ["check", "solve"])
@pytest.mark.parametrize("case", CLI_CASES)
def test_hostile_file_is_one_error_line(cli_runs: dict[Any, Any], case: str, command: str) -> None:
    _, field, fragments = CASES[case]
    result, cpu_seconds = cli_runs[(case, command)]
    line = assert_one_error_line(result, cpu_seconds, field, *fragments)
    assert "File" not in line  # no internal class name (_ContactFile, _SceneFile)


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (("solve", "SCENE", "--max-solutions", "0"), ("--max-solutions", "at least 1", "(got 0)")),
        (("solve", "SCENE", "--max-solutions", "many"), ("--max-solutions",)),
        (("solve", "SCENE", "--bogus"), ("No such option", "--bogus")),
        (("solve",), ("Missing argument", "SCENE")),
        (("check",), ("Missing argument", "SCENE")),
        (("sovle", "SCENE"), ("No such command", "sovle")),
    ],
    ids=["max-solutions-0", "max-solutions-text", "unknown-option", "solve-no-file", "check-no-file", "unknown-command"],
)
def test_bad_option_is_one_error_line(tmp_path: Path, args: tuple[str, ...], fragments: tuple[str, ...]) -> None:
    scene = _write(tmp_path / "scene.yaml", GOOD_YAML)
    result, cpu_seconds = run_cli(*[str(scene) if a == "SCENE" else a for a in args])
    assert_one_error_line(result, cpu_seconds, "", *fragments)


def test_valid_scene_at_the_limits_solves_with_strict_json(tmp_path: Path) -> None:
    """Numbers at MAX_MAGNITUDE and mu at MAX_FRICTION are valid: an audited answer, and JSON without Infinity or NaN."""
    data = good_data()
    data["bodies"]["box"]["mass"] = MAX_MAGNITUDE
    data["contacts"][0]["mu"] = MAX_FRICTION
    result, _ = run_cli("solve", "--json", str(_write(tmp_path / "scene.json", json.dumps(data))))
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""

    def refuse(constant: str) -> Any:
        raise AssertionError(f"{constant} in the JSON output")

    answer = json.loads(result.stdout, parse_constant=refuse)
    assert answer["audit"]["passed"] is True, answer["message"]


def test_the_console_script_exists() -> None:
    assert QUASISTATIC.exists(), f"install the package (pip install -e .): {QUASISTATIC} is missing"


# --------------------------------------------------------------------------- the command line in-process


def _runner() -> CliRunner:
    try:  # click < 8.2 mixes stderr into stdout unless told not to
        return CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        return CliRunner()


def test_solver_crash_is_one_error_line_and_exit_1(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A SolverError is not bad input: exit 1, still one line."""

    def crash(scene: qs.Scene, **kwargs: Any) -> qs.Solution:
        raise qs.SolverError("scip", "SCIP failed: error in input data!")

    monkeypatch.setattr(solve_module, "solve", crash)
    result = _runner().invoke(cli.app, ["solve", str(_write(tmp_path / "scene.yaml", GOOD_YAML))])
    assert result.exit_code == 1
    assert result.stderr.splitlines() == ["error: scip: SCIP failed: error in input data!"]
    assert result.stdout == ""


def test_non_finite_answer_is_never_printed_as_json(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = qs.Solution.to_dict
    monkeypatch.setattr(qs.Solution, "to_dict", lambda self: {**real(self), "power": math.inf})
    result = _runner().invoke(cli.app, ["solve", "--json", str(_write(tmp_path / "scene.yaml", GOOD_YAML))])
    assert result.exit_code == 1
    assert result.stdout == ""
    assert len(result.stderr.splitlines()) == 1 and "not finite" in result.stderr


def test_unexpected_exception_in_main_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not bad input and not a SolverError: a bug. Still one line (with its type), exit 1."""

    def bug(scene: qs.Scene, **kwargs: Any) -> qs.Solution:
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(solve_module, "solve", bug)
    monkeypatch.setattr(sys, "argv", ["quasistatic", "solve", str(_write(tmp_path / "scene.yaml", GOOD_YAML))])
    with pytest.raises(SystemExit) as info:
        cli.main()
    assert info.value.code == 1
    captured = capsys.readouterr()
    assert captured.err.splitlines() == ["error: internal error, please report it: ZeroDivisionError: division by zero"]
    assert captured.out == ""


# --------------------------------------------------------------------------- the library


@pytest.mark.parametrize("case", sorted(CASES))
def test_load_scene_raises_scene_error(case_files: dict[str, Path], case: str) -> None:
    _, field, fragments = CASES[case]
    started = time.process_time()
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(case_files[case])
    assert time.process_time() - started < FAST
    assert info.value.field.startswith(field)
    for fragment in fragments:
        assert fragment in str(info.value), (fragment, str(info.value))


def _nested(depth: int) -> list[Any]:
    value: list[Any] = []
    for _ in range(depth):
        value = [value]
    return value


def _shared(levels: int) -> list[Any]:
    """The alias bomb as Python data: each level holds the one below nine times (one object, not copies)."""
    value: list[Any] = [1.0] * 9
    for _ in range(levels):
        value = [value] * 9
    return value


def _self_referencing() -> list[Any]:
    loop: list[Any] = [0.0]
    loop.append(loop)
    return loop


@pytest.mark.parametrize(
    ("mutate", "field", "fragment"),
    [
        (lambda d: d.__setitem__("gravity", _nested(DEEP)), "gravity[0]", "deeper"),
        (lambda d: d["bodies"].__setitem__("box", {"mass": 1.0, "com": _nested(DEEP)}), "bodies.box.com[0]", "deeper"),
        (lambda d: d.__setitem__("gravity", _shared(12)), "gravity", "values"),
        (lambda d: d.__setitem__("gravity", _self_referencing()), "gravity[1]", "deeper"),
        (lambda d: d.__setitem__("quasistatic", True), "quasistatic", "integer 1"),
        (lambda d: d["bodies"]["box"].__setitem__("mass", 10**400), "bodies.box.mass", "expected a number"),
        (lambda d: d["bodies"]["box"].__setitem__("mass", 1e31), "bodies.box.mass", "1e+30"),
        (lambda d: d["contacts"][0].__setitem__("mu", 1e308), "contacts[0].mu", "at most 1000"),
        (lambda d: d["contacts"][0].__setitem__("body", "b\x1bx"), "contacts[0].body", "printable"),
        (lambda d: d["movers"].__setitem__("x" * 10_000, None), "movers", "at most 256"),
        (lambda d: d["contacts"].__setitem__(0, 1), "contacts[0]", "mapping with keys"),
    ],
    ids=["deep", "deep-com", "shared-lists", "cycle", "version-true", "int-1e400", "mass-1e31", "mu", "name-escape", "long-name", "words"],
)
def test_load_scene_of_hostile_data_raises_scene_error(mutate: Callable[[dict[str, Any]], None], field: str, fragment: str) -> None:
    data = good_data()
    mutate(data)
    started = time.process_time()
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(data)
    assert time.process_time() - started < FAST
    assert info.value.field.startswith(field), str(info.value)
    assert fragment in str(info.value)
    assert len(str(info.value)) < 400


def test_scene_error_message_is_bounded_whatever_the_value() -> None:
    """The message's repr never materialises the value: 9 ** 30 numbers, a 1e6-character name, a 10 ** 5000 integer."""
    started = time.process_time()  # CPU time: a busy machine stretches the wall clock, not this
    for value in (_shared(30), "x" * 1_000_000, 10**5000, _self_referencing(), {"k": _nested(DEEP)}):
        message = str(qs.SceneError("a" * 1000, value, "bad"))
        assert len(message) < 300, message
    assert time.process_time() - started < 1.0


# --------------------------------------------------------------------------- fuzzing: hostile text


_NAMES = st.sampled_from(["box", "table", "b\nx", "b\x1bx", "b\tx", "\u202ebox", "x" * 300, "", "b\x00x", "ok name"])
_NUMBER_TEXT = st.one_of(
    st.sampled_from(["1.0e+308", "-1.0e+308", "1e308", "1.0e+31", "1.0e+30", "1.0e-300", ".nan", ".inf", "NaN", "Infinity"]),
    st.integers(min_value=1, max_value=6000).map(lambda n: "9" * n),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
)


@st.composite
def _hostile_value(draw: st.DrawFn, yaml_text: bool) -> str:
    """Text of one hostile value: nesting, an alias bomb or cycle (YAML), a number, a name or a duplicated key."""
    kind = draw(st.sampled_from(["nested", "mapping", "number", "list", "name", "duplicate", *(["bomb", "cycle"] if yaml_text else [])]))
    depth = draw(st.integers(min_value=0, max_value=3 * MAX_DEPTH))
    if kind == "nested":
        return "[" * depth + draw(_NUMBER_TEXT) + "]" * depth
    if kind == "mapping":
        key = "a: " if yaml_text else '"a": '
        return ("{" + key) * depth + "1" + "}" * depth
    if kind == "number":
        return draw(_NUMBER_TEXT)
    if kind == "list":
        return "[" + ", ".join(draw(st.lists(_NUMBER_TEXT, max_size=8))) + "]"
    if kind == "name":
        return json.dumps(draw(_NAMES))
    if kind == "duplicate":
        key = "x: 1, x: 2" if yaml_text else '"x": 1, "x": 2'
        return "{" + key + "}"
    if kind == "bomb":
        return alias_bomb(draw(st.integers(min_value=1, max_value=12)), draw(st.integers(min_value=1, max_value=12)))
    return "&c [1.0, *c]"


_SLOTS = [
    ("gravity: [0.0, -9.81]", "gravity: {}"),
    ("mass: 1.0", "mass: {}"),
    ("com: [0.0, 0.05]", "com: {}"),
    ("joint_velocities: [0.01]", "joint_velocities: {}"),
    ("normal: [0.0, 1.0]}", "normal: [0.0, 1.0], mu: {}}"),
    ("quasistatic: 1", "quasistatic: {}"),
    ("  box: {mass", "  {}: {{mass"),
    ("other: table", "other: {}"),
    ("dimension: 2\n", "dimension: 2\nfriction: {}\n"),
]


def _json_slot(yaml_old: str, yaml_new: str) -> tuple[str, str]:
    """The JSON spelling of a YAML slot of GOOD_YAML, for JSON_DATA."""
    table = {
        "gravity: [0.0, -9.81]": ('"gravity": [0.0, -9.81]', '"gravity": {}'),
        "mass: 1.0": ('"mass": 1.0', '"mass": {}'),
        "com: [0.0, 0.05]": ('"com": [0.0, 0.05]', '"com": {}'),
        "joint_velocities: [0.01]": ('"joint_velocities": [0.01]', '"joint_velocities": {}'),
        "normal: [0.0, 1.0]}": ('"normal": [0.0, 1.0]}', '"normal": [0.0, 1.0], "mu": {}}'),
        "quasistatic: 1": ('"quasistatic": 1', '"quasistatic": {}'),
        "  box: {mass": ('"box": {"mass"', '{}: {{"mass"'),
        "other: table": ('"other": "table"', '"other": {}'),
        "dimension: 2\n": ('"dimension": 2', '"dimension": 2, "friction": {}'),
    }
    return table[yaml_old]


@st.composite
def hostile_texts(draw: st.DrawFn) -> tuple[str, str]:
    """``(suffix, text)``: the good scene with one to three slots filled with hostile values, as YAML or JSON."""
    yaml_text = draw(st.booleans())
    text = GOOD_YAML if yaml_text else JSON_DATA
    for old, new in draw(st.lists(st.sampled_from(_SLOTS), min_size=1, max_size=3, unique=True)):
        if not yaml_text:
            old, new = _json_slot(old, new)
        value = draw(_hostile_value(yaml_text))
        if "{}:" in new and not value.startswith('"'):
            value = json.dumps(value)  # a key must stay a key
        text = text.replace(old, new.replace("{}", value, 1), 1)
    return (".yaml" if yaml_text else ".json"), text


@pytest.fixture(scope="module")
def fuzz_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


@settings(max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(hostile_texts())
def test_hostile_text_loads_or_raises_scene_error(fuzz_folder: Path, case: tuple[str, str]) -> None:
    """Whatever the text: a Scene or a SceneError, within the deadline; never another exception, a hang or a blow-up."""
    suffix, text = case
    path = _write(fuzz_folder / f"scene{suffix}", text)
    try:
        scene = qs.load_scene(path)
    except qs.SceneError as err:
        assert isinstance(err.field, str)
        assert len(str(err)) < 400, str(err)
        return
    assert isinstance(scene, qs.Scene)
    numbers = [scene.gravity, *(b.com for b in scene.bodies), *(c.point for c in scene.contacts)]
    assert all(abs(float(x)) <= MAX_MAGNITUDE for array in numbers for x in array)
    assert all(name.isprintable() for name in (b.name for b in scene.bodies))
