"""The real console script, run as a user runs it: ``--json`` prints JSON and nothing else.

An in-process CLI runner cannot see what a C library (HiGHS, SCIP) writes to
the process's stdout, so these tests run the installed ``quasistatic`` script
in a subprocess and parse its stdout as a whole.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = Path(sys.executable).parent / "quasistatic"
EXAMPLES = sorted((ROOT / "examples").glob("*.yaml")) + sorted((ROOT / "examples").glob("*.json"))

# What each example's comment says it shows (README's table).
EXPECTED = {
    "two_finger_lift.yaml": "solved",
    "robot_tip.yaml": "solved",
    "robot_tip.json": "solved",
    "squeeze.yaml": "solved",
    "push_up_slope.yaml": "solved",
    "push_up_slope_shapes.yaml": "solved",
    "puck_push_3d.yaml": "solved",
    "box_push_3d.yaml": "ambiguous",
    "box_push_shapes.yaml": "ambiguous",
    "push_into_wall.yaml": "jammed",
    "compliant_grasp.yaml": "jammed",
    "topple.yaml": "unstable",
}


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, timeout=300, cwd=ROOT)


def test_every_example_has_an_expectation() -> None:
    assert {p.name for p in EXAMPLES} == set(EXPECTED)


def test_demo_json_is_json_and_nothing_else() -> None:
    out = _run("demo", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)  # the whole of stdout: a banner line would break this
    assert data["status"] == "solved" and data["certified"] is True
    assert out.stderr == ""


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_json_is_json_and_nothing_else(path: Path) -> None:
    out = _run("solve", str(path), "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["status"] == EXPECTED[path.name], data["message"]
    assert out.stderr == ""  # no solver banner, warning or C-library line on success
    if data["status"] in ("jammed", "unstable"):
        assert data["certificate"] is not None and data["diagnosis"] is not None
    # No round-off noise: these scenes' speeds, forces and powers are 1e-3 and up, so a nonzero
    # value below 1e-12 can only be round-off (audit residuals and power residuals are measurements).
    noise = [(where, x) for where, x in _numbers(data) if x != 0.0 and abs(x) < 1e-12 and "audit" not in where and "residual" not in where]
    assert not noise, noise


def _numbers(value: object, where: str = "") -> list[tuple[str, float]]:
    """Every float in a JSON value with its path."""
    if isinstance(value, dict):
        return [item for key, v in value.items() for item in _numbers(v, f"{where}.{key}")]
    if isinstance(value, list):
        return [item for i, v in enumerate(value) for item in _numbers(v, f"{where}[{i}]")]
    return [(where, value)] if isinstance(value, float) else []


def test_jammed_names_its_blocking_contacts() -> None:
    """push_into_wall: the finger (#4) pushes the box into the wall's two corners (#2, #3); the floor (#0, #1) does not block."""
    out = _run("solve", str(ROOT / "examples" / "push_into_wall.yaml"))
    assert out.returncode == 0, out.stderr
    assert "blocking contacts: #2, #3, #4 " in out.stdout
    assert "units: those of the scene file" in out.stdout


def test_unstable_names_the_direction_of_the_fall() -> None:
    """topple: the weight acts left of the fingertip (x = 0.03 > com x = 0), so the box turns counter-clockwise (+z)."""
    out = _run("solve", str(ROOT / "examples" / "topple.yaml"), "--json")
    data = json.loads(out.stdout)
    assert data["certificate"]["kind"] == "ray"
    vx, vy, wz = data["certificate"]["data"]
    assert wz > 0 and max(abs(vx), abs(vy), abs(wz)) == 1.0
    text = _run("solve", str(ROOT / "examples" / "topple.yaml")).stdout
    assert "falls or accelerates along the twist" in text


def test_unbounded_continuum_names_its_free_directions() -> None:
    """box_push_3d (frictionless): gravity pins vz, wx, wy; the finger at the -x face's middle requires
    vx >= 0.01 (a spin about z moves that point along y only), and nothing bounds vx above, vy or wz."""
    out = _run("solve", str(ROOT / "examples" / "box_push_3d.yaml"), "--json")
    motion = json.loads(out.stdout)["solutions"][0]
    assert motion["unbounded"] is True
    assert set(motion["free_directions"]) == {"box v_x +", "box v_y +", "box v_y -", "box omega_z +", "box omega_z -"}


def test_time_limit_is_honoured_and_said() -> None:
    """A certified search cut short by --time-limit says so (exit 1: not an answer); a non-positive limit is bad input."""
    out = _run("solve", str(ROOT / "examples" / "puck_push_3d.yaml"), "--time-limit", "0.05")
    assert out.returncode == 1 and "time limit" in out.stdout
    bad = _run("solve", str(ROOT / "examples" / "puck_push_3d.yaml"), "--time-limit", "0")
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.startswith("error: --time-limit") and len(bad.stderr.splitlines()) == 1
