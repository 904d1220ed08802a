"""Sweep throughput: certified 2-D solves per second of wall time, serially, with joblib and on a Dask LocalCluster.

The scene is the tip-or-slide box (validation case 4): a box pushed at a
height on a floor with friction, swept over the push height and the floor's
friction coefficient. Every point is a certified, audited solve, as
``quasistatic sweep`` runs it; each backend is warmed up first (worker start,
imports, compiled kernels), and the Dask cluster's start is timed apart.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ...sweeps import SweepResult, sweep

__all__ = ["SWEEP_SCENE", "SweepRow", "run_sweep_bench"]

SWEEP_SCENE: dict[str, Any] = {
    "quasistatic": 1,
    "dimension": 2,
    "bodies": {"box": {"mass": 2.0, "com": [0.0, 0.2]}},
    "movers": {"floor": None, "pusher": {"twist": [0.01, 0.0, 0.0]}},
    "contacts": [
        {"body": "box", "other": "floor", "point": [-0.1, 0.0], "normal": [0.0, 1.0], "mu": 0.5},
        {"body": "box", "other": "floor", "point": [0.1, 0.0], "normal": [0.0, 1.0], "mu": 0.5},
        {"body": "box", "other": "pusher", "point": [-0.1, 0.25], "normal": [1.0, 0.0]},
    ],
}
"""The box of ``validation/scenes/box_push_high.yaml``: w = 0.2 m, m = 2 kg, mu = 0.5, pushed at h = 0.25 m."""


@dataclass(frozen=True)
class SweepRow:
    """One backend's sweep of the same grid; times in seconds.

    ``per_second`` counts certified solves over the sweep's wall time (warm workers);
    ``solve_seconds`` is the median time of one solve as the solver measured it (a point decided in a
    batched chunk: its share of the batch's time, from stacking to audit), so
    ``workers / solve_seconds`` is what the solves alone would allow and the rest is overhead
    (reading the scene at each point, shipping chunks, collecting answers).
    """

    backend: str
    workers: int
    points: int
    seconds: float
    per_second: float
    certified: int
    solve_seconds: float
    ratio_to_serial: float | None
    matches_serial: bool | None
    startup_seconds: float | None = None
    statuses: dict[str, int] | None = None
    skipped: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


Say = Callable[[str], None]


def run_sweep_bench(full: bool, say: Say, workers: int = 2, side: int | None = None) -> list[SweepRow]:
    """Sweep the tip-or-slide box serially, with joblib(``workers``) and Dask LocalCluster(``workers``).

    The grid is ``side`` x ``side`` points (default 40 x 40 for a full run, 8 x 8 for the quick one in CI).
    """
    side = side or (40 if full else 8)
    grid = {"contacts[2].point[1]": np.linspace(0.02, 0.38, side), "contacts[0].mu,contacts[1].mu": np.linspace(0.1, 1.0, side)}
    # 4 x 4: chunks of two or more points even split 8 ways, so the warm-up runs the batched kernels the grid runs
    warm = {name: values[:4] for name, values in grid.items()}
    rows: list[SweepRow] = []
    serial = _timed("serial", 1, grid, warm, {}, None)
    rows.append(serial[0])
    say(_line(serial[0]))
    for row in (_timed("joblib", workers, grid, warm, {"jobs": workers}, serial)[0], _dask_row(workers, grid, warm, serial)):
        rows.append(row)
        say(_line(row))
    return rows


def _timed(
    backend: str,
    workers: int,
    grid: dict[str, np.ndarray],
    warm: dict[str, np.ndarray],
    options: dict[str, Any],
    serial: tuple[SweepRow, SweepResult] | None,
    startup: float | None = None,
) -> tuple[SweepRow, SweepResult]:
    sweep(SWEEP_SCENE, warm, **options)  # discarded: worker start, imports, compiled kernels
    start = time.perf_counter()
    result = sweep(SWEEP_SCENE, grid, **options)
    seconds = time.perf_counter() - start
    points = len(result.points)
    row = SweepRow(
        backend=backend,
        workers=workers,
        points=points,
        seconds=seconds,
        per_second=points / seconds,
        certified=sum(p.certified for p in result.points),
        solve_seconds=float(np.median([p.seconds for p in result.points])),
        ratio_to_serial=None if serial is None else serial[0].seconds / seconds,
        matches_serial=None if serial is None else result.points == serial[1].points,
        startup_seconds=startup,
        statuses=dict(Counter(p.status for p in result.points)),
    )
    return row, result


def _dask_row(workers: int, grid: dict[str, np.ndarray], warm: dict[str, np.ndarray], serial: tuple[SweepRow, SweepResult]) -> SweepRow:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        return SweepRow("dask", workers, 0, 0.0, 0.0, 0, 0.0, None, None, skipped='dask not installed: pip install "quasistatic[sweeps]"')
    start = time.perf_counter()
    with (
        LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        Client(cluster) as client,
    ):
        startup = time.perf_counter() - start
        return _timed("dask", workers, grid, warm, {"dask": client}, serial, startup)[0]


def _line(row: SweepRow) -> str:
    if row.skipped:
        return f"sweep {row.backend}: skipped ({row.skipped})"
    ratio = "" if row.ratio_to_serial is None else f", {row.ratio_to_serial:.2f}x serial"
    return f"sweep {row.backend} x{row.workers}: {row.per_second:,.0f} certified solves/s{ratio}"
