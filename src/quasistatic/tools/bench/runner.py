"""The benchmark runner: time every method on every family, in one run, against a stated baseline.

Per (family, size, method) row: the scenes are assembled once (assembly is
timed on its own), each scene is solved once to warm up (that call is
discarded: imports, JIT compilation, caches) and then ``repeat`` more times;
the row reports the median and the interquartile range of all timed calls
pooled over the scenes, the ratio ``baseline median / method median``
(``> 1``: faster than the baseline) with the baseline measured in the same
run, the statuses, the worst audit residual and the agreement with the
reference answer (the certified ``scip`` search for frictional families, the
``lp`` for frictionless ones). A method that is not registered, does not
apply, or would take too long at a size is reported as skipped with its
reason, never dropped.
"""

from __future__ import annotations

import math
import os
import platform
import statistics
import sys
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from importlib import metadata
from importlib.util import find_spec
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from ...laws import Problem, assemble
from ...solution import Solution
from ...solve import solve
from ...solvers import BACKENDS
from .families import FAMILIES, Family, grasp_2d
from .naive import naive_applicable, solve_naive, to_solution
from .pipeline import PipelineRow, growth_exponent, run_pipeline
from .simulation import run_simulation_rows
from .sweep_bench import SweepRow, run_sweep_bench

__all__ = ["BenchConfig", "Row", "BatchRow", "BenchResult", "run_benchmarks", "machine_info", "growth_exponents"]

NAIVE = "scipy-dense"
FRICTIONAL_METHODS = ("scip", "certified", "fast", "paper", NAIVE)
FRICTIONLESS_METHODS = ("lp", "fast", "paper", NAIVE)
AGREEMENT_TOLERANCE = 1e-4  # scene-relative twist difference still counted as the same motion


@dataclass(frozen=True)
class BenchConfig:
    """What one run measures.

    Attributes
    ----------
    full : bool
        Full sizes and instance counts (else the quick CI subset).
    repeat : int
        Timed calls per scene after the discarded warm-up call, >= 1.
    families : tuple of str or None
        Family names to run (all when None).
    methods : tuple of str or None
        Method names to run (all when None); the baseline is always run.
    instances : int or None
        Scenes per size, overriding the family's own count.
    cap : float
        Seconds: a warm-up call slower than this skips the method at larger
        sizes; also the time limit handed to each solve [s].
    row_budget : float
        Seconds of timed calls aimed at per row; fewer repeats (at least one)
        are made for slow methods [s].
    batch : bool
        Also measure ``solve_many`` throughput on small 2-D scenes.
    sweeps : bool
        Also measure sweep throughput: certified 2-D solves per second, serial, joblib(2) and Dask LocalCluster(2).
    robots : bool
        Also measure robots and geometry: the Allegro hand's detection, Jacobians and
        whole pipeline, and detection's growth with the pairs (needs the robots extra).
    """

    full: bool = False
    repeat: int = 5
    families: tuple[str, ...] | None = None
    methods: tuple[str, ...] | None = None
    instances: int | None = None
    cap: float = 10.0
    row_budget: float = 3.0
    batch: bool = True
    robots: bool = True
    sweeps: bool = True

    def __post_init__(self) -> None:
        if self.repeat < 1:
            raise ValueError(f"repeat must be >= 1, got {self.repeat}")
        if self.families is not None:
            unknown = [name for name in self.families if name not in FAMILIES]
            if unknown:
                raise ValueError(f"unknown benchmark families {unknown}; known: {', '.join(FAMILIES)}")
        if self.methods is not None:
            known = {*FRICTIONAL_METHODS, *FRICTIONLESS_METHODS, *BACKENDS}
            unknown = [name for name in self.methods if name not in known]
            if unknown:
                raise ValueError(f"unknown methods {unknown}; known: {', '.join(sorted(known))}")


