"""Where a sweep's chunks are solved: in this process, in joblib's local workers, or on a Dask cluster.

Each chunk travels as a :class:`Chunk` (the scene file's data and a few
numbers per point, a few kilobytes), is solved by :func:`solve_chunk` in the
worker, and comes back as its points. Chunks are yielded as they finish, so the
caller can store them and show progress.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from typing import Any

from ..errors import BackendUnavailableError, QuasistaticError
from ..solution import Solution
from ..solve import solve
from .batched import batched_points
from .params import SweepParam
from .result import SWEEPS_INSTALL_HINT, SweepPoint, point_from_solution
from .scenes import PointScenes, scene_at

__all__ = ["Chunk", "Executor", "executor_for", "scene_at", "solve_chunk"]

_CONNECT_SECONDS = 10  # how long a scheduler address is tried before the sweep gives up


@dataclass(frozen=True)
class Chunk:
    """A block of points to solve, self-contained so it can be pickled to a worker.

    Attributes
    ----------
    name : str
        The chunk's name in the chunk store (``grid-00012``, ``refine-2-00000``).
    data : mapping
        The scene file's keys, before any parameter is set.
    folder : str
        The folder the file's relative paths (meshes, URDFs) start from.
    params : tuple of SweepParam
        The grid's axes (their paths are set at each point).
    points : tuple of (int, tuple of float, bool)
        Each point's index, parameter values and whether it is a refinement point.
    options : mapping
        Keyword arguments of :func:`quasistatic.solve`.
    """

    name: str
    data: Mapping[str, Any]
    folder: str
    params: tuple[SweepParam, ...]
    points: tuple[tuple[int, tuple[float, ...], bool], ...]
    options: Mapping[str, Any]


def solve_chunk(chunk: Chunk) -> tuple[str, list[SweepPoint]]:
    """Solve every point of a chunk (audited, as :func:`quasistatic.solve` does); a point whose scene or solve
    fails is recorded as ``failed`` with the reason, so one bad corner does not lose the sweep. Points of one planar
    shape are first decided together where the batch proves them (:mod:`.batched`, the same records); the rest one
    by one."""
    points = []
    scenes = PointScenes(chunk.data, chunk.folder, chunk.params)  # the file validated once per chunk
    decided = batched_points(scenes, chunk.points, chunk.options)  # the points proven together, by position
    for position, (index, values, refinement) in enumerate(chunk.points):
        if position in decided:
            points.append(decided[position])
            continue
        start = time.perf_counter()
        try:
            solution = solve(scenes.at(values), **chunk.options)
        except QuasistaticError as exc:  # SceneError and SolverError included
            method = str(chunk.options.get("method", "auto"))
            solution = Solution("failed", f"not solved at this point: {exc}", method, "", seconds=time.perf_counter() - start)
        points.append(point_from_solution(index, values, refinement, solution))
    return chunk.name, points


class Executor:
    """Runs chunks and yields ``(name, points)`` as each finishes; a context manager that frees its workers."""

    def __init__(self, jobs: int = 1, dask: Any = None) -> None:
        self.jobs = jobs
        self.dask = dask
        self._stack = ExitStack()
        self._client: Any = None

    def __enter__(self) -> Executor:
        if self.dask is not None:
            self._client = self._stack.enter_context(_dask_client(self.dask))
        return self

    def __exit__(self, *exc: object) -> None:
        self._stack.close()

    def run(self, chunks: Sequence[Chunk]) -> Iterator[tuple[str, list[SweepPoint]]]:
        if not chunks:
            return iter(())
        if self._client is not None:
            return _run_dask(self._client, chunks)
        if self.jobs != 1 and len(chunks) > 1:
            return _run_joblib(self.jobs, chunks)
        return (solve_chunk(chunk) for chunk in chunks)


def executor_for(jobs: int, dask: Any) -> Executor:
    """The executor for ``jobs`` local processes (1: this process; -1: every core) or a Dask cluster.

    ``dask`` is a ``distributed.Client``, a scheduler address (``tcp://host:8786``) or ``local:N``
    (a LocalCluster of N single-threaded worker processes, started and stopped with the sweep).

    Raises
    ------
    ValueError
        A bad ``jobs`` or ``dask``.
    BackendUnavailableError
        ``dask`` given without the ``sweeps`` extra.
    """
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs == 0 or jobs < -1:
        raise ValueError(f"jobs must be a positive number of processes or -1 (every core), got {jobs!r}")
    if isinstance(dask, str):
        _local_workers(dask)  # checks the text before anything starts
    return Executor(jobs, dask)


def _run_joblib(jobs: int, chunks: Sequence[Chunk]) -> Iterator[tuple[str, list[SweepPoint]]]:
    import joblib

    parallel = joblib.Parallel(n_jobs=jobs, backend="loky", return_as="generator_unordered")
    yield from parallel(joblib.delayed(solve_chunk)(chunk) for chunk in chunks)


def _run_dask(client: Any, chunks: Sequence[Chunk]) -> Iterator[tuple[str, list[SweepPoint]]]:
    from distributed import as_completed

    futures = client.map(solve_chunk, list(chunks), pure=False)
    for future in as_completed(futures):
        yield future.result()


def _dask_client(spec: Any) -> Any:
    """A context manager giving a Client: the one passed (left open), one connected to an address, or a LocalCluster."""
    from contextlib import nullcontext

    try:
        import distributed
    except ImportError as exc:
        raise BackendUnavailableError("dask", SWEEPS_INSTALL_HINT, needed_for="sweeps on a Dask cluster") from exc
    if not isinstance(spec, str):
        return nullcontext(spec)
    workers = _local_workers(spec)
    if workers is None:
        try:
            return distributed.Client(spec, timeout=_CONNECT_SECONDS)
        except (OSError, TimeoutError) as exc:
            raise QuasistaticError(f"--dask {spec!r}: cannot reach the Dask scheduler ({exc})") from None
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    return _ClusterClient(cluster, distributed.Client(cluster))


class _ClusterClient:
    """A Client and the LocalCluster it owns, closed together."""

    def __init__(self, cluster: Any, client: Any) -> None:
        self.cluster, self.client = cluster, client

    def __enter__(self) -> Any:
        return self.client

    def __exit__(self, *exc: object) -> None:
        self.client.close()
        self.cluster.close()


def _local_workers(spec: str) -> int | None:
    """N for ``local:N``; None for a scheduler address."""
    if spec.startswith("local:"):
        count = spec.removeprefix("local:")
        if not count.isdigit() or int(count) < 1:
            raise ValueError(f"--dask {spec!r}: write local:N with N >= 1 worker processes")
        return int(count)
    if "://" not in spec and ":" not in spec:
        raise ValueError(f"--dask {spec!r}: give a scheduler address (tcp://host:8786) or local:N")
    return None
