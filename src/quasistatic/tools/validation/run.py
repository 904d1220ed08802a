"""Running cases: a solve compared with its expectation, a bisection for a threshold, and the Whitney grid."""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import quasistatic as qs

from .cases import DEFAULT_FOLDER, Case, CaseResult, load_cases
from .report import describe_expectation, describe_kind, describe_motion, describe_solution, format_modes, format_ranges, format_vector
from .scenes import ladder_deg, push_height, scene_data, slope_deg, to_spatial
from .whitney import run_whitney_grid, tip_moment

Setter = Callable[[dict[str, Any], float, Mapping[str, Any]], None]

#: The scene parameters a ``bisect`` case can vary (its ``vary`` key), each setting one value in a scene dict.
SETTERS: dict[str, Setter] = {
    "slope_deg": slope_deg,
    "ladder_deg": ladder_deg,
    "push_height": push_height,
    "tip_moment": tip_moment,
}


def run_validation(
    folder: str | Path = DEFAULT_FOLDER,
    *,
    include_slow: bool = True,
    select: Callable[[Case], bool] | None = None,
) -> list[CaseResult]:
    """Run every case of a validation folder (the ``validation/`` of a clone by default).

    Parameters
    ----------
    folder : path
        Folder holding ``cases.yaml`` and the scene files.
    include_slow : bool
        Also run the cases marked slow (3-D runs, bisections, sweeps).
    select : callable, optional
        Keep only the cases for which it returns True.

    Returns
    -------
    list of CaseResult
        In the order of ``cases.yaml``.
    """
    results = []
    for case in load_cases(folder):
        if (case.slow and not include_slow) or (select is not None and not select(case)):
            continue
        results.append(run_case(case))
    return results


def run_case(case: Case) -> CaseResult:
    """Run one case; a library exception becomes a failed result that names it.

    Parameters
    ----------
    case : Case

    Returns
    -------
    CaseResult
    """
    start = time.perf_counter()
    expected = describe_expectation(case)
    try:
        if case.check == "bisect":
            got, failures = _run_bisection(case)
        elif case.check == "whitney-grid":
            got, failures = run_whitney_grid(case)
        else:
            got, failures = _run_solve(case)
    except Exception as exc:  # noqa: BLE001 - a crash in one case must not hide the others
        error = f"{type(exc).__name__}: {exc}"
        return CaseResult(case, expected, f"error: {error}", False, (error,), time.perf_counter() - start, error)
    return CaseResult(case, expected, got, not failures, tuple(failures), time.perf_counter() - start)


def _solve_case(case: Case, data: Mapping[str, Any] | None = None) -> qs.Solution:
    """Solve a case's scene (or ``data``) with its prescribed modes, each doubled for an extruded run."""
    scene = qs.load_scene(scene_data(case) if data is None else data)
    modes = case.modes
    if modes is not None and case.depth is not None:
        modes = tuple(m for m in modes for _ in range(2))
    return qs.solve(scene, modes=modes, all_solutions=True)  # validation checks the certified answer


def _groups(case: Case, n_planar: int) -> list[list[int]]:
    """Indices of the contacts that stand for each planar contact (a pair when extruded)."""
    if case.depth is None:
        return [[i] for i in range(n_planar)]
    return [[2 * i, 2 * i + 1] for i in range(n_planar)]


def _run_solve(case: Case) -> tuple[str, list[str]]:
    """Check a ``solve`` case: its one-line result and what differs from the expectation."""
    data = scene_data(case)
    solution = _solve_case(case, data)
    n_planar = len(data["contacts"]) // (2 if case.depth is not None else 1)
    groups = _groups(case, n_planar)
    return describe_solution(solution, groups), _compare(case, solution, groups)


def _compare(case: Case, solution: qs.Solution, groups: list[list[int]]) -> list[str]:
    """What differs between a solution and the case's expectation, one line each."""
    expect, tol = case.expect, case.tolerance
    failures: list[str] = []
    if solution.status != expect["status"]:
        failures.append(f"status {solution.status} ({solution.message}), expected {expect['status']}")
        return failures
    if solution.motion is not None and not solution.motion.audit.passed:
        failures.append(f"audit failed: {', '.join(solution.motion.audit.failures())}")
    if solution.motion is not None:
        failures += _compare_motion(case, solution.motion, expect, groups, tol)
    extruded = case.depth is not None
    if "forces_indeterminate" in expect and not extruded and solution.forces_indeterminate != expect["forces_indeterminate"]:
        failures.append(f"forces_indeterminate {solution.forces_indeterminate}, expected {expect['forces_indeterminate']}")
    if "normal_force_ranges" in expect and not extruded:
        failures += _compare_ranges(solution, expect["normal_force_ranges"], tol["force"])
    for kind in expect.get("solutions", []):
        if not any(not _compare_motion(case, motion, kind, groups, tol) for motion in solution.solutions):
            listed = "; ".join(describe_motion(m, groups) for m in solution.solutions) or "none"
            failures.append(f"no listed motion is of the kind {describe_kind(kind)} (listed: {listed})")
    return failures


