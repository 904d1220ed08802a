"""Many solves at once: ``solve_many(problems)``, serially or over worker processes.

Worker processes: on Linux, when this process runs no other Python thread, the workers are forked after the items are in
memory, so they inherit the items instead of receiving them pickled (a
pickled Problem costs more than a fast solve of it), each gets contiguous
blocks of item indices, and only the solutions travel back. Elsewhere joblib
(the ``loky`` backend) ships the chunks of items to its workers.
"""

from __future__ import annotations

import dataclasses
import gc
import multiprocessing
import os
import pickle
import queue
import sys
import threading
from collections.abc import Iterable, Sequence
from typing import Any

from .check import DEFAULT_TOLERANCE
from .derivative import SolvedScene
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
    certify: bool = True,
    all_solutions: bool | None = None,
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
    certify, all_solutions, max_solutions, tolerance, time_limit
        As in :func:`quasistatic.solve`, for every item (``certify=False`` for the
        fast path's first motion, the fastest for large batches).
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
        "certify": certify,
        "all_solutions": all_solutions,
        "max_solutions": max_solutions,
        "tolerance": tolerance,
        "time_limit": time_limit,
    }
    if n_jobs == 1 or len(items) <= 1:
        return _solve_chunk(items, 0, method, options)
    if _can_fork():
        workers = len(os.sched_getaffinity(0)) if n_jobs == -1 else n_jobs
        return _with_scenes(_solve_forked(items, workers, chunks_per_job, method, options), items)
    try:
        import joblib
    except ImportError as exc:  # a declared dependency; only a broken install lacks it
        raise ImportError("solve_many(n_jobs != 1) needs joblib: pip install 'joblib>=1.3'") from exc
    workers = joblib.cpu_count() if n_jobs == -1 else n_jobs
    size = max(1, -(-len(items) // (workers * chunks_per_job)))
    starts = range(0, len(items), size)
    parallel = joblib.Parallel(n_jobs=workers, backend="loky")
    results = parallel(joblib.delayed(_solve_chunk)(items[s : s + size], s, method, options) for s in starts)
    return _with_scenes([solution for chunk in results for solution in chunk], items)


def _with_scenes(solutions: list[Solution], items: Sequence[Scene | Problem]) -> list[Solution]:
    """Each solution with its scene attached again (a Solution is pickled without it), so ``sensitivity()`` works."""
    return [
        dataclasses.replace(solution, source=SolvedScene(item.scene if isinstance(item, Problem) else item))
        for solution, item in zip(solutions, items, strict=True)
    ]


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


def _can_fork() -> bool:
    """Linux (macOS system libraries are not fork-safe), and no other Python thread could hold a lock across the fork."""
    return sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1


def _solve_forked(items: list[Scene | Problem], workers: int, chunks_per_job: int, method: str, options: dict[str, Any]) -> list[Solution]:
    """Solve the first item here (imports, JIT code and caches are then inherited), the rest in forked workers.

    Each worker is forked with the items as its argument (inherited, never
    pickled) and takes blocks of indices from a queue until none is left;
    only the solutions travel back.
    """
    first = _solve_chunk(items[:1], 0, method, options)
    rest = len(items) - 1
    size = max(1, -(-rest // (workers * chunks_per_job)))
    blocks = [(start, min(start + size, len(items))) for start in range(1, len(items), size)]
    context = multiprocessing.get_context("fork")
    tasks: Any = context.Queue()
    done: Any = context.Queue()
    count = min(workers, len(blocks))
    # Frozen objects are left out of garbage collection: the workers do not traverse (and so do not
    # copy) the heap they inherit, and neither process re-traverses it while solutions are pickled.
    gc.freeze()
    try:
        processes = [context.Process(target=_worker, args=(items, tasks, done, method, options), daemon=True) for _ in range(count)]
        for process in processes:
            process.start()
        # Tasks go in after the fork: the queue's feeder thread must not exist when the workers are forked.
        for index, block in enumerate(blocks):
            tasks.put((index, *block))
        for _ in range(count):
            tasks.put(None)  # one stop sign per worker
        answers = _collect(done, len(blocks), processes)
        for process in processes:
            process.join()
    finally:
        gc.unfreeze()
        # The task queue's feeder thread must end with this call: a thread left running would keep
        # the next call from forking (it falls back to joblib, which pickles every item).
        tasks.close()
        tasks.join_thread()
    solutions = list(first)
    for index in range(len(blocks)):
        ok, value = answers[index]
        if not ok:
            raise value
        solutions += value
    return solutions


def _collect(done: Any, expected: int, processes: list[Any]) -> dict[int, tuple[bool, Any]]:
    """Every block's answer from the workers; a worker that dies without answering is an error, not a hang."""
    answers: dict[int, tuple[bool, Any]] = {}
    while len(answers) < expected:
        try:
            index, answer = done.get(timeout=0.5)
        except queue.Empty:
            dead = [p.exitcode for p in processes if p.exitcode not in (None, 0)]
            if dead:
                raise QuasistaticError(f"a solve_many worker process died (exit code {dead[0]}) before answering") from None
            continue
        answers[index] = answer
    return answers


def _worker(items: list[Scene | Problem], tasks: Any, done: Any, method: str, options: dict[str, Any]) -> None:
    """In a forked worker: solve blocks of the inherited ``items`` until the stop sign."""
    while (task := tasks.get()) is not None:
        index, start, stop = task
        done.put((index, _solve_block(items, start, stop, method, options)))


def _solve_block(items: list[Scene | Problem], start: int, stop: int, method: str, options: dict[str, Any]) -> tuple[bool, Any]:
    """Solve ``items[start:stop]``.

    Returns ``(True, solutions)``, or ``(False, exception)`` with the item's
    index in its notes; an exception that would not survive pickling is
    replaced by a QuasistaticError that names it.
    """
    try:
        return True, _solve_chunk(items[start:stop], start, method, options)
    except Exception as exc:
        try:
            pickle.loads(pickle.dumps(exc))
            return False, exc
        except Exception:
            error = QuasistaticError(f"{type(exc).__name__}: {exc}")
            for note in getattr(exc, "__notes__", ()):
                error.add_note(note)
            return False, error
