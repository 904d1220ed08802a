"""Many solves at once: ``solve_many(problems)``, serially or over worker processes.

Worker processes: on Linux, when this process runs no other Python thread, the workers are forked after the items are in
memory, so they inherit the items instead of receiving them pickled (a
pickled Problem costs more than a fast solve of it), each gets contiguous
blocks of item indices, and only the solutions travel back. Elsewhere joblib
(the ``loky`` backend) ships the chunks of items to its workers.
"""

from __future__ import annotations

import gc
import multiprocessing
import os
import pickle
import sys
import threading
from collections.abc import Iterable, Sequence
from typing import Any

from .check import DEFAULT_TOLERANCE
from .errors import QuasistaticError
from .laws import Problem, assemble
from .model import Scene
from .solution import Solution
from .solve import solve
from .solvers import get_backend

__all__ = ["solve_many"]


def solve_many(
    problems: Iterable[Scene | Problem],
    method: str = "auto",
    n_jobs: int = 1,
    *,
    all_solutions: bool = False,
    max_solutions: int = 16,
    tolerance: float = DEFAULT_TOLERANCE,
    time_limit: float = 60.0,
    chunks_per_job: int = 4,
) -> list[Solution]:
    """Solve many scenes (or assembled problems), e.g. thousands of variants of one scene.

    Each item is solved exactly as :func:`quasistatic.solve` would solve it,
    audit included, and the solutions come back in input order. With
    ``n_jobs > 1`` the items are split into ``n_jobs * chunks_per_job``
    contiguous chunks solved in worker processes. On Linux, when no other
    Python thread runs, the workers are forked from this
    process after it has solved the first item (so imports and compiled
    kernels are inherited): they read their chunks from the inherited list
    and only the solutions are pickled back. Otherwise joblib (the ``loky``
    backend) pickles each chunk to its workers, which keep their solver
    state across chunks. Either way, starting workers costs milliseconds:
    for a few hundred fast solves, ``n_jobs=1`` is quicker.
    Pre-assembled :class:`~quasistatic.Problem` objects skip assembly;
    passing scenes includes it.

    Parameters
    ----------
    problems : iterable of Scene or Problem
        The items to solve; any mix of the two.
    method : str
        ``auto`` (default) or a backend name (see :data:`quasistatic.METHODS`),
        the same for every item.
    n_jobs : int
        Worker processes: 1 solves in this process (no joblib needed); -1
        uses every core; otherwise >= 1.
    all_solutions, max_solutions, tolerance, time_limit
        As in :func:`quasistatic.solve`, for every item.
    chunks_per_job : int
        Chunks handed to each worker (more balances uneven solve times,
        fewer lowers the overhead), >= 1.

    Returns
    -------
    list of Solution
        ``solutions[i]`` answers ``problems[i]``.

    Raises
    ------
    TypeError
        An item is neither a Scene nor a Problem (its index is named).
    ValueError
        An unknown method, or a bad ``n_jobs`` / ``chunks_per_job``.
    QuasistaticError
        As :func:`quasistatic.solve` raises for an item (e.g. ``lp`` on a
        frictional scene); the item's index is added to the message.
    """
    items = list(problems)
    for index, item in enumerate(items):
        if not isinstance(item, (Scene, Problem)):
            raise TypeError(f"problems[{index}]: expected a Scene or a Problem, got {type(item).__name__}")
    if method != "auto":
        get_backend(method)
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, int) or n_jobs == 0 or n_jobs < -1:
        raise ValueError(f"n_jobs must be a positive number of processes or -1 (every core), got {n_jobs!r}")
    if isinstance(chunks_per_job, bool) or not isinstance(chunks_per_job, int) or chunks_per_job < 1:
        raise ValueError(f"chunks_per_job must be an integer >= 1, got {chunks_per_job!r}")
    options: dict[str, Any] = {
        "all_solutions": all_solutions,
        "max_solutions": max_solutions,
        "tolerance": tolerance,
        "time_limit": time_limit,
    }
    if n_jobs == 1 or len(items) <= 1:
        return _solve_chunk(items, 0, method, options)
    if _can_fork():
        workers = len(os.sched_getaffinity(0)) if n_jobs == -1 else n_jobs
        return _solve_forked(items, workers, chunks_per_job, method, options)
    try:
        import joblib
    except ImportError as exc:  # a declared dependency; only a broken install lacks it
        raise ImportError("solve_many(n_jobs != 1) needs joblib: pip install 'joblib>=1.3'") from exc
    workers = joblib.cpu_count() if n_jobs == -1 else n_jobs
    size = max(1, -(-len(items) // (workers * chunks_per_job)))
    starts = range(0, len(items), size)
    parallel = joblib.Parallel(n_jobs=workers, backend="loky")
    results = parallel(joblib.delayed(_solve_chunk)(items[s : s + size], s, method, options) for s in starts)
    return [solution for chunk in results for solution in chunk]


def _solve_chunk(items: Sequence[Scene | Problem], offset: int, method: str, options: dict[str, Any]) -> list[Solution]:
    solutions = []
    for index, item in enumerate(items, start=offset):
        problem = item if isinstance(item, Problem) else assemble(item)
        try:
            solutions.append(solve(problem, method=method, **options))
        except Exception as exc:
            exc.add_note(f"while solving problems[{index}]")
            raise
    return solutions


# --------------------------------------------------------------------------- forked workers

_WORKER_ITEMS: list[Scene | Problem] = []  # in a forked worker only: the parent's items, set once at its start


def _can_fork() -> bool:
    """Linux (macOS system libraries are not fork-safe), and no other Python thread could hold a lock across the fork."""
    return sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1


def _solve_forked(items: list[Scene | Problem], workers: int, chunks_per_job: int, method: str, options: dict[str, Any]) -> list[Solution]:
    """Solve the first item here (imports, JIT code and caches are then inherited), the rest in forked workers."""
    first = _solve_chunk(items[:1], 0, method, options)
    rest = len(items) - 1
    size = max(1, -(-rest // (workers * chunks_per_job)))
    blocks = [(start, min(start + size, len(items)), method, options) for start in range(1, len(items), size)]
    # Frozen objects are left out of garbage collection: the workers do not traverse (and so do not
    # copy) the heap they inherit, and neither process re-traverses it while solutions are pickled.
    gc.freeze()
    try:
        # A forked worker's initializer arguments are inherited, not pickled.
        with multiprocessing.get_context("fork").Pool(min(workers, len(blocks)), _adopt_items, (items,)) as pool:
            results = pool.starmap(_solve_inherited, blocks, chunksize=1)
    finally:
        gc.unfreeze()
    solutions = list(first)
    for ok, value in results:
        if not ok:
            raise value
        solutions += value
    return solutions


def _adopt_items(items: list[Scene | Problem]) -> None:
    """In a forked worker, at its start: keep the parent's items (inherited with the process, never pickled)."""
    _WORKER_ITEMS[:] = items


def _solve_inherited(start: int, stop: int, method: str, options: dict[str, Any]) -> tuple[bool, Any]:
    """In a forked worker: solve ``items[start:stop]`` of the inherited list.

    Returns ``(True, solutions)``, or ``(False, exception)`` with the item's
    index in its notes; an exception that would not survive pickling is
    replaced by a QuasistaticError that names it.
    """
    try:
        return True, _solve_chunk(_WORKER_ITEMS[start:stop], start, method, options)
    except Exception as exc:
        try:
            pickle.loads(pickle.dumps(exc))
            return False, exc
        except Exception:
            error = QuasistaticError(f"{type(exc).__name__}: {exc}")
            for note in getattr(exc, "__notes__", ()):
                error.add_note(note)
            return False, error
