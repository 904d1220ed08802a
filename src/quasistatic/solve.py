"""The one verb: ``solve(scene)``. Dispatches to a backend, then audits every motion."""

from __future__ import annotations

from collections.abc import Sequence

from .audit import DEFAULT_TOLERANCE
from .backends.base import BackendResult, Options
from .backends.registry import get_backend
from .errors import QuasistaticError
from .evaluate import to_motion
from .problem import Problem, assemble
from .scene import Scene
from .solution import Mode, Motion, Solution

__all__ = ["solve", "METHODS"]

METHODS = ("auto", "lp", "scip")
_MODE_NAMES = ("rolling", "sliding", "separating")


def solve(
    scene: Scene | Problem,
    method: str = "auto",
    *,
    modes: Sequence[Mode | None] | None = None,
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
        ``auto`` (default) or a backend name from :data:`METHODS`.
    modes : sequence of {"rolling", "sliding", "separating", None}, optional
        Prescribe contact modes, one entry per contact (None leaves it free).
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
    options = Options(max_solutions=max_solutions, modes=_check_modes(modes, problem), time_limit=time_limit)
    name = _choose(method, problem, options.modes is not None)
    backend = get_backend(name)
    if backend.frictionless_only and not problem.is_frictionless:
        raise QuasistaticError(
            f"method {name!r} is frictionless but contacts {_frictional(problem)} have mu > 0; "
            "use method 'auto', or set 'friction: none' to drop friction on purpose"
        )
    result = backend.load()(problem, options)
    return _audited(problem, result, name, tolerance)


def _choose(method: str, problem: Problem, modes_given: bool) -> str:
    if method != "auto":
        if modes_given and method == "lp":
            raise ValueError("modes: method 'lp' cannot prescribe contact modes; use method 'auto' or 'scip'")
        get_backend(method)
        return method
    if problem.is_frictionless and not modes_given:
        return "lp"
    return "scip"


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
