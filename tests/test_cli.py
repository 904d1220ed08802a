"""The command line (demo, solve, check) and the example scenes it ships with."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

import quasistatic as qs
from quasistatic import cli

# the module (the package's attribute `solve` is the function): the CLI imports `solve` from it when a command solves
solve_module = importlib.import_module("quasistatic.solve")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
EXAMPLE_FILES = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".yml", ".json"))
DEMO = ROOT / "src" / "quasistatic" / "examples" / "two_finger_lift.yaml"

# The status each example's header comment promises.
EXPECTED_STATUS = {
    "box_push_3d.yaml": "ambiguous",
    "box_push_shapes.yaml": "ambiguous",
    "puck_push_3d.yaml": "solved",
    "push_up_slope.yaml": "solved",
    "push_up_slope_shapes.yaml": "solved",
    "push_into_wall.yaml": "jammed",
    "compliant_grasp.yaml": "jammed",
    "robot_tip.json": "solved",
    "robot_tip.yaml": "solved",
    "squeeze.yaml": "solved",
    "topple.yaml": "unstable",
    "two_finger_lift.yaml": "solved",
}


def _runner() -> CliRunner:
    try:  # click < 8.2 mixes stderr into stdout unless told not to
        return CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        return CliRunner()


def invoke(*args: str) -> Any:
    return _runner().invoke(cli.app, [str(a) for a in args])


def _write(tmp_path: Path, text: str, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


GOOD_SCENE = """\
quasistatic: 1
dimension: 2
bodies:
  box: {mass: 1.0, com: [0.0, 0.05]}
movers:
  table:
contacts:
  - {body: box, other: table, point: [-0.05, 0.0], normal: [0.0, 1.0]}
  - {body: box, other: table, point: [0.05, 0.0], normal: [0.0, 1.0]}
