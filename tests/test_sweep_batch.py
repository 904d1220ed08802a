"""Batched sweep chunks: the stacked laws and audit equal the per-point ones, and every batched answer equals
the per-point solve's, field for field and bit for bit (status, message, twists, forces, modes)."""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from quasistatic.check.audit import AuditGeometry, audit_arrays
from quasistatic.check.stacked import MODE_CODES, audit_stack
from quasistatic.errors import QuasistaticError
from quasistatic.laws import assemble
from quasistatic.laws.stacked import assemble_stack
from quasistatic.model.io import read_scene_data, read_scene_file, scene_from_file
from quasistatic.model.stacked import PlanarStack, stackable
from quasistatic.solution import Solution
from quasistatic.solve import solve
from quasistatic.sweeps import sweep
from quasistatic.sweeps.backends import Chunk, solve_chunk
from quasistatic.sweeps.batched import batched_points
from quasistatic.sweeps.params import sweep_params
from quasistatic.sweeps.result import SweepPoint, point_from_solution
from quasistatic.sweeps.scenes import PointScenes
from quasistatic.tools.bench.sweep_bench import SWEEP_SCENE

ROOT = Path(__file__).resolve().parents[1]
OPTIONS = {"method": "auto", "certify": True, "all_solutions": None, "tolerance": 1e-6, "time_limit": 60.0}


def _random_scene(rng: np.random.Generator, m: int | None = None) -> dict[str, Any]:
    """One body against a still floor and a moving pusher, every number random (some contacts frictionless)."""
    m = int(rng.integers(1, 10)) if m is None else m
    angles = rng.uniform(0.0, 2.0 * np.pi, m)
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": rng.normal(size=2).tolist(),
        "bodies": {
            "box": {"mass": float(rng.uniform(0.1, 5.0)), "com": rng.normal(size=2).tolist(), "wrench": rng.normal(size=3).tolist()}
        },  # noqa: E501
        "movers": {"pusher": {"twist": rng.normal(size=3).tolist(), "origin": rng.normal(size=2).tolist()}, "floor": None},
        "contacts": [
            {
                "body": "box",
                "other": "pusher" if rng.random() < 0.5 else "floor",
                "point": rng.normal(size=2).tolist(),
                "normal": [float(np.cos(a)), float(np.sin(a))],
                "mu": float(rng.uniform(0.0, 1.0)) if rng.random() < 0.8 else 0.0,
            }
            for a in angles
        ],
    }


def _pushed_box(rng: np.random.Generator) -> dict[str, Any]:
    """The bench's tip-or-slide box with its numbers moved at random: width, com, mass, friction, push height and tilt."""
    half = float(rng.uniform(0.05, 0.3))
    tilt = float(rng.uniform(-0.3, 0.3))
    return {
        "quasistatic": 1,
        "dimension": 2,
        "bodies": {"box": {"mass": float(rng.uniform(0.5, 5.0)), "com": [float(rng.uniform(-0.05, 0.05)), float(rng.uniform(0.05, 0.4))]}},
        "movers": {"floor": None, "pusher": {"twist": [float(rng.uniform(0.005, 0.05)), 0.0, 0.0]}},
        "contacts": [
            {"body": "box", "other": "floor", "point": [-half, 0.0], "normal": [0.0, 1.0], "mu": float(rng.uniform(0.1, 1.0))},
            {"body": "box", "other": "floor", "point": [half, 0.0], "normal": [0.0, 1.0], "mu": float(rng.uniform(0.1, 1.0))},
            {
                "body": "box",
                "other": "pusher",
                "point": [-half, float(rng.uniform(0.02, 0.5))],
                "normal": [float(np.cos(tilt)), float(np.sin(tilt))],
                "mu": float(rng.uniform(0.0, 0.5)),
            },
        ],
    }


def _scene(data: dict[str, Any]) -> Any:
    return scene_from_file(read_scene_file(data)[0])


def _alone(scenes: PointScenes, tasks: tuple[tuple[int, tuple[float, ...], bool], ...], **options: Any) -> list[SweepPoint]:
    """Each point solved by itself, as solve_chunk solved every point before batches."""
    points = []
    for index, values, refinement in tasks:
        try:
            solution = solve(scenes.at(values), **{**OPTIONS, **options})
        except QuasistaticError as exc:
            solution = Solution("failed", f"not solved at this point: {exc}", "auto", "")
        points.append(point_from_solution(index, values, refinement, solution))
    return points


