"""``sweep()``: one scene solved over a grid of parameter values, in chunks, resumable, with refined boundaries."""

from __future__ import annotations

import itertools
import math
import os
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..check import DEFAULT_TOLERANCE
from ..errors import SceneError
from ..model import Scene
from ..model.io import read_scene_data, read_scene_file, scene_to_dict
from ..solvers import get_backend
from .backends import Chunk, Executor, executor_for
from .params import SweepParam, sweep_params
from .refine import boundary_intervals, narrowed
from .result import PhaseKind, SweepPoint, SweepResult
from .scenes import PointScenes
from .store import ChunkStore, sweep_key

__all__ = ["Progress", "sweep", "UNDECIDED_MESSAGES"]

Progress = Callable[[int, int], None]
"""Called after each finished chunk with (points done, points planned so far)."""

UNDECIDED_MESSAGES = 4096
"""Most points whose message (its claim about the forces) waits to be worked out when read: each keeps its solve's
Problem until then (about 10 KiB on a small 2-D scene), so older points' messages are worked out as the sweep goes on."""


def sweep(
    scene: Scene | str | Path | Mapping[str, Any],
    params: Mapping[str, Any],
    *,
    method: str = "auto",
    certify: bool = True,
    all_solutions: bool | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
    time_limit: float = 60.0,
    jobs: int = 1,
    dask: Any = None,
    chunk_size: int | None = None,
    chunk_dir: str | Path | None = None,
    resume: bool = False,
    refine: int = 0,
    phase: PhaseKind = "status",
    progress: Progress | None = None,
) -> SweepResult:
    """Solve a scene at every point of a grid of parameter values (the Cartesian product).

    Every point is solved as :func:`quasistatic.solve` solves a scene, audit
    included; a point whose scene or solve fails is recorded as ``failed``
    with the reason.

    Parameters
    ----------
    scene : Scene, path or mapping
        The scene: a Scene, a scene file (one of shapes or URDF robots has its contacts found at
        every point), or a dict of its keys.
    params : mapping
        Parameter path -> values, e.g. ``{"contacts[2].mu": np.linspace(0, 1, 101)}``. A path names one number of
        the scene file: ``bodies.box.mass``, ``movers.pusher.twist[0]``, ``contacts[2].point[1]``,
        ``robots.hand.joint_velocities.j1`` (a named joint); paths joined by commas move together.
    method, certify, all_solutions, tolerance, time_limit
        As in :func:`quasistatic.solve`, at every point.
    jobs : int
        Local worker processes (joblib): 1 solves here; -1 uses every core.
    dask : distributed.Client, str or None
        Solve on a Dask cluster instead: a Client, a scheduler address (``tcp://host:8786``) or ``local:N``
        (a LocalCluster of N worker processes for this sweep). Needs the ``sweeps`` extra.
    chunk_size : int or None
        Points per chunk (default: about 4 chunks per worker, at most 256 points each).
    chunk_dir : path or None
        Keep each finished chunk here (Parquet, in a folder named by a hash of the scene, grid and options).
    resume : bool
        Reuse the chunks already in ``chunk_dir`` instead of solving them again.
    refine : int
        Bisections between each pair of grid neighbours whose phases differ (0: none); each adds a
        refinement point, so the boundary is located to ``spacing / 2**refine``.
    phase : {"status", "modes"}
        What a phase is for refinement: the status alone, or the status and every contact's mode
        (``modes`` tells tipping from sliding).
    progress : callable or None
        Called as ``progress(done, planned)`` after each chunk.

    Returns
    -------
    SweepResult

    Raises
    ------
    SceneError
        Naming the parameter path that does not lead to a number of the scene, or whose values
        the scene rejects.
    ValueError
        An unknown method, a bad ``jobs``, ``chunk_size``, ``refine`` or ``phase``, or ``resume`` without ``chunk_dir``.
    BackendUnavailableError
        ``dask`` or ``chunk_dir`` without the ``sweeps`` extra (dask, pyarrow).
    """
    data, folder = _scene_data(scene)
    axes = sweep_params(data, params)
    _check_options(method, chunk_size, refine, phase, resume, chunk_dir)
    _check_values(data, folder, axes)
    options = {"method": method, "certify": certify, "all_solutions": all_solutions, "tolerance": tolerance, "time_limit": time_limit}
    store = ChunkStore(Path(chunk_dir) / sweep_key(data, folder, axes, options)) if chunk_dir is not None else None
    if store is not None and not resume:
        store.clear()
    run = _Run(data, folder, axes, options, store, progress)
    grid = list(itertools.product(*(p.values.tolist() for p in axes)))
    size = chunk_size or _default_chunk(len(grid), jobs)
    with executor_for(jobs, dask) as executor:
        points = run.solve(executor, "grid", [(i, tuple(v), False) for i, v in enumerate(grid)], size)
        result = SweepResult(axes, tuple(points))
        intervals = boundary_intervals(result, phase)
        for round_ in range(1, refine + 1):
            if not intervals:
                break
            start = len(points)
            tasks = [(start + k, interval.midpoint(), True) for k, interval in enumerate(intervals)]
            middles = run.solve(executor, f"refine-{round_}", tasks, size)
            points += middles
            intervals = narrowed(intervals, middles, phase)
    return SweepResult(axes, tuple(points), reused=run.reused)