"""


# --------------------------------------------------------------------------- demo


def test_demo_exits_0_and_prints_the_answer() -> None:
    result = invoke("demo")
    assert result.exit_code == 0, result.output
    assert "status: solved" in result.stdout
    assert "2.4525" in result.stdout
    assert "passed" in result.stdout
    assert "-0 " not in result.stdout and "-0]" not in result.stdout and "-0," not in result.stdout


def test_demo_json_is_the_documented_answer() -> None:
    result = invoke("demo", "--json")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["status"] == "solved"
    np.testing.assert_allclose(data["bodies"]["box"]["twist"], [0.0, 0.01, 0.0], atol=1e-12)
    assert [c["mode"] for c in data["contacts"][:2]] == ["rolling", "rolling"]
    assert [c["normal_force"] for c in data["contacts"][:2]] == pytest.approx([2.4525, 2.4525], rel=1e-9)
    assert data["audit"]["passed"] is True


def test_packaged_demo_matches_the_copy_in_examples() -> None:
    assert DEMO.read_text(encoding="utf-8") == (EXAMPLES / "two_finger_lift.yaml").read_text(encoding="utf-8")


# --------------------------------------------------------------------------- solve


# The twist each solved example's header comment derives (com velocity, then angular velocity).
EXPECTED_TWISTS = {
    "puck_push_3d.yaml": {"puck": [0.01 * np.cos(np.pi / 6), 0.005, 0.0, 0.0, 0.0, 0.0]},
    "push_up_slope.yaml": {"block": [0.01 * np.cos(np.radians(20.0)), 0.01 * np.sin(np.radians(20.0)), 0.0]},
    "push_up_slope_shapes.yaml": {"block": [0.01 * np.cos(np.radians(20.0)), 0.01 * np.sin(np.radians(20.0)), 0.0]},
    "robot_tip.json": {"box": [-0.003, 0.003, 0.06]},
    "robot_tip.yaml": {"box": [-0.003, 0.003, 0.06]},
    "squeeze.yaml": {"box": [0.0, 0.0, 0.0]},
    "two_finger_lift.yaml": {"box": [0.0, 0.01, 0.0]},
}


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_solve_json_equals_the_library_answer(path: Path) -> None:
    """The JSON is the library's answer, and that answer is the one the example's header derives."""
    result = invoke("solve", path, "--json")
    assert result.exit_code == 0, result.output
    printed = json.loads(result.stdout)  # stdout holds the JSON and nothing else
    assert printed["status"] == EXPECTED_STATUS[path.name], printed["message"]
    for name, twist in EXPECTED_TWISTS.get(path.name, {}).items():
        np.testing.assert_allclose(printed["bodies"][name]["twist"], twist, rtol=0, atol=1e-9)
    expected = qs.solve(qs.load_scene(path)).to_dict()
    assert printed.keys() == expected.keys()
    assert printed["status"] == expected["status"]
    assert printed["bodies"].keys() == expected["bodies"].keys()
    for name, body in expected["bodies"].items():
        np.testing.assert_allclose(printed["bodies"][name]["twist"], body["twist"], rtol=0, atol=1e-9)
    assert [c["mode"] for c in printed["contacts"]] == [c["mode"] for c in expected["contacts"]]


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_solve_table_prints_status_and_exits_0(path: Path) -> None:
    result = invoke("solve", path)
    assert result.exit_code == 0, result.output
    assert f"status: {EXPECTED_STATUS[path.name]}" in result.stdout


def test_ambiguous_lists_every_solution() -> None:
    """The frictionless box of box_push_3d.yaml may run ahead of the finger (+x only), slide sideways and spin
    about the vertical (either way): one unbounded continuum, listed with its free directions and extremes."""
    result = invoke("solve", EXAMPLES / "box_push_3d.yaml")
    assert result.exit_code == 0, result.output
    text = " ".join(result.stdout.split())
    assert "motion 1: continuum (unbounded: box v_x +, box v_y -, box v_y +, box omega_z -, box omega_z +)" in text
    assert "extreme twists" in result.stdout


def test_indeterminate_forces_show_their_ranges() -> None:
    result = invoke("solve", EXAMPLES / "squeeze.yaml")
    assert result.exit_code == 0, result.output
    assert "f_n range" in result.stdout
    assert "[0, 4.0875]" in result.stdout


def test_modes_and_options_are_passed_to_solve(monkeypatch: pytest.MonkeyPatch) -> None:
    seen: dict[str, Any] = {}
    real_solve = qs.solve

    def spy(scene: qs.Scene, **kwargs: Any) -> qs.Solution:
        seen.update(kwargs)
        return real_solve(scene, method=kwargs["method"], max_solutions=kwargs["max_solutions"])

    monkeypatch.setattr(solve_module, "solve", spy)
    args = ("--modes", "rolling, rolling,free,SLIDING", "--method", "lp", "--max-solutions", "3", "--time-limit", "7.5")
    result = invoke("solve", DEMO, *args)
    assert result.exit_code == 0, result.output
    progress = seen.pop("progress")
    assert callable(progress)
    expected = {
        "method": "lp",
        "modes": ["rolling", "rolling", None, "sliding"],
        "max_solutions": 3,
        "all_solutions": False,
        "time_limit": 7.5,
    }
    assert seen == expected
    invoke("solve", DEMO)
    assert seen["all_solutions"] is True  # the command line certifies by default
    invoke("solve", DEMO, "--first-solution")
    assert seen["all_solutions"] is False


def test_failed_status_exits_1(monkeypatch: pytest.MonkeyPatch) -> None:
    failed = qs.Solution("failed", "failed: the backend gave up", "lp", "exact")
    monkeypatch.setattr(solve_module, "solve", lambda scene, **kwargs: failed)
    result = invoke("solve", DEMO)
    assert result.exit_code == 1
    assert "status: failed" in result.stdout
    assert invoke("solve", DEMO, "--json").exit_code == 1


# --------------------------------------------------------------------------- check


def test_check_valid_file(tmp_path: Path) -> None:
    result = invoke("check", _write(tmp_path, GOOD_SCENE))
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == "ok: 1 bodies, 1 movers, 2 contacts, dimension 2, friction exact"


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_check_every_example(path: Path) -> None:
    result = invoke("check", path)
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("ok: ")


# --------------------------------------------------------------------------- bad input


def _assert_one_line_error(result: Any, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    for fragment in fragments:
        assert fragment in lines[0]
    assert result.stdout == ""


BAD_SCENES = {
    "typo": (GOOD_SCENE.replace("dimension: 2", "dimension: 2\ngravty: [0.0, -9.81]"), ("did you mean", "'gravity'")),
    "typo_in_contact": (
        GOOD_SCENE.replace("normal: [0.0, 1.0]}", "normal: [0.0, 1.0], muu: 0.0}", 1),
        ("did you mean", "'mu'"),
    ),
    "nan_normal": (
        GOOD_SCENE.replace("normal: [0.0, 1.0]}", "normal: [.nan, 1.0]}", 1),
        ("contacts[0].normal", "finite"),
    ),
    "invalid_yaml": ("quasistatic: 1\nbodies: [unclosed\n", ("not valid YAML",)),
    "not_a_mapping": ("- just\n- a list\n", ("mapping",)),
    "bad_version": (GOOD_SCENE.replace("quasistatic: 1", "quasistatic: 7"), ("version",)),
}


@pytest.mark.parametrize("command", ["check", "solve"])
@pytest.mark.parametrize("case", sorted(BAD_SCENES))
def test_bad_scene_exits_2_with_one_line(tmp_path: Path, command: str, case: str) -> None:
    text, fragments = BAD_SCENES[case]
    _assert_one_line_error(invoke(command, _write(tmp_path, text)), *fragments)


@pytest.mark.parametrize(
    "text",
    [GOOD_SCENE.replace("bodies:", "bodeis:"), GOOD_SCENE.replace("normal: [0.0, 1.0]}", "normall: [0.0, 1.0]}", 1)],
    ids=["bodies", "normal"],
)
def test_misspelled_required_key_suggests_the_right_one(tmp_path: Path, text: str) -> None:
    _assert_one_line_error(invoke("check", _write(tmp_path, text)), "did you mean")


def test_invalid_json_exits_2(tmp_path: Path) -> None:
    _assert_one_line_error(invoke("solve", _write(tmp_path, '{"quasistatic": 1,', "scene.json")), "not valid JSON")


@pytest.mark.parametrize("command", ["check", "solve"])
def test_missing_file_exits_2(tmp_path: Path, command: str) -> None:
    _assert_one_line_error(invoke(command, tmp_path / "no-such-scene.yaml"), "cannot read")


def test_unknown_method_exits_2() -> None:
    _assert_one_line_error(invoke("solve", DEMO, "--method", "simplexx"), "unknown method")


@pytest.mark.parametrize(("modes", "fragment"), [("rolling,skidding,free,free", "skidding"), ("rolling", "4 entries")])
def test_bad_modes_exit_2(modes: str, fragment: str) -> None:
    _assert_one_line_error(invoke("solve", DEMO, "--modes", modes), fragment)


def test_frictional_scene_without_a_frictional_solver_is_an_error_not_a_crash(tmp_path: Path) -> None:
    scene = _write(tmp_path, GOOD_SCENE.replace("normal: [0.0, 1.0]}", "normal: [0.0, 1.0], mu: 0.5}"))
    result = invoke("solve", scene, "--method", "lp")
    _assert_one_line_error(result, "mu > 0")


# --------------------------------------------------------------------------- examples


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_every_example_solves_with_an_audited_result(path: Path) -> None:
    solution = qs.solve(qs.load_scene(path))
    assert solution.status == EXPECTED_STATUS[path.name], solution.message
    if solution.status in ("solved", "ambiguous"):
        assert solution.motion is not None and solution.audit is not None
        assert solution.audit.passed, solution.audit.failures()
        assert all(m.audit.passed for m in solution.solutions)
    else:
        assert solution.motion is None


def test_examples_cover_the_listed_cases() -> None:
    assert {p.name for p in EXAMPLE_FILES} == set(EXPECTED_STATUS)
    assert {name for name, status in EXPECTED_STATUS.items() if status == "solved"} == set(EXPECTED_TWISTS)
    assert set(EXPECTED_STATUS.values()) == {"solved", "ambiguous", "jammed", "unstable"}


@pytest.mark.parametrize("name", ["robot_tip.yaml", "robot_tip.json"])
def test_robot_tip_matches_its_header(name: str) -> None:
    solution = qs.solve(qs.load_scene(EXAMPLES / name))
    assert solution.status == "solved" and not solution.forces_indeterminate
    np.testing.assert_allclose(solution.twists["box"], [-0.003, 0.003, 0.06], atol=1e-12)
    assert solution.modes == ("rolling", "rolling", "sliding")
    weight = 0.5 * 9.81
    forces = [c.normal_force for c in solution.contacts]
    np.testing.assert_allclose(forces, [0.5 * weight, 0.375 * weight, 0.625 * weight], rtol=1e-9)
    np.testing.assert_allclose(solution.contacts[2].slip, [-0.004, -0.003], atol=1e-12)
    assert solution.power is not None
    assert solution.power.input == pytest.approx(0.014715, rel=1e-9)


def test_squeeze_matches_its_header() -> None:
    solution = qs.solve(qs.load_scene(EXAMPLES / "squeeze.yaml"))
    assert solution.status == "solved" and solution.forces_indeterminate
    np.testing.assert_allclose(solution.twists["box"], [0.0, 0.0, 0.0], atol=1e-12)
    ranges = [c.normal_force_range for c in solution.contacts]
    expected = [(2.4525, 4.905), (0.0, 2.4525), (0.0, 4.0875), (0.0, 4.0875)]
    for got, want in zip(ranges, expected, strict=True):
        assert got is not None and got[1] is not None
        assert got == pytest.approx(want, abs=1e-9)


def test_two_finger_lift_walls_have_unbounded_range() -> None:
    solution = qs.solve(qs.load_scene(DEMO))
    ranges = [c.normal_force_range for c in solution.contacts]
    assert ranges[0] == pytest.approx((2.4525, 2.4525)) and ranges[1] == pytest.approx((2.4525, 2.4525))
    assert ranges[2] is not None and ranges[2][1] is None
    assert ranges[3] is not None and ranges[3][1] is None


def test_every_documented_command_is_registered_and_answers_help() -> None:
    """The module's list of commands, the registered commands and the console script agree (a merge once dropped one)."""
    import re
    import subprocess
    import sys

    import quasistatic.cli as cli

    listed = re.search(r"``quasistatic ([a-z |]+)``", cli.__doc__ or "")
    assert listed is not None
    documented = {word.strip() for word in listed.group(1).split("|")}
    registered = {command.name or command.callback.__name__ for command in cli.app.registered_commands if command.callback}
    assert documented == registered
    result = subprocess.run(
        [sys.executable, "-c", "from quasistatic.cli import main; main()", "--help"], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0
    shown = set(re.findall(r"^\W*([a-z]+)\s", result.stdout, re.M))
    assert documented <= shown, documented - shown


def test_the_command_line_names_the_library_methods() -> None:
    assert cli.METHODS == qs.METHODS


def test_importing_the_package_and_its_cli_loads_no_solver() -> None:
    """A bad scene file or ``--help`` answers without SciPy, HiGHS, SCIP or numba (the package root is lazy)."""
    heavy = ("scipy", "highspy", "pyscipopt", "numba", "pinocchio", "coal", "matplotlib")
    # a None entry blocks an import (how tests simulate an install without numba): not loaded
    code = f"import sys, quasistatic, quasistatic.cli; print(' '.join(m for m in {heavy!r} if sys.modules.get(m) is not None))"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert loaded == []


def test_submodules_named_like_functions_leave_the_functions_in_place() -> None:
    code = (
        "import importlib, quasistatic as qs\n"
        "for name in ('solve', 'plan', 'sensitivity'):\n"
        "    importlib.import_module('quasistatic.' + name)\n"
        "    assert callable(getattr(qs, name)) and not isinstance(getattr(qs, name), type(qs)), name\n"
        "assert all(hasattr(qs, name) for name in qs.__all__) and set(qs.__all__) <= set(dir(qs))\n"
        "print('ok')"
    )
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "ok"


# Run in one subprocess, in this order: each command's argv, then what it may not have loaded (cumulative, so the
# commands that load less come first). A module-level import that brings one back fails here, with no timing.
_HEAVY = ("scipy", "numba", "matplotlib", "viser", "pyarrow", "dask", "quasistatic.solvers", "quasistatic.sim")
_LIGHT_COMMANDS: tuple[tuple[tuple[str, ...], tuple[str, ...]], ...] = (
    (("check", "examples/squeeze.yaml"), _HEAVY),
    (("solve", "examples/squeeze.yaml", "--max-solutions", "0"), _HEAVY),
    (("simulate", "examples/sim/tip_box.yaml", "--duration", "1", "--ambiguous", "x"), _HEAVY),
    (("sweep", "examples/box_push_3d.yaml", "--param", "mu"), (*_HEAVY, "quasistatic.sweeps.run")),
    (("sweep", "examples/box_push_3d.yaml", "--param", "contacts[9].mu=0:1:3"), (*_HEAVY, "quasistatic.sweeps.run")),
    (("plot", "examples/squeeze.yaml", "-o", "x.bmp"), (*_HEAVY, "quasistatic.viz.figures")),
    (("plot", "examples/squeeze.yaml", "-o", "x.png", "--view", "top"), (*_HEAVY, "quasistatic.viz.figures")),
    (("view", "examples/squeeze.yaml", "--view", "top"), (*_HEAVY, "quasistatic.viz.viewer")),
    (("animate", "run.npz", "-o", "x.avi"), (*_HEAVY, "quasistatic.viz.animation")),
    (("solve", "examples/two_finger_lift.yaml", "--json"), ("scipy.optimize", "matplotlib", "quasistatic.sim", "quasistatic.viz.figures")),
)


def test_commands_check_their_input_before_the_heavy_imports() -> None:
    """Bad options are refused before SciPy, matplotlib, sim/ or the solvers load; a plain solve needs no scipy.optimize."""
    code = (
        "import sys\nfrom quasistatic.cli import main\n"
        f"for argv, absent in {_LIGHT_COMMANDS!r}:\n"
        "    sys.argv = ['quasistatic', *argv]\n"
        "    try:\n        main()\n    except SystemExit as exc:\n        code = exc.code\n"
        "    print(code, *argv[:1], *(m for m in absent if sys.modules.get(m) is not None), file=sys.stderr)\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    lines = [line for line in result.stderr.splitlines() if not line.startswith("error:")]
    expected = ["0 check", *(f"2 {argv[0]}" for argv, _ in _LIGHT_COMMANDS[1:-1]), "0 solve"]
    assert lines == expected, result.stderr