def _batched_equals_alone(data: dict[str, Any], grid: dict[str, Any]) -> int:
    """Solve one chunk of the grid batched and point by point; assert equal records; return how many the batch decided."""
    axes = sweep_params(data, grid)
    tasks = tuple((i, tuple(v), False) for i, v in enumerate(itertools.product(*(p.values.tolist() for p in axes))))
    scenes = PointScenes(data, str(ROOT), axes)
    alone = _alone(scenes, tasks)
    decided = batched_points(scenes, tasks, OPTIONS)
    for position, point in decided.items():
        assert point == alone[position], (position, point, alone[position])
    _, chunk = solve_chunk(Chunk("grid-00000", data, str(ROOT), axes, tasks, OPTIONS))
    assert chunk == alone
    return len(decided)


def test_stacked_laws_equal_assemble_bit_for_bit() -> None:
    rng = np.random.default_rng(5)
    for _ in range(40):
        scene = _scene(_random_scene(rng))
        assert stackable(scene)
        laws = assemble_stack(PlanarStack.tiled(scene, 2))
        problem = assemble(scene)
        assert laws is not None
        pairs = ((laws.J, problem.J), (laws.b, problem.b), (laws.g, problem.g), (laws.mu, problem.mu), (laws.frames, problem.frames))
        scales = problem.scales
        for k in range(2):
            assert all(np.array_equal(stacked[k], alone) for stacked, alone in pairs)
            assert (laws.length[k], laws.force[k], laws.velocity[k]) == (scales.length, scales.force, scales.velocity)


def test_stacked_audit_passes_and_fails_with_the_audit() -> None:
    """On solved motions and on the same motions with their forces or twists off, the stacked audit's verdict and
    modes equal the audit's."""
    rng = np.random.default_rng(11)
    checked = failed = 0
    for _ in range(12):
        scene = _scene(_pushed_box(rng))
        solution = solve(scene)
        if solution.motion is None:
            continue
        problem = assemble(scene)
        twist = np.array([solution.twists["box"]])
        forces, _ = solution.motion.forces_and_slips()
        for T, f in ((twist, forces), (twist, 1.01 * forces), (1.5 * twist, forces)):
            audit, _, evaluation = audit_arrays(AuditGeometry.of(scene), T, f, problem.scales)
            scales = tuple(np.array([x]) for x in (problem.scales.length, problem.scales.force, problem.scales.velocity))
            stacked = audit_stack(PlanarStack.tiled(scene, 1), T, f[None], scales)
            assert bool(stacked.passed[0]) == audit.passed
            threshold = 1e-6 * problem.scales.velocity
            measured = evaluation.normal.tolist()
            modes = tuple("separating" if u > threshold else "sliding" if s > threshold else "rolling" for u, s, _ in measured)
            assert tuple(MODE_CODES[c] for c in stacked.modes[0]) == modes
            checked += 1
            failed += not audit.passed
    assert checked >= 30 and failed >= 20  # both verdicts were compared


def test_the_bench_grid_is_decided_in_one_batch_equal_to_each_point_alone() -> None:
    grid = {"contacts[2].point[1]": np.linspace(0.02, 0.38, 8), "contacts[0].mu,contacts[1].mu": np.linspace(0.1, 1.0, 8)}
    assert _batched_equals_alone(SWEEP_SCENE, grid) == 64


def test_the_tip_or_slide_and_whitney_grids_equal_each_point_alone() -> None:
    box = dict(read_scene_data(ROOT / "validation" / "scenes" / "box_push_high.yaml"))
    grid = {"contacts[2].point[1]": np.linspace(0.06, 0.34, 4), "contacts[0].mu,contacts[1].mu": [0.25, 0.5, 0.8]}
    assert _batched_equals_alone(box, grid) == 12
    peg = dict(read_scene_data(ROOT / "validation" / "scenes" / "whitney_peg.yaml"))
    peg["bodies"] = {"peg": {**peg["bodies"]["peg"], "com": [0.0, 0.0], "wrench": [0.0, -10.0, 0.0]}}  # as whitney_sweep
    grid = {"bodies.peg.wrench[0]": np.linspace(-33.3, 33.3, 4), "bodies.peg.wrench[2]": np.linspace(-0.1, 0.6, 4)}
    assert _batched_equals_alone(peg, grid) == 9  # the peg stays (indeterminate forces); unstable: left to solve