@dataclass(frozen=True)
class Row:
    """One (family, size, method) measurement; times in seconds."""

    family: str
    size: int
    size_label: str
    contacts: int
    bodies: int
    method: str
    baseline: str
    skipped: str | None = None
    instances: int = 0
    samples: int = 0
    median: float | None = None
    p25: float | None = None
    p75: float | None = None
    ratio: float | None = None
    assemble: float | None = None
    statuses: dict[str, int] = field(default_factory=dict)
    worst_residual: float | None = None
    agree: int = 0
    compared: int = 0
    contradictions: int = 0
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class BatchRow:
    """Throughput of :func:`quasistatic.solve_many` on ``scenes`` small 2-D scenes."""

    scenes: str
    method: str
    n_jobs: int
    problems: int
    seconds: float
    per_second: float
    statuses: dict[str, int]
    matches_serial: bool | None
    skipped: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class BenchResult:
    """Everything one run measured, with the machine and the configuration."""

    config: BenchConfig
    machine: dict[str, Any]
    rows: tuple[Row, ...]
    batch: tuple[BatchRow, ...]
    wall_seconds: float
    left_out: tuple[str, ...] = ()
    pipeline: tuple[PipelineRow, ...] = ()
    sweeps: tuple[SweepRow, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {
            "config": asdict(self.config),
            "machine": self.machine,
            "wall_seconds": self.wall_seconds,
            "rows": [r.to_dict() for r in self.rows],
            "batch": [b.to_dict() for b in self.batch],
            "left_out": list(self.left_out),
            "growth": growth_exponents(self.rows),
            "pipeline": [p.to_dict() for p in self.pipeline],
            "detect_growth": growth_exponent(list(self.pipeline)),
            "sweeps": [s.to_dict() for s in self.sweeps],
        }


Progress = Callable[[str], None]


BLAS_THREADS = 1
"""BLAS threads while the benchmark times anything: OpenBLAS's own threads, on a loaded 2-core machine, made the
Allegro simulate row's solve take 270 ms a step instead of 19 (and its CPU time twice its wall time elsewhere)."""


def run_benchmarks(config: BenchConfig, progress: Progress | None = None) -> BenchResult:
    """Run the families and methods of ``config`` with BLAS held to :data:`BLAS_THREADS` thread(s) (threadpoolctl);
    ``progress`` gets one line per finished row."""
    say = progress or (lambda _line: None)
    say(f"BLAS held to {BLAS_THREADS} thread for every timing (threadpoolctl), whatever OPENBLAS_NUM_THREADS says")
    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        result = _run_benchmarks(config, say)
    result.machine["blas_threads"] = BLAS_THREADS
    return result


def _run_benchmarks(config: BenchConfig, say: Progress) -> BenchResult:
    start = time.perf_counter()
    load_at_start = machine_info()["load_average"]
    rows: list[Row] = []
    names = config.families or tuple(FAMILIES)
    left_out = []
    for name in names:
        if not FAMILIES[name].sizes(config.full):
            left_out.append(f"{name} (full run only)")
            say(f"{name}: not in the quick run (full run only)")
            continue
        rows += _run_family(FAMILIES[name], config, say)
    batch = tuple(_run_batch(config, say)) if config.batch else ()
    pipeline = tuple(run_pipeline(config.full, config.row_budget, say) + run_simulation_rows(config.full, say)) if config.robots else ()
    sweeps = tuple(run_sweep_bench(config.full, say)) if config.sweeps else ()
    machine = machine_info()
    if config.batch:
        machine["effective_cores_for_2_workers"] = effective_cores()
    machine["load_average_at_start"] = load_at_start
    return BenchResult(config, machine, tuple(rows), batch, time.perf_counter() - start, tuple(left_out), pipeline, sweeps=sweeps)


# --------------------------------------------------------------------------- one family


@dataclass
class _Outcome:
    times: list[float]
    solutions: list[Solution]
    note: str = ""
    warm_max: float = 0.0


def _methods(family: Family, config: BenchConfig) -> tuple[str, tuple[str, ...]]:
    methods = FRICTIONLESS_METHODS if family.frictionless else FRICTIONAL_METHODS
    baseline = methods[0]
    extra = tuple(m for m in (config.methods or ()) if m not in methods)
    chosen = tuple(m for m in methods + extra if config.methods is None or m in config.methods or m == baseline)
    return baseline, chosen


def _run_family(family: Family, config: BenchConfig, say: Progress) -> list[Row]:
    baseline, methods = _methods(family, config)
    n_instances = config.instances or family.instances(config.full)
    rows: list[Row] = []
    history: dict[str, list[tuple[int, float, float]]] = {}  # method -> (contacts, warm-up max, median) per size run
    for size in family.sizes(config.full):
        scenes = [family.make(size, i) for i in range(n_instances)]
        problems, assemble_time = _assemble_all(scenes, config.repeat)
        head: dict[str, Any] = {
            "family": family.name,
            "size": size,
            "size_label": family.size_label,
            "contacts": problems[0].n_contacts,
            "bodies": len(scenes[0].bodies),
            "baseline": baseline,
            "assemble": assemble_time,
        }
        reference: list[Solution] | None = None
        base_median: float | None = None
        for method in methods:
            reason = _skip_reason(method, problems[0], history.get(method, []), config)
            if reason is not None:
                row = Row(method=method, skipped=reason, **head)
            else:
                outcome = _measure(method, problems, config)
                if outcome.times:
                    history.setdefault(method, []).append((problems[0].n_contacts, outcome.warm_max, statistics.median(outcome.times)))
                row = _row(head, method, outcome, problems, reference, base_median)
                if method == baseline and row.skipped is None:
                    reference, base_median = outcome.solutions, row.median
                    row = _with(row, ratio=1.0)
            rows.append(row)
            say(_progress_line(row))
    return rows


def _with(row: Row, **changes: Any) -> Row:
    return Row(**{**row.to_dict(), **changes})


def _assemble_all(scenes: Sequence[Any], repeat: int) -> tuple[list[Problem], float]:
    problems = [assemble(scene) for scene in scenes]
    times = []
    for scene in scenes[:3]:
        for _ in range(min(repeat, 3)):
            t0 = time.perf_counter()
            assemble(scene)
            times.append(time.perf_counter() - t0)
    return problems, statistics.median(times)


def _skip_reason(method: str, problem: Problem, history: Sequence[tuple[int, float, float]], config: BenchConfig) -> str | None:
    """Why ``method`` is not run on ``problem``, or None.

    ``history`` holds (contacts, slowest warm-up, median) at the sizes already
    run. A method is skipped once a warm-up call exceeded the cap, or when
    its median, extrapolated with the growth seen between its last two sizes
    (n^2 after a single size, never less than n^1), would exceed the cap.
    """
    if method == NAIVE:
        reason = naive_applicable(problem)
        if reason is not None:
            return reason
    else:
        backend = BACKENDS.get(method)
        if backend is None:
            return f"method {method!r} is not registered in this build"
        if backend.requires and find_spec(backend.requires) is None:
            return f"not installed ({backend.install_hint})"
        if not backend.frictional and not problem.is_frictionless:
            return "frictionless only"
    if not history:
        return None
    contacts, warm, median = history[-1]
    if warm > config.cap:
        return f"too slow: one solve took {format_seconds(warm)} at {contacts} contacts (cap {format_seconds(config.cap)})"
    power = 2.0
    if len(history) >= 2 and history[-2][0] < contacts:
        before, _, before_median = history[-2]
        power = max(1.0, math.log(median / before_median) / math.log(contacts / before))
    predicted = median * (problem.n_contacts / max(contacts, 1)) ** power
    if predicted > config.cap:
        growth = f"n^{power:.2g} from {format_seconds(median)} at {contacts} contacts"
        return f"too slow: predicted ~{format_seconds(predicted)} per solve ({growth})"
    return None


def _call(method: str, problem: Problem, config: BenchConfig) -> Callable[[], Any]:
    if method == NAIVE:
        return lambda: solve_naive(problem)
    return lambda: solve(problem, method=method, time_limit=config.cap)


def _measure(method: str, problems: Sequence[Problem], config: BenchConfig) -> _Outcome:
    """Per scene: a warm-up call (discarded), then timed repeats, within the row budget.

    Fewer repeats (at least one) are made when one call is slow; a warm-up
    call slower than the row budget is itself the only sample of its scene
    (then noted), and no further scene is started once the row budget is spent.
    """
    times: list[float] = []
    solutions: list[Solution] = []
    warm_max = 0.0
    cold = 0
    started = time.perf_counter()
    for problem in problems:
        call = _call(method, problem, config)
        t0 = time.perf_counter()
        try:
            result = call()
        except Exception as exc:  # a benchmark reports a backend's crash instead of dying with it
            return _Outcome([], [], f"error: {type(exc).__name__}: {' '.join(str(exc).split())[:160]}")
        warm = time.perf_counter() - t0
        warm_max = max(warm_max, warm)
        if warm > config.row_budget:
            times.append(warm)
            cold += 1
        else:
            t0 = time.perf_counter()
            result = call()
            first = time.perf_counter() - t0
            times.append(first)
            repeats = max(1, min(config.repeat, int(config.row_budget / len(problems) / max(first, 1e-9))))
            for _ in range(repeats - 1):
                t0 = time.perf_counter()
                result = call()
                times.append(time.perf_counter() - t0)
        solutions.append(to_solution(problem, result) if method == NAIVE else result)
        if time.perf_counter() - started > config.row_budget:
            break
    notes = []
    if cold:
        notes.append(f"{cold} slow scene(s) timed once, warm-up included")
    if len(solutions) < len(problems):
        notes.append(f"{len(solutions)} of {len(problems)} scenes (row budget)")
    return _Outcome(times, solutions, "; ".join(notes), warm_max)


def _row(
    head: dict[str, Any],
    method: str,
    outcome: _Outcome,
    problems: Sequence[Problem],
    reference: list[Solution] | None,
    base_median: float | None,
) -> Row:
    if not outcome.times:
        return Row(method=method, skipped=outcome.note or "no timed call", **head)
    q25, median, q75 = np.percentile(outcome.times, [25, 50, 75])
    statuses: dict[str, int] = dict(Counter(str(s.status) for s in outcome.solutions))
    residuals = [_worst_residual(s) for s in outcome.solutions]
    worst = max((r for r in residuals if r is not None), default=None)
    agree = compared = contradictions = 0
    if reference is not None:
        for problem, mine, ref in zip(problems, outcome.solutions, reference, strict=False):
            if not _certified(ref):
                continue
            compared += 1
            agree += _same_answer(problem, mine, ref)
            contradictions += _contradicts(problem, mine, ref)
    return Row(
        method=method,
        instances=len(outcome.solutions),
        samples=len(outcome.times),
        median=float(median),
        p25=float(q25),
        p75=float(q75),
        ratio=None if base_median is None else base_median / float(median),
        statuses=statuses,
        worst_residual=worst,
        agree=agree,
        compared=compared,
        contradictions=contradictions,
        note=outcome.note,
        **head,
    )


def _certified(solution: Solution) -> bool:
    """A reference answer that can be compared with: not failed, and its search was complete."""
    return solution.status != "failed" and solution.search_complete is not False


def _worst_residual(solution: Solution) -> float | None:
    motions = [solution.motion, *solution.solutions] if solution.motion is not None else list(solution.solutions)
    values = [v for m in motions if m is not None for v in m.audit.residuals().values()]
    return max(values) if values else None


def _contradicts(problem: Problem, mine: Solution, ref: Solution) -> bool:
    """A claim against the certified reference: not a ``failed`` (which claims nothing), nor one motion of an ``ambiguous`` set."""
    if mine.status == "failed" or (mine.status == "solved" and ref.status == "ambiguous"):
        return False
    return not _same_answer(problem, mine, ref)


def _same_answer(problem: Problem, a: Solution, b: Solution) -> bool:
    """Same status, and for ``solved`` the same twists within :data:`AGREEMENT_TOLERANCE` (scene-relative)."""
    if a.status != b.status:
        return False
    if a.status != "solved":
        return True
    units = problem.scales.twist_units(problem.dimension)
    return all(np.max(np.abs(a.twists[name] - b.twists[name]) / units) <= AGREEMENT_TOLERANCE for name in b.twists)


# --------------------------------------------------------------------------- batch throughput


def _busy_loop(n: int) -> float:
    start = time.perf_counter()
    total = 0
    for i in range(n):
        total += i
    return time.perf_counter() - start


def effective_cores(workers: int = 2, n: int = 3_000_000) -> float:
    """Cores this run really gets: one busy loop alone, then ``workers`` at once in joblib workers.

    On a shared machine this is below the core count; it tells how far an
    ``n_jobs`` speed-up can go at the moment.
    """
    import joblib
    from joblib.externals.loky import get_reusable_executor

    parallel = joblib.Parallel(n_jobs=workers, backend="loky")
    parallel(joblib.delayed(_busy_loop)(1000) for _ in range(workers))  # start the workers
    alone = min(parallel(joblib.delayed(_busy_loop)(n) for _ in range(1)))
    together = parallel(joblib.delayed(_busy_loop)(n) for _ in range(workers))
    # Stop loky's workers and its threads: solve_many forks its workers only from a single-threaded process.
    get_reusable_executor().shutdown(wait=True)
    return round(workers * alone / max(together), 2)


def _run_batch(config: BenchConfig, say: Progress) -> list[BatchRow]:
    from ...batch import solve_many

    say(f"batch: effective cores for 2 workers right now: {effective_cores()}")

    count = 4000 if config.full else 1000
    frictionless = "grasp-2d, 3 contacts, friction none"
    frictional = "grasp-2d, 3 contacts, exact cones"
    sets = {
        frictionless: [assemble(grasp_2d(3, i, friction="none")) for i in range(count)],
        frictional: [assemble(grasp_2d(3, i)) for i in range(count)],
    }
    wanted = [(frictionless, "lp", count), (frictional, "fast", count)]
    if config.full:
        wanted.append((frictional, "scip", 100))
    rows: list[BatchRow] = []
    for scenes, method, size in wanted:
        problems = sets[scenes][:size]
        if config.methods is not None and method not in config.methods:
            continue
        if method not in BACKENDS:
            row = BatchRow(scenes, method, 0, len(problems), 0.0, 0.0, {}, None, f"method {method!r} is not registered")
            rows.append(row)
            say(f"batch {scenes} {method}: skipped ({row.skipped})")
            continue
        serial: list[Solution] | None = None
        for n_jobs in (1, 2):
            warm_up = problems[: min(50, max(8, len(problems) // 10))]
            solve_many(warm_up, method=method, n_jobs=n_jobs)  # discarded: worker start, imports, JIT
            t0 = time.perf_counter()
            solutions = solve_many(problems, method=method, n_jobs=n_jobs)
            seconds = time.perf_counter() - t0
            matches = None if serial is None else all(_same_answer(p, a, b) for p, a, b in zip(problems, solutions, serial, strict=True))
            if serial is None:
                serial = solutions
            row = BatchRow(
                scenes, method, n_jobs, len(problems), seconds, len(problems) / seconds, dict(Counter(s.status for s in solutions)), matches
            )
            rows.append(row)
            say(f"batch {scenes} {method} n_jobs={n_jobs}: {row.per_second:,.0f} solves/s")
    return rows


# --------------------------------------------------------------------------- summaries


def growth_exponents(rows: Sequence[Row]) -> dict[str, dict[str, float]]:
    """Least-squares slope of log(median time) against log(contacts), per family and method (>= 3 sizes)."""
    out: dict[str, dict[str, float]] = {}
    groups: dict[tuple[str, str], list[tuple[int, float]]] = {}
    for row in rows:
        if row.median is not None:
            groups.setdefault((row.family, row.method), []).append((row.contacts, row.median))
    for (family, method), points in groups.items():
        if len({c for c, _ in points}) >= 3:
            x = np.log([c for c, _ in points])
            y = np.log([t for _, t in points])
            out.setdefault(family, {})[method] = float(np.polyfit(x, y, 1)[0])
    return out


def machine_info() -> dict[str, Any]:
    """Cores, CPU model, Python and the numerical libraries' versions."""
    model = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as handle:
            for line in handle:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    versions: dict[str, str | None] = {}
    for package in ("quasistatic", "numpy", "scipy", "highspy", "pyscipopt", "numba", "joblib", "threadpoolctl", "pin", "coal"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    return {
        "cpu": model,
        "cores": usable,
        "load_average": None if load is None else [round(x, 2) for x in load],
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "versions": versions,
    }


def format_seconds(seconds: float | None) -> str:
    """A duration with a unit: 37 µs, 4.2 ms, 1.3 s."""
    if seconds is None or not math.isfinite(seconds):
        return "-"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def format_seconds_range(low: float | None, high: float | None) -> str:
    """Two durations in the unit of the larger: 82–138 µs, 1.22–1.27 ms."""
    if low is None or high is None:
        return "-"
    scale, unit = (1e6, "µs") if high < 1e-3 else (1e3, "ms") if high < 1.0 else (1.0, "s")
    return f"{low * scale:.3g}–{high * scale:.3g} {unit}"


def _progress_line(row: Row) -> str:
    what = f"{row.family} {row.size} {row.method}"
    if row.skipped:
        return f"{what}: skipped ({row.skipped})"
    return f"{what}: median {format_seconds(row.median)} over {row.samples} calls, {row.statuses}"
