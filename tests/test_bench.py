"""The benchmark runner keeps working: a tiny subset (one family, two repeats) end to end."""

from __future__ import annotations

import csv
import io
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

import quasistatic as qs
from quasistatic.adapters.robot import installed_model_folders
from quasistatic.tools.bench import (
    FAMILIES,
    BenchConfig,
    Row,
    growth_exponents,
    markdown_tables,
    pipeline,
    render_result,
    run_benchmarks,
    run_sweep_bench,
    runner,
    write_results,
    write_scaling_plot,
)


@pytest.fixture(scope="module")
def result() -> runner.BenchResult:
    config = BenchConfig(
        families=("grasp-3d-nf",), methods=("lp", "scipy-dense"), repeat=2, instances=2, batch=False, robots=False, sweeps=False
    )
    return run_benchmarks(config)


def test_rows_cover_sizes_and_methods(result: runner.BenchResult) -> None:
    sizes = FAMILIES["grasp-3d-nf"].quick_sizes
    assert [(r.size, r.method) for r in result.rows] == [(s, m) for s in sizes for m in ("lp", "scipy-dense")]
    for row in result.rows:
        assert row.skipped is None
        assert row.samples >= 2 and row.instances == 2
        assert 0 < row.p25 <= row.median <= row.p75
        assert row.assemble is not None and row.assemble > 0
        assert sum(row.statuses.values()) == 2
    baseline = [r for r in result.rows if r.method == "lp"]
    assert all(r.ratio == 1.0 for r in baseline)
    naive = [r for r in result.rows if r.method == "scipy-dense"]
    # The naive LP agrees with the certified LP on these scenes (they are solved or unstable, never ambiguous).
    assert all(r.compared == 2 and r.agree == 2 for r in naive)
    assert all(r.ratio is not None and r.ratio > 0 for r in naive)


def test_outputs(result: runner.BenchResult, tmp_path: Path) -> None:
    csv_path, json_path, md_path = write_results(result, tmp_path)
    assert md_path.read_text().count("| grasp-3d-nf") == 0 and "**grasp-3d-nf**" in md_path.read_text()
    with csv_path.open() as handle:
        lines = list(csv.DictReader(handle))
    assert len(lines) == len(result.rows)
    assert {"family", "method", "median", "ratio", "agree"} <= set(lines[0])
    data = json.loads(json_path.read_text())
    assert data["machine"]["cores"] >= 1 and data["rows"][0]["family"] == "grasp-3d-nf"
    console = Console(file=io.StringIO(), width=160)
    render_result(result, console)
    text = console.file.getvalue()  # type: ignore[attr-defined]
    assert "grasp-3d-nf" in text and "scipy-dense" in text and "(assemble)" in text
    assert write_scaling_plot(result, tmp_path / "plot.png") is None  # no scaling family in this subset