class _Run:
    """The chunks of one sweep: planned, looked up in the store, solved, stored, counted."""

    def __init__(
        self,
        data: Mapping[str, Any],
        folder: str,
        axes: tuple[SweepParam, ...],
        options: Mapping[str, Any],
        store: ChunkStore | None,
        progress: Progress | None,
    ) -> None:
        self.data, self.folder, self.axes, self.options = data, folder, axes, options
        self.store, self.progress = store, progress
        self.done = self.planned = self.reused = 0
        self.undecided: deque[SweepPoint] = deque()

    def solve(self, executor: Executor, stage: str, tasks: Sequence[tuple[int, tuple[float, ...], bool]], size: int) -> list[SweepPoint]:
        """The points of ``tasks``, in order: stored chunks read back, the others solved and stored."""
        chunks = [
            Chunk(f"{stage}-{k:05d}", self.data, self.folder, self.axes, tuple(tasks[s : s + size]), self.options)
            for k, s in enumerate(range(0, len(tasks), size))
        ]
        self.planned += len(tasks)
        found: dict[str, list[SweepPoint]] = {}
        todo = []
        for chunk in chunks:
            stored = self.store.load(chunk.name) if self.store is not None else None
            if stored is not None and [p.index for p in stored] == [t[0] for t in chunk.points]:
                found[chunk.name] = stored
                self.reused += len(stored)
                self._count(len(stored))
            else:
                todo.append(chunk)
        for name, points in self._finished(executor, todo):
            found[name] = points
        return [point for chunk in chunks for point in found[chunk.name]]

    def _finished(self, executor: Executor, todo: list[Chunk]) -> Iterator[tuple[str, list[SweepPoint]]]:
        for name, points in executor.run(todo):
            if self.store is not None:
                self.store.save(name, points)
            self._hold(points)
            self._count(len(points))
            yield name, points

    def _hold(self, points: list[SweepPoint]) -> None:
        """Keep at most :data:`UNDECIDED_MESSAGES` points' messages waiting (a worker's points come decided)."""
        self.undecided.extend(points)
        while len(self.undecided) > UNDECIDED_MESSAGES:
            _ = self.undecided.popleft().message  # worked out now, so its Problem is let go

    def _count(self, points: int) -> None:
        self.done += points
        if self.progress is not None:
            self.progress(self.done, self.planned)


def _scene_data(scene: Scene | str | Path | Mapping[str, Any]) -> tuple[dict[str, Any], str]:
    """The scene file's keys and the folder its relative paths start from."""
    if isinstance(scene, Scene):
        return scene_to_dict(scene), str(Path.cwd())
    if isinstance(scene, (str, Path)):
        return dict(read_scene_data(Path(scene))), str(Path(scene).resolve().parent)
    if isinstance(scene, Mapping):
        read_scene_file(scene)  # the keys are checked before any path is followed
        return dict(scene), str(Path.cwd())
    raise TypeError(f"scene: expected a Scene, a scene file path or a dict of its keys, got {type(scene).__name__}")


def _check_options(method: str, chunk_size: int | None, refine: int, phase: str, resume: bool, chunk_dir: Any) -> None:
    if method != "auto":
        get_backend(method)
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size must be an integer >= 1, got {chunk_size!r}")
    if isinstance(refine, bool) or not isinstance(refine, int) or not 0 <= refine <= 30:
        raise ValueError(f"refine must be an integer from 0 to 30 bisections, got {refine!r}")
    if phase not in ("status", "modes"):
        raise ValueError(f"phase must be 'status' or 'modes', got {phase!r}")
    if resume and chunk_dir is None:
        raise ValueError("resume needs chunk_dir: the folder where the finished chunks were kept")


def _check_values(data: Mapping[str, Any], folder: str, axes: tuple[SweepParam, ...]) -> None:
    """Every value of every parameter, set alone on the scene, gives a valid scene; else the error names the path."""
    base = [float(p.values[0]) for p in axes]
    scenes = PointScenes(data, folder, axes)
    for position, param in enumerate(axes):
        for value in dict.fromkeys(param.values.tolist()):
            values = [*base[:position], value, *base[position + 1 :]]
            try:
                scenes.at(values)
            except SceneError as exc:
                raise SceneError(param.name, value, f"the scene rejects this value ({exc.field}: {exc.reason})") from None


def _default_chunk(points: int, jobs: int) -> int:
    """About four chunks per worker (uneven solve times balance), at most 256 points (progress and resume stay fine)."""
    workers = (os.cpu_count() or 1) if jobs == -1 else max(jobs, 1)
    return max(1, min(256, math.ceil(points / (4 * workers))))