def test_random_grids_equal_each_point_alone() -> None:
    rng = np.random.default_rng(3)
    decided = 0
    for trial in range(3):
        data = _pushed_box(rng)
        grid = {
            "contacts[2].point[1]": np.sort(rng.uniform(0.02, 0.5, 3)),
            "contacts[0].mu,contacts[1].mu": np.sort(rng.uniform(0.05, 1.2, 3)),
            "movers.pusher.twist[2]": rng.normal(size=2) * 0.05,
        }
        if trial == 2:  # the last box on a tilted floor: gravity swept too
            data["gravity"] = [0.0, -9.81]
            grid["gravity[0]"] = [-1.0, 0.5]
        decided += _batched_equals_alone(data, grid)
    assert decided > 20


def test_points_the_batch_cannot_take_are_solved_alone() -> None:
    """A value the scene rejects, all friction swept to zero (the LP), and a swept path the stack does not hold."""
    grid = {"contacts[0].mu,contacts[1].mu": [-0.1, 0.0, 0.5], "contacts[2].point[1]": [0.1, 0.3]}
    axes = sweep_params(SWEEP_SCENE, {"contacts[0].mu,contacts[1].mu": [0.5], "contacts[2].point[1]": [0.1]})
    axes = tuple(type(a)(a.name, a.paths, np.asarray(grid[a.name])) for a in axes)
    tasks = tuple((i, tuple(v), False) for i, v in enumerate(itertools.product(*(p.values.tolist() for p in axes))))
    scenes = PointScenes(SWEEP_SCENE, ".", axes)
    decided = batched_points(scenes, tasks, OPTIONS)
    assert sorted(decided) == [4, 5]  # mu = 0.5 only: -0.1 is rejected, 0 leaves every contact frictionless
    _, points = solve_chunk(Chunk("grid-00000", SWEEP_SCENE, ".", axes, tasks, OPTIONS))
    assert points == _alone(scenes, tasks)
    assert [p.status for p in points[:2]] == ["failed", "failed"] and "must be >= 0" in points[0].message
    joined = sweep_params(SWEEP_SCENE, {"contacts[0].mu,bodies.box.mass": [1.0]})  # one value, two kinds of number
    joined_tasks = ((0, (-0.5,), False), (1, (0.5,), False), (2, (1.5,), False))
    assert sorted(batched_points(PointScenes(SWEEP_SCENE, ".", joined), joined_tasks, OPTIONS)) == [1, 2]
    normal = sweep_params(SWEEP_SCENE, {"contacts[2].normal[0]": [1.0, 0.99]})
    assert batched_points(PointScenes(SWEEP_SCENE, ".", normal), ((0, (1.0,), False), (1, (0.99,), False)), OPTIONS) == {}


def test_a_motion_the_stacked_audit_turns_down_is_left_to_the_per_point_solve() -> None:
    """With an audit threshold below round-off every proven motion fails its audit: the batch reports none of them,
    and the per-point solve's verdict (its audit failing too) is what the chunk records."""
    axes = sweep_params(SWEEP_SCENE, {"contacts[2].point[1]": [0.1, 0.3], "contacts[0].mu,contacts[1].mu": [0.5]})
    tasks = ((0, (0.1, 0.5), False), (1, (0.3, 0.5), False))
    scenes = PointScenes(SWEEP_SCENE, ".", axes)
    strict = {**OPTIONS, "tolerance": 1e-30}
    assert batched_points(scenes, tasks, strict) == {} and len(batched_points(scenes, tasks, OPTIONS)) == 2
    _, points = solve_chunk(Chunk("grid-00000", SWEEP_SCENE, ".", axes, tasks, strict))
    assert points == _alone(scenes, tasks, tolerance=1e-30)
    assert all(p.status != "solved" or not p.certified for p in points)