def test_the_benchmark_holds_blas_to_one_thread_while_it_times_and_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """OpenBLAS's own threads made the Allegro simulate row's solve 270 ms a step instead of 19 on a loaded 2-core
    machine: every row is timed with BLAS held to one thread, whatever the environment says."""
    from threadpoolctl import threadpool_info

    seen: list[int] = []
    timed = runner._run_family

    def recording(family: object, config: BenchConfig, say: object) -> list[Row]:
        seen.extend(pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas")
        return timed(family, config, say)  # type: ignore[arg-type]

    monkeypatch.setattr(runner, "_run_family", recording)
    lines: list[str] = []
    config = BenchConfig(families=("grasp-3d-nf",), methods=("lp",), repeat=1, instances=1, batch=False, robots=False, sweeps=False)
    result = run_benchmarks(config, lines.append)
    assert seen and set(seen) == {1}
    assert result.machine["blas_threads"] == 1
    assert any("BLAS held to 1 thread for every timing" in line for line in lines)
    console = Console(file=io.StringIO(), width=200)
    render_result(result, console)
    assert "BLAS threads 1 while timing" in console.file.getvalue()  # type: ignore[attr-defined]


def test_unregistered_or_inapplicable_methods_are_reported_not_dropped(monkeypatch: pytest.MonkeyPatch) -> None:
    problem = qs.assemble(FAMILIES["grasp-3d"].make(4, 0))
    monkeypatch.delitem(runner.BACKENDS, "lp")
    config = BenchConfig()
    assert "not registered" in (runner._skip_reason("lp", problem, [], config) or "")
    assert "frictional 3-D" in (runner._skip_reason("scipy-dense", problem, [], config) or "")
    assert "too slow: one solve" in (runner._skip_reason("scip", problem, [(4, 2 * config.cap, 1.0)], config) or "")
    # 2 s at 2 contacts growing as n^3 predicts 16 s at 4 contacts, over the 10 s cap.
    assert "predicted" in (runner._skip_reason("scip", problem, [(1, 1.0, 0.25), (2, 1.0, 2.0)], config) or "")
    assert runner._skip_reason("scip", problem, [(2, 0.1, 0.1)], config) is None
    assert runner._skip_reason("scip", problem, [], config) is None


def test_families_are_deterministic_and_valid() -> None:
    for family in FAMILIES.values():
        size = family.full_sizes[0]
        first, again = family.make(size, 1), family.make(size, 1)
        a, b = qs.assemble(first), qs.assemble(again)
        for name in ("J", "b", "g", "mu"):
            assert np.array_equal(getattr(a, name), getattr(b, name))
        assert family.frictionless == (str(first.friction) == "none")


def test_growth_exponent_of_a_power_law() -> None:
    rows = [Row("f", n, "contacts", n, 1, "m", "m", median=1e-6 * n**1.5) for n in (10, 100, 1000)]
    assert growth_exponents(rows)["f"]["m"] == pytest.approx(1.5)


def test_bad_config() -> None:
    with pytest.raises(ValueError, match="unknown benchmark families"):
        BenchConfig(families=("nope",))
    with pytest.raises(ValueError, match="repeat"):
        BenchConfig(repeat=0)


def test_contradictions_are_claims_against_the_certified_answer() -> None:
    """`bench --check` fails CI on a contradiction: a status or twist other than the certified one.
    A `failed` answer claims nothing, and one motion of an `ambiguous` set is not a contradiction."""
    root = Path(__file__).resolve().parents[1] / "validation" / "scenes"
    rest = qs.assemble(qs.load_scene(root / "slope_block_20.yaml"))
    certified = qs.solve(rest, method="scip")
    assert certified.status == "solved"
    stopped = qs.solve(rest, method="scip", time_limit=1e-6)
    unstable = qs.solve(qs.load_scene(root / "slope_block_30.yaml"), method="scip")
    assert stopped.status == "failed" and unstable.status == "unstable"
    assert not runner._contradicts(rest, certified, certified)
    assert not runner._contradicts(rest, stopped, certified)
    assert runner._contradicts(rest, unstable, certified)
    lift = qs.load_scene(root / "grasp_level.yaml")
    every = qs.solve(lift, method="scip")
    assert every.status == "ambiguous"
    one = qs.solve(lift, method="paper")
    assert one.status == "solved" and not runner._contradicts(qs.assemble(lift), one, every)
    assert runner._contradicts(qs.assemble(lift), every, qs.solve(lift, method="scip", modes=["rolling", "rolling"]))


def test_robot_rows_are_tabled_and_skips_are_said() -> None:
    rows = (
        pipeline.PipelineRow("detect growth", 10, 19, 19, 34, 5, 1e-3, 9e-4, 2e-3, cpu_median=7.25e-4),
        pipeline.PipelineRow("detect growth", 20, 38, 38, 68, 5, 2e-3, 1e-3, 3e-3),
        pipeline.PipelineRow("detect growth", 40, 76, 76, 136, 5, 4e-3, 3e-3, 5e-3),
        pipeline.PipelineRow("allegro pipeline (certified)", skipped="coal/pinocchio not installed"),
    )
    assert pipeline.growth_exponent(list(rows)) == pytest.approx(1.0)  # one row has no CPU time: the wall times
    # CPU time linear in the near pairs, wall time (inflated unevenly by other work) quadratic.
    wall_square = [replace(r, cpu_median=1e-3 * r.near / 19, median=1e-3 * (r.near / 19) ** 2) for r in rows[:3]]
    assert pipeline.growth_exponent(wall_square) == pytest.approx(1.0)  # the CPU times decide where every row has one
    config = BenchConfig(batch=False, robots=False)
    result = runner.BenchResult(config, runner.machine_info(), (), (), 1.0, pipeline=rows)
    console = Console(file=io.StringIO(), width=200)
    render_result(result, console)
    text = console.file.getvalue()  # type: ignore[attr-defined]
    assert "robots and geometry" in text and "skipped" in text and "near pairs: n^1.00" in text
    data = result.to_dict()
    assert data["detect_growth"] == pytest.approx(1.0) and len(data["pipeline"]) == 4
    assert "| allegro pipeline (certified) |" in markdown_tables(data)
    assert "| CPU median |" in markdown_tables(data) and "725 µs" in markdown_tables(data)  # the process time, beside the wall time


def test_robot_scenes_touch_where_they_should() -> None:
    pytest.importorskip("coal")
    world = pipeline.resting_rows(10)
    detection = world.detect()
    # 5 spheres (1 point on the table) and 5 cubes (4 corners), 9 sphere-cube neighbours in the row (1 point each).
    assert len(detection.contacts) == 5 + 20 + 9 and max(abs(g) for g in detection.gaps) < 1e-12
    pytest.importorskip("pinocchio")
    if not installed_model_folders():
        pytest.skip("example-robot-data is not installed")
    world, _ = pipeline.allegro_grasp()
    detection = world.detect()
    tips = {c.other for c in detection.contacts if c.other.endswith("_tip")}
    assert tips == {f"hand/{link}" for link in pipeline.GRASP_TIPS}
    assert sum(c.other == "table" for c in detection.contacts) == 4 and max(abs(g) for g in detection.gaps) < 1e-9


def test_sweep_rows_compare_backends_on_certified_solves() -> None:
    lines: list[str] = []
    rows = run_sweep_bench(False, lines.append, side=2)
    assert [(r.backend, r.workers) for r in rows] == [("serial", 1), ("joblib", 2), ("dask", 2)]
    for row in rows:
        assert row.points == 4 and row.certified == 4 and row.statuses == {"solved": 4}
        assert row.per_second == pytest.approx(4 / row.seconds) and row.solve_seconds > 0
    assert rows[0].ratio_to_serial is None and all(r.matches_serial for r in rows[1:])
    assert rows[2].startup_seconds is not None and len(lines) == 3
    result = runner.BenchResult(BenchConfig(batch=False, robots=False), runner.machine_info(), (), (), 1.0, sweeps=tuple(rows))
    console = Console(file=io.StringIO(), width=200)
    render_result(result, console)
    assert "sweep throughput" in console.file.getvalue()  # type: ignore[attr-defined]
    assert "| dask | 2 | 4 |" in markdown_tables(result.to_dict())
