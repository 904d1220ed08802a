"""The one verb: ``solve(scene)``. Dispatches to a backend, then audits every motion."""

from __future__ import annotations

import dataclasses
import functools
import sys
from collections.abc import Sequence
from types import ModuleType

from .audit import DEFAULT_TOLERANCE
from .backends.base import BackendResult, Options
from .backends.registry import BACKENDS, Backend, Solver, get_backend
from .errors import QuasistaticError
from .evaluate import derived, to_motion
from .problem import Problem, assemble
from .scene import Scene
from .solution import Mode, Motion, Solution

__all__ = ["solve", "METHODS"]

METHODS = ("auto", "lp", "fast", "scip", "paper")
_MODE_NAMES = ("rolling", "sliding", "separating")


def solve(
    scene: Scene | Problem,
    method: str = "auto",
    *,
    modes: Sequence[Mode | None] | None = None,
    all_solutions: bool = False,
    max_solutions: int = 16,
    tolerance: float = DEFAULT_TOLERANCE,
    time_limit: float = 60.0,
) -> Solution:
    """Predict the quasi-static motion of the free bodies of a scene.

    Parameters
    ----------
    scene : Scene or Problem
        A validated scene (or one already assembled, to solve it again cheaply).
    method : str
        ``auto`` (default) or a backend name from :data:`METHODS`. ``auto``
        solves frictionless scenes by LP (certified) and frictional ones by
        the fast path first; when the fast path finds no audited motion, or
        when ``all_solutions`` or ``modes`` are given, by the certified search.
    modes : sequence of {"rolling", "sliding", "separating", None}, optional
        Prescribe contact modes, one entry per contact (None leaves it free).
    all_solutions : bool
        Certify the answer: list every motion (``ambiguous`` when there are
        several) instead of returning the first audited one the fast path finds.
    max_solutions : int
        Most distinct motions listed when the answer is ``ambiguous``.
    tolerance : float
        Audit threshold on every scene-relative residual [-].
    time_limit : float
        Seconds a certified search may take [s].

    Returns
    -------
    Solution
        Every motion in it has been audited on the original scene data.
    """
    problem = scene if isinstance(scene, Problem) else assemble(scene)
    checked = _check_modes(modes, problem)
    options = _options(max_solutions, time_limit) if checked is None else Options(max_solutions, checked, time_limit)
    names = _choose(method, problem, checked is not None, all_solutions)
    fallback: dict[str, str] = {}
    for name in names:
        backend = get_backend(name)
        if backend.frictionless_only and not _is_frictionless(problem):
            raise QuasistaticError(
                f"method {name!r} is frictionless but contacts {_frictional(problem)} have mu > 0; "
                "use method 'auto', or set 'friction: none' to drop friction on purpose"
            )
        solution = _audited(problem, _load(backend)(problem, options), name, tolerance)
        if fallback:
            solution = dataclasses.replace(solution, details={**solution.details, "fallback": fallback})
        if solution.ok or name == names[-1]:
            return solution
        fallback[name] = solution.message
    raise AssertionError("unreachable: the last method always returns")


def _choose(method: str, problem: Problem, modes_given: bool, all_solutions: bool) -> tuple[str, ...]:
    """Methods to try in order; a later one runs only when the earlier one found no audited motion."""
    if method != "auto":
        get_backend(method)
        if modes_given and method != "scip":
            raise ValueError(f"modes: method {method!r} cannot prescribe contact modes; use method 'auto' or 'scip'")
        if all_solutions and method in ("fast", "paper"):
            raise ValueError(f"all_solutions: method {method!r} finds one motion; use method 'auto' or 'scip'")
        return (method,)
    if _is_frictionless(problem) and not modes_given:
        return ("lp",)
    if modes_given or all_solutions or "fast" not in BACKENDS:
        return ("scip",)
    return ("fast", "scip")


@functools.lru_cache(maxsize=64)
def _options(max_solutions: int, time_limit: float) -> Options:
    """Options without prescribed modes (frozen, so one object serves every solve that uses them)."""
    return Options(max_solutions=max_solutions, time_limit=time_limit)


def _load(backend: Backend) -> Solver:
    """``backend.load()``, whose import (and availability check) runs once per registry entry."""
    module = _MODULES.get(backend)
    if module is None:
        # load() raises BackendUnavailableError with the install hint when the backend is missing.
        module = _MODULES[backend] = sys.modules[getattr(backend.load(), "__module__", "")]
    solver: Solver = getattr(module, backend.function)
    return solver


_MODULES: dict[Backend, ModuleType] = {}


def _is_frictionless(problem: Problem) -> bool:
    return derived(problem, "frictionless", lambda p: p.is_frictionless)


def _frictional(problem: Problem) -> list[int]:
    return [i for i, mu in enumerate(problem.mu) if mu > 0]


def _check_modes(modes: Sequence[Mode | None] | None, problem: Problem) -> tuple[Mode | None, ...] | None:
    if modes is None:
        return None
    modes = tuple(modes)
    if len(modes) != problem.n_contacts:
        raise ValueError(f"modes: expected {problem.n_contacts} entries (one per contact), got {len(modes)}")
    for i, mode in enumerate(modes):
        if mode is not None and mode not in _MODE_NAMES:
            raise ValueError(f"modes[{i}]: {mode!r} is not one of rolling, sliding, separating (or None)")
    return modes


def _audited(problem: Problem, result: BackendResult, method: str, tolerance: float) -> Solution:
    """Turn raw motions into audited ones; a motion that fails its audit is never a success."""
    friction = str(problem.friction)
    motions: list[Motion] = []
    for raw in result.motions:
        ranges = result.force_ranges if len(result.motions) == 1 else None
        motion = to_motion(problem, raw, ranges, tolerance)
        motions.append(motion)
    failed = [m for m in motions if not m.audit.passed]
    if failed:
        laws = ", ".join(sorted({law for m in failed for law in m.audit.failures()}))
        return Solution(
            "failed",
            f"failed: {method} returned a motion that violates the laws ({laws}); it is not reported as a solution",
            method,
            friction,
            motion=failed[0],
            details=result.details,
        )
    primary = motions[0] if motions else None
    solutions = tuple(motions) if result.status == "ambiguous" else ()
    return Solution(
        result.status,
        result.message,
        method,
        friction,
        motion=primary,
        solutions=solutions,
        forces_indeterminate=result.force_ranges is not None and result.status == "solved",
        details=result.details,
    )