def _compare_motion(
    case: Case, motion: qs.Motion, expect: Mapping[str, Any], groups: list[list[int]], tol: Mapping[str, float]
) -> list[str]:
    """What differs between a motion and an expected one (twists, modes, normal forces, continuum flags)."""
    failures = _compare_twists(case, motion, expect, tol["twist"])
    if "modes" in expect:
        got_modes = [sorted({motion.modes[j] for j in group}) for group in groups]
        if any(g != [m] for g, m in zip(got_modes, expect["modes"], strict=True)):
            failures.append(f"modes {format_modes(motion, groups)}, expected {', '.join(expect['modes'])}")
    failures += _compare_forces(motion, expect, groups, tol["force"])
    for flag in ("continuum", "unbounded"):
        if flag in expect and getattr(motion, flag) != expect[flag]:
            failures.append(f"{flag} {getattr(motion, flag)}, expected {expect[flag]}")
    return failures


def _compare_twists(case: Case, motion: qs.Motion, expect: Mapping[str, Any], tol: float) -> list[str]:
    """The expected twists a motion misses by more than ``tol``; planar ones are made spatial for an extruded run."""
    failures: list[str] = []
    for name, twist in expect.get("twists", {}).items():
        want = np.asarray(to_spatial(twist) if case.depth is not None else twist, dtype=float)
        got = np.asarray(motion.twists[name])
        if got.shape != want.shape or np.max(np.abs(got - want)) > tol:
            failures.append(f"twist of {name} {format_vector(got)}, expected {format_vector(want)}")
    return failures


def _compare_forces(motion: qs.Motion, expect: Mapping[str, Any], groups: list[list[int]], tol: float) -> list[str]:
    """Normal forces, summed over each group, against ``normal_forces`` and ``min_normal_forces``."""
    failures: list[str] = []
    forces = [sum(motion.contacts[j].normal_force for j in group) for group in groups]
    if "normal_forces" in expect:
        want = np.asarray(expect["normal_forces"], dtype=float)
        if np.max(np.abs(np.asarray(forces) - want)) > tol:
            failures.append(f"normal forces {format_vector(forces)} N, expected {format_vector(want)} N")
    if "min_normal_forces" in expect:
        low = np.asarray(expect["min_normal_forces"], dtype=float)
        if np.any(np.asarray(forces) < low - tol):
            failures.append(f"normal forces {format_vector(forces)} N, expected at least {format_vector(low)} N")
    return failures


def _compare_ranges(solution: qs.Solution, ranges: Sequence[Sequence[float | None]], tol: float) -> list[str]:
    """The normal force ranges of a solution against the expected ones; one line if any differs."""
    got = [c.normal_force_range for c in solution.contacts]
    if any(r is None for r in got):
        return [f"normal force ranges {got}, expected {ranges}"]
    for got_range, (want_lo, want_hi) in zip(got, ranges, strict=True):
        lo, hi = got_range  # type: ignore[misc]
        bad_hi = (hi is None) != (want_hi is None) or (hi is not None and want_hi is not None and abs(hi - want_hi) > tol)
        if abs(lo - float(want_lo or 0.0)) > tol or bad_hi:
            return [f"normal force ranges {format_ranges(got)} N, expected {format_ranges(ranges)} N"]
    return []


def _observe(solution: qs.Solution, what: str) -> str:
    """What a bisection watches: the status, or ``mode:i``, the mode of contact ``i`` when solved."""
    if what == "status":
        return solution.status
    if what.startswith("mode:") and solution.status == "solved":
        return solution.modes[int(what[5:])]
    return solution.status


def _run_bisection(case: Case) -> tuple[str, list[str]]:
    """Check a ``bisect`` case: bisect its bracket down to a quarter of the tolerance and compare the threshold."""
    vary = SETTERS[case.params["vary"]]
    base = scene_data(case)
    observe = case.params.get("observe", "status")
    below, above = case.params["below"], case.params["above"]
    tol = case.tolerance["threshold"]

    def outcome(value: float) -> str:
        data = copy.deepcopy(base)
        vary(data, value, case.params)
        return _observe(_solve_case(case, data), observe)

    lo, hi = (float(v) for v in case.params["bracket"])
    for value, want in ((lo, below), (hi, above)):
        got = outcome(value)
        if got != want:
            return f"{got} at {value:g}", [f"bracket end {value:g}: got {got}, expected {want}"]
    steps = 0
    while hi - lo > tol / 4:
        mid = (lo + hi) / 2
        got = outcome(mid)
        steps += 1
        if got == below:
            lo = mid
        elif got == above:
            hi = mid
        else:
            return f"{got} at {mid:.6g}", [f"at {mid:.8g}: got {got}, expected {below} or {above}"]
    found = (lo + hi) / 2
    want = float(case.expect["threshold"])
    text = f"threshold {found:.6f} ({steps + 2} solves)"
    return text, [] if abs(found - want) <= tol else [f"threshold {found:.8g}, expected {want:g} +- {tol:g}"]
