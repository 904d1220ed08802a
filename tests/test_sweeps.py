"""Sweeps: parameter paths, the grid's answers against the tip-or-slide law, refinement, backends, resume, tables, CLI."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.sweeps.backends as backends
from quasistatic.errors import BackendUnavailableError, SceneError
from quasistatic.sweeps import parse_param_spec, parse_path, sweep
from quasistatic.sweeps.result import require_pyarrow

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = Path(sys.executable).parent / "quasistatic"
# Box w = 0.2 m on two floor corners (mu = 0.5), pushed at height contacts[2].point[1]: it slides below
# h* = w / (2 mu) = 0.1 / mu and tips about its front corner above (validation/cases.yaml, case 4).
BOX = ROOT / "validation" / "scenes" / "box_push_high.yaml"
HEIGHT = "contacts[2].point[1]"
FLOOR_MU = "contacts[0].mu,contacts[1].mu"
SLIDES = ("sliding", "sliding", "rolling")
TIPS = ("separating", "rolling", "sliding")


def _tip_or_slide(**options: Any) -> qs.SweepResult:
    return sweep(BOX, {HEIGHT: np.linspace(0.06, 0.34, 4), FLOOR_MU: [0.25, 0.5, 0.8]}, **options)


# --------------------------------------------------------------------------- parameter paths


def test_paths_parse_into_keys_and_indices() -> None:
    assert parse_path("contacts[2].point[1]") == ("contacts", 2, "point", 1)
    assert parse_path("robots.hand.joint_velocities.j1") == ("robots", "hand", "joint_velocities", "j1")
    name, values = parse_param_spec("contacts[2].mu=0:1:101")
    assert name == "contacts[2].mu" and values.shape == (101,) and values[0] == 0.0 and values[-1] == 1.0
    assert parse_param_spec("bodies.box.mass=1,2.5")[1].tolist() == [1.0, 2.5]


@pytest.mark.parametrize(
    ("path", "words"),
    [
        ("contacts[7].mu", "index must be below 3"),
        ("contacts[2].mux", "unknown key"),
        ("bodies.crate.mass", "no key 'crate'"),
        ("bodies.box.com", "not a number"),
        ("movers.floor.twist[0]", "empty in the scene"),
        ("movers.pusher.twist[3]", "index must be below 3"),
        ("contacts.mu", "use an index"),
        ("bodies[0].mass", "not a list"),
        ("contacts[0]mu", "not a parameter path"),
    ],
)
def test_a_bad_path_is_a_scene_error_naming_it(path: str, words: str) -> None:
    with pytest.raises(SceneError, match=words) as info:
        sweep(BOX, {path: [0.1, 0.2]})
    assert info.value.field == path


def test_a_value_the_scene_rejects_names_the_path() -> None:
    with pytest.raises(SceneError, match="must be >= 0") as info:
        sweep(BOX, {"contacts[0].mu": [0.5, -0.1]})
    assert info.value.field == "contacts[0].mu" and info.value.value == -0.1


def test_named_joints_mover_twists_and_masses_reach_the_scene() -> None:
    data = qs.model.io.read_scene_data(ROOT / "examples" / "robot_tip.yaml")
    data["robots"]["arm"]["joint_names"] = ["shoulder", "elbow"]
    # The tipping box's twist is linear in the arm's joint velocities: doubling both doubles it.
    result = sweep(data, {"robots.arm.joint_velocities.shoulder,robots.arm.joint_velocities.elbow": [1.0, 2.0]})
    one, two = (dict(p.twists)["box"] for p in result.points)
    assert all(p.status == "solved" and p.certified for p in result.points)
    # joint velocities [1, 1] and [2, 2]: the second twist is twice the first
    assert np.allclose(np.array(two), 2 * np.array(one)) and np.any(np.array(one) != 0)
    pushed = sweep(BOX, {"movers.pusher.twist[0]": [0.01, 0.03], "bodies.box.mass": [2.0, 4.0]})
    twists = np.array([dict(p.twists)["box"] for p in pushed.points]).reshape(2, 2, 3)
    assert np.allclose(twists[1], 3 * twists[0])  # the tipping motion scales with the pusher's speed...
    assert np.allclose(twists[:, 1], twists[:, 0])  # ...and does not depend on the box's weight
    forces = np.array([p.forces[1][1] for p in pushed.points]).reshape(2, 2)
    assert np.allclose(forces[:, 1], 2 * forces[:, 0])  # the front corner carries the whole weight m g


# --------------------------------------------------------------------------- answers and refinement


def test_tip_or_slide_grid_follows_the_critical_height() -> None:
    result = _tip_or_slide()
    assert result.shape == (4, 3) and len(result.points) == 12 and not result.refined
    for point in result.points:
        height, mu = point.values
        assert point.status == "solved" and point.certified
        assert point.modes == (SLIDES if height < 0.1 / mu else TIPS), point.values
    assert result.statuses().shape == (4, 3)


def test_refinement_brackets_the_boundary_by_bisection() -> None:
    result = sweep(BOX, {HEIGHT: np.linspace(0.03, 0.33, 4)}, refine=5, phase="modes")
    refined = result.refined
    assert len(refined) == 5 and all(p.refinement for p in refined)
    assert [p.index for p in result.points] == list(range(9))
    slides = [p.values[0] for p in result.points if p.modes == SLIDES]
    tips = [p.values[0] for p in result.points if p.modes == TIPS]
    assert max(slides) < 0.2 < min(tips)  # h* = w / (2 mu) = 0.2 m
    assert min(tips) - max(slides) == pytest.approx(0.1 / 2**5)  # the grid's spacing halved five times
    # the status alone does not change between sliding and tipping: nothing to refine
    assert not sweep(BOX, {HEIGHT: np.linspace(0.03, 0.33, 4)}, refine=3).refined


# --------------------------------------------------------------------------- backends and resume


def test_serial_joblib_and_dask_give_equal_results() -> None:
    from distributed import Client, LocalCluster

    serial = _tip_or_slide(refine=1, phase="modes")
    local = _tip_or_slide(refine=1, phase="modes", jobs=2, chunk_size=3)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, Client(cluster) as client:
        dask = _tip_or_slide(refine=1, phase="modes", dask=client, chunk_size=3)
    assert serial.refined
    assert local.points == serial.points
    assert dask.points == serial.points


class _InterruptedError(Exception):
    pass


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    solved: list[int] = []
    real = backends.solve_chunk

    def counted(chunk: backends.Chunk) -> Any:
        solved.extend(index for index, _, _ in chunk.points)
        return real(chunk)

    monkeypatch.setattr(backends, "solve_chunk", counted)
    return solved


def test_resume_after_an_interruption_recomputes_nothing_done(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    solved = _counting(monkeypatch)

    def stop_after_two_chunks(done: int, planned: int) -> None:
        if done >= 6:
            raise _InterruptedError

    with pytest.raises(_InterruptedError):
        _tip_or_slide(chunk_dir=tmp_path, chunk_size=3, progress=stop_after_two_chunks)
    first = list(solved)
    assert sorted(first) == list(range(6))
    solved.clear()
    resumed = _tip_or_slide(chunk_dir=tmp_path, chunk_size=3, resume=True)
    assert sorted(solved) == list(range(6, 12))  # only the chunks not finished before
    assert resumed.reused == 6
    solved.clear()
    again = _tip_or_slide(chunk_dir=tmp_path, chunk_size=3, resume=True)
    assert solved == [] and again.points == resumed.points
    assert resumed.points == _tip_or_slide().points
    solved.clear()
    _tip_or_slide(chunk_dir=tmp_path, chunk_size=3)  # without resume: everything again
    assert sorted(solved) == list(range(12))


def test_a_changed_grid_does_not_reuse_chunks(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    solved = _counting(monkeypatch)
    sweep(BOX, {HEIGHT: [0.1, 0.3]}, chunk_dir=tmp_path)
    solved.clear()
    sweep(BOX, {HEIGHT: [0.1, 0.31]}, chunk_dir=tmp_path, resume=True)
    assert sorted(solved) == [0, 1]


# --------------------------------------------------------------------------- tables, extras and the command line


def test_tables_hold_every_point(tmp_path: Path) -> None:
    import pyarrow.csv as pcsv
    import pyarrow.parquet as pq

    result = _tip_or_slide()
    table = pq.read_table(result.to_parquet(tmp_path / "r.parquet"))
    assert table.num_rows == 12 and table.equals(result.to_table())
    assert table.column(HEIGHT).to_pylist() == [p.values[0] for p in result.points]
    assert table.column("contacts[0].mode").to_pylist() == [p.modes[0] for p in result.points]
    assert table.column("twist.box[2]").to_pylist() == [dict(p.twists)["box"][2] for p in result.points]
    csv = pcsv.read_csv(result.to_csv(tmp_path / "r.csv"))
    assert csv.column("status").to_pylist() == ["solved"] * 12
    assert csv.column("certified").to_pylist() == [True] * 12


def test_missing_extras_say_how_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    with pytest.raises(BackendUnavailableError, match=r"quasistatic\[sweeps\]"):
        require_pyarrow()
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(BackendUnavailableError, match=r"quasistatic\[sweeps\]"):
        sweep(BOX, {HEIGHT: [0.1]}, dask="local:2")


def _run(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=600, cwd=ROOT)


def test_cli_writes_parquet_csv_and_the_diagram(tmp_path: Path) -> None:
    import pyarrow.csv as pcsv
    import pyarrow.parquet as pq

    grid = ["--param", f"{HEIGHT}=0.06:0.34:3", "--param", f"{FLOOR_MU}=0.25,0.8", "--phase", "modes"]
    done = _run("sweep", BOX, *grid, "--out", tmp_path / "r.parquet", "--plot", tmp_path / "d.png", "--refine", "1")
    assert done.returncode == 0, done.stderr
    table = pq.read_table(tmp_path / "r.parquet")
    assert table.num_rows > 6 and any(table.column("refinement").to_pylist())
    assert (tmp_path / "d.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "0 unproven" in done.stdout and "read from finished chunks" not in done.stdout
    resumed = _run("sweep", BOX, *grid, "--out", tmp_path / "r.parquet", "--refine", "1", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert f"; {table.num_rows} read from finished chunks" in resumed.stdout  # nothing solved again
    assert pq.read_table(tmp_path / "r.parquet").equals(table)
    again = _run("sweep", BOX, *grid, "--out", tmp_path / "r.csv", "--no-certify")
    assert again.returncode == 0, again.stderr
    csv = pcsv.read_csv(tmp_path / "r.csv")
    assert csv.column("status").to_pylist() == ["solved"] * 6
    assert csv.column("certified").to_pylist() == [False] * 6 and "6 unproven" in again.stdout  # said, not hidden


def test_cli_bad_param_is_one_error_line() -> None:
    done = _run("sweep", BOX, "--param", "contacts[9].mu=0:1:3")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip().splitlines() == ["error: contacts[9].mu: contacts has 3 entries; the index must be below 3 (got 9)"]
    done = _run("sweep", BOX, "--param", "contacts[0].mu=0:1")
    assert done.returncode == 2 and done.stderr.startswith("error: --param contacts[0].mu:")
    # A huge COUNT is refused before its values exist (it once allocated 8 GB and ran on).
    done = _run("sweep", BOX, "--param", "contacts[0].mu=0:1:1000000000")
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == ["error: --param contacts[0].mu: the grid has more than 10,000,000 points (got 1000000000)"]
    # Ends beyond a float's range: one line, no numpy warning.
    done = _run("sweep", BOX, "--param", "contacts[0].mu=0:1e400:3")
    assert done.returncode == 2
    assert [line[:60] for line in done.stderr.strip().splitlines()] == ["error: contacts[0].mu: the values must be a non-empty 1-D li"]


def test_whitney_sweep_stays_above_the_jamming_line() -> None:
    from quasistatic.tools.validation import whitney_line, whitney_parameters
    from quasistatic.tools.validation.cases import read_yaml
    from quasistatic.tools.validation.whitney import whitney_sweep

    p = whitney_parameters(read_yaml(ROOT / "validation" / "scenes" / "whitney_peg.yaml"))
    result = whitney_sweep(ROOT / "validation", n=6, refine=1)
    assert result.refined and all(point.certified for point in result.points)
    for point in result.points:
        x, y = point.values[0] / p["F_z"], point.values[1] / (p["r"] * p["F_z"])
        line = float(whitney_line(x, p["lambda"], p["mu"]))
        if abs(y - line) > 0.02:
            assert point.status == ("solved" if y > line else "unstable"), (x, y)