def test_a_sweeps_records_do_not_depend_on_how_its_points_are_grouped(monkeypatch: pytest.MonkeyPatch) -> None:
    """One chunk, stacks of at most 5 points, and chunks of one point (never batched): equal sweeps."""
    import quasistatic.sweeps.batched as batched

    grid = {"contacts[2].point[1]": np.linspace(0.02, 0.38, 6), "contacts[0].mu,contacts[1].mu": np.linspace(0.1, 1.0, 6)}
    whole = sweep(SWEEP_SCENE, grid, chunk_size=36)
    alone = sweep(SWEEP_SCENE, grid, chunk_size=1)
    monkeypatch.setattr(batched, "BATCH_POINTS", 5)
    assert sweep(SWEEP_SCENE, grid, chunk_size=36).points == whole.points == alone.points


@pytest.mark.slow
def test_many_random_grids_equal_each_point_alone() -> None:
    """Cross-check on 40 random boxes and 20 random scenes of 1 to 8 contacts (about 10 s): the batch decides every
    point whose per-point answer is one motion proven by the vertex certificate (550 of 644 solved here)."""
    rng = np.random.default_rng(2024)
    decided = 0
    for trial in range(60):
        data = _pushed_box(rng) if trial < 40 else _random_scene(rng, int(rng.integers(1, 9)))
        paths = ["contacts[0].mu", "contacts[0].point[1]", "movers.pusher.twist[0]", "bodies.box.mass", "bodies.box.com[0]"]
        chosen = rng.choice(len(paths), 2, replace=False)
        grid = {paths[k]: np.sort(np.abs(rng.normal(size=4))) * (0.5 if "mu" in paths[k] else 0.2) + 0.01 for k in chosen}
        if "movers.pusher.twist[0]" in grid and not any(c["other"] == "pusher" for c in data["contacts"]):
            continue
        decided += _batched_equals_alone(data, grid)
    assert decided > 500


@pytest.mark.slow
def test_batched_sweeps_equal_point_by_point_without_numba() -> None:
    """With numba made unimportable (the kernels as plain Python), a batched chunk still equals chunks of one point."""
    code = textwrap.dedent(
        """
        import sys
        sys.modules["numba"] = None  # import numba now raises ImportError
        import numpy as np
        from quasistatic import jit
        from quasistatic.sweeps import sweep
        from quasistatic.tools.bench.sweep_bench import SWEEP_SCENE
        assert not jit.HAVE_NUMBA
        grid = {"contacts[2].point[1]": np.linspace(0.02, 0.38, 3), "contacts[0].mu,contacts[1].mu": [0.1, 1.0]}
        assert sweep(SWEEP_SCENE, grid, chunk_size=6).points == sweep(SWEEP_SCENE, grid, chunk_size=1).points
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr


def test_the_batchs_force_claims_agree_with_the_per_point_solve() -> None:
    """Where the batch decides a point, its claim on the forces (unique, or indeterminate) is the per-point solve's:
    random scenes of 1 to 8 contacts and pushed boxes, each a stack of one, cover maps of full rank and rank-deficient ones."""
    from quasistatic.solvers.batched import certify_stack

    rng = np.random.default_rng(11)
    claims = {True: 0, False: 0}
    for trial in range(80):
        scene = _scene(_pushed_box(rng) if trial % 2 else _random_scene(rng, int(rng.integers(1, 9))))
        if not stackable(scene):
            continue
        batch = certify_stack(assemble_stack(PlanarStack.tiled(scene, 1)))
        if not batch.decided[0]:
            continue
        solution = solve(scene, **OPTIONS)
        assert solution.status == "solved" and solution.certified
        assert solution.forces_indeterminate == bool(batch.indeterminate[0])
        claims[bool(batch.indeterminate[0])] += 1
    assert claims[True] >= 2 and claims[False] >= 5, claims  # both claims were checked


def test_forces_free_along_a_narrow_step_are_never_claimed_unique() -> None:
    """Two rolling contacts give four force coordinates against three equations: the forces may vary, and the per-point
    solve says they are indeterminate, but from Lemke's forces a step along the free direction is narrow (a cone edge
    stops it), so the batch cannot show it: it must leave the point to the per-point solve, not call it unique
    (found by the slow cross-check's random scene 45)."""
    from quasistatic.solvers.batched import certify_stack

    data = json.loads((ROOT / "tests" / "data" / "batch_narrow_free_forces.json").read_text())
    scene = _scene(data)
    solution = solve(scene, **OPTIONS)
    assert solution.status == "solved" and solution.forces_indeterminate
    batch = certify_stack(assemble_stack(PlanarStack.tiled(scene, 1)))
    assert not batch.decided[0] or batch.indeterminate[0]
