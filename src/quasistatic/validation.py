"""Validation suite: classical results of statics with friction, run through the library.

The cases live in a folder (``validation/`` of a clone): ``cases.yaml`` lists
each case with its source, a hand derivation of the expected outcome and its
tolerances, and points at a scene file under ``scenes/``. A case is one of

- ``solve``: one solve compared with the expected status, twists, modes,
  normal forces (or their ranges) and, for ``ambiguous``, the kinds of motion
  that must be listed;
- ``bisect``: a threshold (angle of repose, a ladder's critical angle, a
  pushing height) found by bisection over a scene parameter, each step a solve;
- ``whitney-grid``: a grid of peg loads compared with Whitney's jamming line.

A planar case with ``extrude: d`` runs a second time in 3-D: extruded along z
with every contact duplicated at ``z = -d/2`` and ``z = +d/2``. The 3-D run
must give the same status, twists and modes, and each pair of contacts must
carry the planar contact's normal force.

``run_validation(folder)`` runs every case and ``render_results`` prints the
table; ``python -m quasistatic.validation --whitney docs/whitney.png`` draws
Whitney's jamming diagram from a sweep of the library (needs matplotlib).
"""

from __future__ import annotations

import argparse
import copy
import math
import re
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from rich.console import Console
from rich.table import Table
from rich.text import Text

from .errors import QuasistaticError
from .scene import load_scene
from .solution import Mode, Motion, Solution
from .solve import solve

__all__ = [
    "CASES_FILE",
    "Case",
    "CaseResult",
    "load_cases",
    "run_case",
    "run_validation",
    "render_results",
    "scene_data",
    "extrude",
    "whitney_parameters",
    "whitney_line",
    "whitney_load",
    "plot_whitney",
]

CASES_FILE = "cases.yaml"
DEFAULT_FOLDER = Path("validation")
_DEFAULT_TOLERANCE = {"force": 1e-4, "twist": 1e-7, "threshold": 1e-3}
_CHECKS = ("solve", "bisect", "whitney-grid")


@dataclass(frozen=True)
class Case:
    """One validation case, as read from ``cases.yaml``.

    Attributes
    ----------
    id, group, title, source, ref, derivation : str
        ``ref`` is the short source shown in the table.
    folder : Path
        The validation folder; ``scene`` is relative to it.
    scene : str
        Scene file of the case.
    overrides : mapping
        Scene keys to replace, by dotted path (``bodies.peg.wrench``, ``contacts[2].point``).
    modes : tuple of str or None, optional
        Prescribed contact modes of the solve.
    check : {"solve", "bisect", "whitney-grid"}
    expect : mapping
        The expected outcome (see ``cases.yaml``).
    tolerance : mapping
        ``force`` [N], ``twist`` [m/s, rad/s], ``threshold`` [unit of the varied parameter].
    depth : float or None
        Set for the 3-D run of a planar case: extrusion depth [m].
    slow : bool
        Left out of the default pytest run.
    known : str or None
        A documented disagreement: why the library's answer differs from the
        expectation (``known``, or ``known_3d`` for the extruded run, in
        ``cases.yaml``). Such a case is reported ``known`` when it fails and
        ``FIXED`` (a failure: update the file) when it passes.
    params : mapping
        Parameters of ``bisect`` and ``whitney-grid`` checks.
    """

    id: str
    group: str
    title: str
    source: str
    ref: str
    derivation: str
    folder: Path
    scene: str
    overrides: Mapping[str, Any] = field(default_factory=dict)
    modes: tuple[Mode | None, ...] | None = None
    check: str = "solve"
    expect: Mapping[str, Any] = field(default_factory=dict)
    tolerance: Mapping[str, float] = field(default_factory=dict)
    depth: float | None = None
    slow: bool = False
    known: str | None = None
    params: Mapping[str, Any] = field(default_factory=dict)

    @property
    def dimension(self) -> int:
        """Dimension the case runs in (3 for an extruded planar case)."""
        return 3 if self.depth is not None else int(_read_yaml(self.folder / self.scene).get("dimension", 3))


@dataclass(frozen=True)
class CaseResult:
    """The outcome of one case.

    Attributes
    ----------
    case : Case
    expected, got : str
        One-line summaries for the table.
    passed : bool
    failures : tuple of str
        What differs from the expectation, one line each.
    seconds : float
        Wall time of the case [s].
    error : str or None
        ``ExceptionType: message`` when the library raised.
    """

    case: Case
    expected: str
    got: str
    passed: bool
    failures: tuple[str, ...] = ()
    seconds: float = 0.0
    error: str | None = None

    @property
    def verdict(self) -> str:
        """``pass``, ``FAIL``, ``known`` (fails as documented) or ``FIXED`` (documented to fail, passes)."""
        if self.case.known is None:
            return "pass" if self.passed else "FAIL"
        return "FIXED" if self.passed else "known"

    @property
    def ok(self) -> bool:
        """True unless the case fails unexpectedly or a documented failure went away."""
        return self.verdict in ("pass", "known")


# --------------------------------------------------------------------------- loading


def load_cases(folder: str | Path = DEFAULT_FOLDER, *, extruded: bool = True) -> list[Case]:
    """Every case of ``folder/cases.yaml``, each planar case followed by its 3-D run.

    Raises
    ------
    QuasistaticError
        When the folder or its ``cases.yaml`` is missing or malformed.
    """
    folder = Path(folder)
    path = folder / CASES_FILE
    if not path.is_file():
        raise QuasistaticError(
            f"no validation cases: {path} does not exist; run from the repository root or pass the folder that holds cases.yaml"
        )
    data = _read_yaml(path)
    defaults = {**_DEFAULT_TOLERANCE, **(data.get("defaults", {}).get("tolerance", {}))}
    cases: list[Case] = []
    seen: set[str] = set()
    for entry in data.get("cases", []):
        case = _case(entry, folder, defaults)
        if case.id in seen:
            raise QuasistaticError(f"{path}: case id {case.id!r} appears twice")
        seen.add(case.id)
        cases.append(case)
        depth = entry.get("extrude")
        if extruded and depth is not None:
            known_3d = " ".join(str(entry["known_3d"]).split()) if entry.get("known_3d") else None
            twin = _replace(case, id=f"{case.id}-3d", title=f"{case.title} (3-D)", depth=float(depth), slow=True, known=known_3d)
            cases.append(twin)
    return cases


def _case(entry: Mapping[str, Any], folder: Path, defaults: Mapping[str, float]) -> Case:
    try:
        check = entry.get("check", "solve")
        if check not in _CHECKS:
            raise QuasistaticError(f"case {entry.get('id')!r}: unknown check {check!r}; known: {', '.join(_CHECKS)}")
        known = {
            "id",
            "group",
            "title",
            "source",
            "ref",
            "derivation",
            "scene",
            "set",
            "modes",
            "check",
            "expect",
            "tolerance",
            "extrude",
            "slow",
            "known",
            "known_3d",
        }
        modes = entry.get("modes")
        return Case(
            id=str(entry["id"]),
            group=str(entry["group"]),
            title=str(entry["title"]),
            source=str(entry["source"]),
            ref=str(entry.get("ref", entry["source"])),
            derivation=" ".join(str(entry["derivation"]).split()),
            folder=folder,
            scene=str(entry["scene"]),
            overrides=dict(entry.get("set", {})),
            modes=tuple(modes) if modes is not None else None,
            check=check,
            expect=dict(entry["expect"]),
            tolerance={**defaults, **entry.get("tolerance", {})},
            slow=bool(entry.get("slow", False)),
            known=" ".join(str(entry["known"]).split()) if entry.get("known") else None,
            params={k: v for k, v in entry.items() if k not in known},
        )
    except KeyError as exc:
        raise QuasistaticError(f"case {entry.get('id', '?')!r} in {folder / CASES_FILE}: missing key {exc}") from None


def _replace(case: Case, **changes: Any) -> Case:
    return Case(**{**case.__dict__, **changes})


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise QuasistaticError(f"cannot read {path}: {exc}") from None
    if not isinstance(data, dict):
        raise QuasistaticError(f"{path}: expected a mapping of keys")
    return data


def scene_data(case: Case) -> dict[str, Any]:
    """The scene dict of a case: its file, with the case's overrides, extruded for a 3-D run."""
    data = copy.deepcopy(_read_yaml(case.folder / case.scene))
    for path, value in case.overrides.items():
        _set_path(data, path, copy.deepcopy(value))
    return extrude(data, case.depth) if case.depth is not None else data


def _set_path(data: Any, path: str, value: Any) -> None:
    """Replace ``data[...]`` at a dotted path with ``[index]`` parts, e.g. ``contacts[2].point``."""
    keys: list[str | int] = [int(k[1:-1]) if k.startswith("[") else k for k in re.findall(r"\[\d+\]|[^.\[\]]+", path)]
    target = data
    for key in keys[:-1]:
        target = target[key]
    target[keys[-1]] = value


def extrude(data: Mapping[str, Any], depth: float) -> dict[str, Any]:
    """A planar scene dict extruded along z: every contact duplicated at z = -depth/2 and +depth/2.

    Vectors gain a zero z entry, planar twists ``[vx, vy, wz]`` and wrenches
    ``[fx, fy, mz]`` become ``[vx, vy, 0, 0, 0, wz]`` and ``[fx, fy, 0, 0, 0, mz]``.
    Contact ``i`` of the planar scene becomes contacts ``2i`` (z = -depth/2) and ``2i + 1``.
    """
    if data.get("dimension", 3) != 2:
        raise ValueError("only a planar scene (dimension: 2) can be extruded")
    out = {k: copy.deepcopy(v) for k, v in data.items() if k not in ("dimension", "gravity", "bodies", "movers", "contacts")}
    out["dimension"] = 3
    out["gravity"] = [*data.get("gravity", [0.0, -9.81]), 0.0]
    out["bodies"] = {}
    for name, body in data["bodies"].items():
        body = dict(body)
        body["com"] = [*body["com"], 0.0]
        if body.get("wrench") is not None:
            body["wrench"] = _spatial(body["wrench"])
        out["bodies"][name] = body
    out["movers"] = {}
    for name, mover in (data.get("movers") or {}).items():
        mover = dict(mover or {})
        if mover.get("twist") is not None:
            mover["twist"] = _spatial(mover["twist"])
        if mover.get("origin") is not None:
            mover["origin"] = [*mover["origin"], 0.0]
        out["movers"][name] = mover
    out["contacts"] = []
    for contact in data["contacts"]:
        for z in (-depth / 2, depth / 2):
            out["contacts"].append({**contact, "point": [*contact["point"], z], "normal": [*contact["normal"], 0.0]})
    return out


def _spatial(planar: Sequence[float]) -> list[float]:
    vx, vy, wz = planar
    return [vx, vy, 0.0, 0.0, 0.0, wz]


# --------------------------------------------------------------------------- running


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
    """
    results = []
    for case in load_cases(folder):
        if (case.slow and not include_slow) or (select is not None and not select(case)):
            continue
        results.append(run_case(case))
    return results


def run_case(case: Case) -> CaseResult:
    """Run one case; a library exception becomes a failed result that names it."""
    start = time.perf_counter()
    expected = _describe_expectation(case)
    try:
        if case.check == "bisect":
            got, failures = _run_bisection(case)
        elif case.check == "whitney-grid":
            got, failures = _run_whitney_grid(case)
        else:
            got, failures = _run_solve(case)
    except Exception as exc:  # noqa: BLE001 - a crash in one case must not hide the others
        error = f"{type(exc).__name__}: {exc}"
        return CaseResult(case, expected, f"error: {error}", False, (error,), time.perf_counter() - start, error)
    return CaseResult(case, expected, got, not failures, tuple(failures), time.perf_counter() - start)


def _solve_case(case: Case, data: Mapping[str, Any] | None = None) -> Solution:
    scene = load_scene(scene_data(case) if data is None else data)
    modes = case.modes
    if modes is not None and case.depth is not None:
        modes = tuple(m for m in modes for _ in range(2))
    return solve(scene, modes=modes, all_solutions=True)  # validation checks the certified answer


def _groups(case: Case, n_planar: int) -> list[list[int]]:
    """Indices of the contacts that stand for each planar contact (a pair when extruded)."""
    if case.depth is None:
        return [[i] for i in range(n_planar)]
    return [[2 * i, 2 * i + 1] for i in range(n_planar)]


def _run_solve(case: Case) -> tuple[str, list[str]]:
    data = scene_data(case)
    solution = _solve_case(case, data)
    n_planar = len(data["contacts"]) // (2 if case.depth is not None else 1)
    groups = _groups(case, n_planar)
    return _describe_solution(solution, groups), _compare(case, solution, groups)


def _compare(case: Case, solution: Solution, groups: list[list[int]]) -> list[str]:
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
            listed = "; ".join(_describe_motion(m, groups) for m in solution.solutions) or "none"
            failures.append(f"no listed motion is of the kind {_describe_kind(kind)} (listed: {listed})")
    return failures


def _compare_motion(case: Case, motion: Motion, expect: Mapping[str, Any], groups: list[list[int]], tol: Mapping[str, float]) -> list[str]:
    failures: list[str] = []
    for name, twist in expect.get("twists", {}).items():
        want = np.asarray(_spatial(twist) if case.depth is not None else twist, dtype=float)
        got = np.asarray(motion.twists[name])
        if got.shape != want.shape or np.max(np.abs(got - want)) > tol["twist"]:
            failures.append(f"twist of {name} {_vector(got)}, expected {_vector(want)}")
    if "modes" in expect:
        got_modes = [sorted({motion.modes[j] for j in group}) for group in groups]
        if any(g != [m] for g, m in zip(got_modes, expect["modes"], strict=True)):
            failures.append(f"modes {_modes(motion, groups)}, expected {', '.join(expect['modes'])}")
    forces = [sum(motion.contacts[j].normal_force for j in group) for group in groups]
    if "normal_forces" in expect:
        want = np.asarray(expect["normal_forces"], dtype=float)
        if np.max(np.abs(np.asarray(forces) - want)) > tol["force"]:
            failures.append(f"normal forces {_vector(forces)} N, expected {_vector(want)} N")
    if "min_normal_forces" in expect:
        low = np.asarray(expect["min_normal_forces"], dtype=float)
        if np.any(np.asarray(forces) < low - tol["force"]):
            failures.append(f"normal forces {_vector(forces)} N, expected at least {_vector(low)} N")
    for flag in ("continuum", "unbounded"):
        if flag in expect and getattr(motion, flag) != expect[flag]:
            failures.append(f"{flag} {getattr(motion, flag)}, expected {expect[flag]}")
    return failures


def _compare_ranges(solution: Solution, ranges: Sequence[Sequence[float | None]], tol: float) -> list[str]:
    got = [c.normal_force_range for c in solution.contacts]
    if any(r is None for r in got):
        return [f"normal force ranges {got}, expected {ranges}"]
    for got_range, (want_lo, want_hi) in zip(got, ranges, strict=True):
        lo, hi = got_range  # type: ignore[misc]
        bad_hi = (hi is None) != (want_hi is None) or (hi is not None and want_hi is not None and abs(hi - want_hi) > tol)
        if abs(lo - float(want_lo or 0.0)) > tol or bad_hi:
            return [f"normal force ranges {_ranges(got)} N, expected {_ranges(ranges)} N"]
    return []


# --------------------------------------------------------------------------- bisection


def _slope_deg(data: dict[str, Any], angle: float, params: Mapping[str, Any]) -> None:
    """Tilt gravity so that the x axis is a slope rising at ``angle`` degrees."""
    g = float(np.linalg.norm(data.get("gravity", [0.0, -9.81])))
    a = math.radians(angle)
    data["gravity"] = [-g * math.sin(a), -g * math.cos(a)]


def _ladder_deg(data: dict[str, Any], angle: float, params: Mapping[str, Any]) -> None:
    """Stand the ladder at ``angle`` degrees: contact 0 its foot on the floor y = 0, contact 1 its top on the wall x = 0."""
    foot, top = data["contacts"][0], data["contacts"][1]
    if list(foot["normal"]) != [0.0, 1.0] or list(top["normal"]) != [1.0, 0.0]:
        raise ValueError("ladder_deg needs contact 0 on the floor (normal [0, 1]) and contact 1 on the wall (normal [1, 0])")
    length = math.dist(foot["point"], top["point"])
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    foot["point"] = [length * c, 0.0]
    top["point"] = [0.0, length * s]
    data["bodies"][foot["body"]]["com"] = [length * c / 2, length * s / 2]


def _push_height(data: dict[str, Any], height: float, params: Mapping[str, Any]) -> None:
    """Move the last contact (the pusher's) to height ``height``."""
    data["contacts"][-1]["point"] = [data["contacts"][-1]["point"][0], height]


def _tip_moment(data: dict[str, Any], moment: float, params: Mapping[str, Any]) -> None:
    """Load the peg with ``(F_x, -F_z)`` at its tip and ``moment`` about the tip."""
    data["bodies"]["peg"]["wrench"] = whitney_load(data, float(params["fixed"]["F_x"]), moment)


_VARY: dict[str, Callable[[dict[str, Any], float, Mapping[str, Any]], None]] = {
    "slope_deg": _slope_deg,
    "ladder_deg": _ladder_deg,
    "push_height": _push_height,
    "tip_moment": _tip_moment,
}


def _observe(solution: Solution, what: str) -> str:
    if what == "status":
        return solution.status
    if what.startswith("mode:") and solution.status == "solved":
        return solution.modes[int(what[5:])]
    return solution.status


def _run_bisection(case: Case) -> tuple[str, list[str]]:
    vary = _VARY[case.params["vary"]]
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


# --------------------------------------------------------------------------- Whitney


def whitney_parameters(data: Mapping[str, Any]) -> dict[str, float]:
    """Peg radius r, contact separation l, friction mu, insertion force F_z and lambda of a Whitney peg scene.

    The scene convention of ``scenes/whitney_peg.yaml``: the tip at the origin,
    contact 0 at the tip's corner (r, 0), contact 1 on the other side at (-r, l),
    the peg loaded by ``[F_x, -F_z, M_com]``.
    """
    c0, c1 = data["contacts"][0], data["contacts"][1]
    r = float(c0["point"][0])
    l = float(c1["point"][1]) - float(c0["point"][1])  # noqa: E741 - Whitney's name for it
    mu = float(c0["mu"])
    f_z = -float(data["bodies"]["peg"]["wrench"][1])
    return {"r": r, "l": l, "mu": mu, "F_z": f_z, "lambda": l / (2 * r * mu)}


def whitney_line(x: np.ndarray | float, lam: float, mu: float) -> np.ndarray | float:
    """Whitney's two-point boundary: the peg stays iff ``M/(r F_z) >= lam - mu (1 + lam) F_x/F_z``."""
    return lam - mu * (1 + lam) * x


def whitney_load(data: Mapping[str, Any], f_x: float, moment: float) -> list[float]:
    """The peg's wrench about its com for a force ``(f_x, -F_z)`` at the tip (the origin) and ``moment`` about it."""
    f_z = whitney_parameters(data)["F_z"]
    cx, cy = (float(v) for v in data["bodies"]["peg"]["com"])
    force = (f_x, -f_z)
    # moment of the tip force about the com: (tip - com) x F
    return [f_x, -f_z, moment + (-cx) * force[1] - (-cy) * force[0]]


def _whitney_status(base: Mapping[str, Any], x: float, y: float) -> str:
    p = whitney_parameters(base)
    data = copy.deepcopy(dict(base))
    data["bodies"]["peg"]["wrench"] = whitney_load(base, x * p["F_z"], y * p["r"] * p["F_z"])
    return solve(load_scene(data), all_solutions=True).status


def _grid(spec: Mapping[str, Sequence[float]]) -> tuple[np.ndarray, np.ndarray]:
    (x0, x1, nx), (y0, y1, ny) = spec["x"], spec["y"]
    return np.linspace(x0, x1, int(nx)), np.linspace(y0, y1, int(ny))


def _run_whitney_grid(case: Case) -> tuple[str, list[str]]:
    base = scene_data(case)
    p = whitney_parameters(base)
    xs, ys = _grid(case.params["grid"])
    margin = float(case.params.get("margin", 0.02))
    failures, checked = [], 0
    for x in xs:
        line = float(whitney_line(float(x), p["lambda"], p["mu"]))
        for y in ys:
            if abs(y - line) <= margin:
                continue
            want = "solved" if y > line else "unstable"
            got = _whitney_status(base, float(x), float(y))
            checked += 1
            if got != want:
                failures.append(f"x = {x:.4g}, y = {y:.4g}: got {got}, expected {want} (line at y = {line:.4g})")
    return f"{checked - len(failures)} of {checked} points agree", failures


def plot_whitney(path: str | Path, folder: str | Path = DEFAULT_FOLDER, n: int = 41) -> Path:
    """Draw Whitney's jamming diagram from an ``n`` x ``n`` sweep of the library, with the analytic line.

    Needs matplotlib (``pip install matplotlib``); uses the Agg backend.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    base = _read_yaml(Path(folder) / "scenes" / "whitney_peg.yaml")
    p = whitney_parameters(base)
    lam, mu = p["lambda"], p["mu"]
    xs = np.linspace(-1 / mu, 1 / mu, n)
    ys = np.linspace(-1.0, 6.0, n)
    stays: list[tuple[float, float]] = []
    moves: list[tuple[float, float]] = []
    for x in xs:
        for y in ys:
            status = _whitney_status(base, float(x), float(y))
            (stays if status == "solved" else moves).append((float(x), float(y)))
    fig, ax = plt.subplots(figsize=(7, 6), dpi=120)
    if moves:
        m = np.array(moves)
        ax.scatter(m[:, 0], m[:, 1], s=14, marker="o", facecolors="none", edgecolors="tab:red", label="moves (unstable)")
    if stays:
        k = np.array(stays)
        ax.scatter(k[:, 0], k[:, 1], s=14, marker="o", color="tab:blue", label="stays (at rest)")
    line_x = np.linspace(-1 / mu, 1 / mu, 2)
    ax.plot(
        line_x,
        whitney_line(line_x, lam, mu),
        "k-",
        lw=2,
        label=rf"Whitney: $y = \lambda - \mu(1+\lambda)\,x$, $\lambda = {lam:g}$, $\mu = {mu:g}$",
    )
    cases = [c for c in load_cases(folder, extruded=False) if c.scene.endswith("whitney_peg.yaml") and c.check == "solve"]
    if cases:
        points = []
        for case in cases:
            f_x, _, m_com = scene_data(case)["bodies"]["peg"]["wrench"]
            moment = m_com - whitney_load(base, f_x, 0.0)[2]
            points.append((f_x / p["F_z"], moment / (p["r"] * p["F_z"])))
        c = np.array(points)
        ax.scatter(c[:, 0], c[:, 1], s=60, marker="x", color="k", label="validation cases")
    ax.set_xlabel(r"$x = F_x / F_z$")
    ax.set_ylabel(r"$y = M / (r F_z)$")
    ax.set_title(f"Peg in a hole, two-point contact: r = {p['r']:g} m, l = {p['l']:g} m, F_z = {p['F_z']:g} N")
    ax.set_xlim(xs[0] - 0.2, xs[-1] + 0.2)
    ax.set_ylim(ys[0] - 0.3, ys[-1] + 0.3)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8, frameon=False)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- report


def render_results(results: Sequence[CaseResult], console: Console | None = None) -> None:
    """Print the table: case, source, expected, got, verdict and time, then a summary line."""
    console = console or Console()
    table = Table(title="quasistatic validation", show_lines=False)
    table.add_column("case", no_wrap=True)
    table.add_column("source")
    table.add_column("expected")
    table.add_column("got")
    table.add_column("result", no_wrap=True)
    table.add_column("time", justify="right", no_wrap=True)
    styles = {"pass": "bold green", "known": "bold yellow", "FAIL": "bold red", "FIXED": "bold red"}
    for r in results:
        got = Text(r.got) if r.passed else Text(r.got + "\n" + "\n".join(r.failures), style="red")
        if r.verdict == "known":
            got = Text(r.got + "\nknown: " + str(r.case.known), style="yellow")
        table.add_row(r.case.id, r.case.ref, r.expected, got, Text(r.verdict, style=styles[r.verdict]), f"{r.seconds:.2f} s")
    console.print(table)
    total = sum(r.seconds for r in results)
    passed = sum(r.verdict == "pass" for r in results)
    parts = [f"{passed} of {len(results)} cases passed in {total:.1f} s"]
    labels = {"known": "known disagreements (docs/validation.md)", "FAIL": "failed", "FIXED": "documented to fail but passed"}
    for verdict, label in labels.items():
        ids = [r.case.id for r in results if r.verdict == verdict]
        if ids:
            parts.append(f"{label}: {', '.join(ids)}")
    console.print(Text("; ".join(parts), style="green" if all(r.ok for r in results) else "red"))


def _describe_expectation(case: Case) -> str:
    e = case.expect
    if case.check == "bisect":
        return f"threshold {e['threshold']:g} +- {case.tolerance['threshold']:g}"
    if case.check == "whitney-grid":
        return "every point on the side of Whitney's line it is on"
    prescribed = f" ({', '.join(m or 'free' for m in case.modes)} prescribed)" if case.modes else ""
    parts = [e["status"] + prescribed]
    parts += [_twist_text(name, _spatial(t) if case.depth else t) for name, t in e.get("twists", {}).items()]
    if "modes" in e:
        parts.append(_mode_text(e["modes"]))
    if "normal_forces" in e:
        parts.append(f"N {_vector(e['normal_forces'])}")
    if "normal_force_ranges" in e and case.depth is None:
        parts.append(f"N in {_ranges(e['normal_force_ranges'])}")
    for kind in e.get("solutions", []):
        parts.append(f"lists {_describe_kind(kind)}")
    return "; ".join(parts)


def _describe_solution(solution: Solution, groups: list[list[int]]) -> str:
    if solution.motion is None:
        return solution.status
    if solution.status == "ambiguous":
        kinds = "; ".join(f"({_describe_motion(m, groups)})" for m in solution.solutions)
        return f"ambiguous, {len(solution.solutions)} listed: {kinds}"
    ranges = solution.forces_indeterminate and len(groups[0]) == 1
    text = f"{solution.status}; {_describe_motion(solution.motion, groups, forces=not ranges)}"
    if ranges:
        text += f"; N in {_ranges([c.normal_force_range for c in solution.contacts])}"
    return text


def _describe_motion(motion: Motion, groups: list[list[int]], forces: bool = True) -> str:
    parts = [_twist_text(name, t) for name, t in motion.twists.items()]
    parts.append(_modes(motion, groups))
    if forces:
        parts.append(f"N {_vector([sum(motion.contacts[j].normal_force for j in group) for group in groups])}")
    if motion.continuum:
        parts.append("continuum, unbounded" if motion.unbounded else "continuum")
    return "; ".join(parts)


def _twist_text(name: str, twist: Sequence[float] | np.ndarray) -> str:
    return f"{name} at rest" if not np.any(np.asarray(twist, dtype=float)) else f"v {name} {_vector(twist)}"


def _mode_text(modes: Sequence[str]) -> str:
    if len(modes) > 1 and len(set(modes)) == 1:
        return f"{len(modes)} x {modes[0]}"
    return ", ".join(modes)


def _describe_kind(kind: Mapping[str, Any]) -> str:
    parts = [_mode_text(kind["modes"])] if "modes" in kind else []
    if "twists" in kind:
        parts += [_twist_text(name, t) for name, t in kind["twists"].items()]
    if "normal_forces" in kind:
        parts.append(f"N {_vector(kind['normal_forces'])}")
    if "min_normal_forces" in kind:
        parts.append(f"N >= {_vector(kind['min_normal_forces'])}")
    if kind.get("continuum"):
        parts.append("continuum")
    return "(" + "; ".join(parts) + ")"


def _modes(motion: Motion, groups: list[list[int]]) -> str:
    return _mode_text(["/".join(sorted({motion.modes[j] for j in group})) for group in groups])


def _number(x: float) -> str:
    text = f"{float(x):.6g}"
    return "0" if float(text) == 0.0 else text


def _vector(values: Sequence[float] | np.ndarray) -> str:
    return "[" + ", ".join(_number(x) for x in np.asarray(values, dtype=float).ravel()) + "]"


def _ranges(ranges: Sequence[Sequence[float | None] | None]) -> str:
    shown = []
    for r in ranges:
        if r is None:
            shown.append("?")
            continue
        lo, hi = r
        shown.append(f"[{_number(lo)}, {'inf' if hi is None else _number(hi)}]")  # type: ignore[arg-type]
    return ", ".join(shown)


# --------------------------------------------------------------------------- command line


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m quasistatic.validation [--folder F] [--quick] [--whitney PNG]``."""
    parser = argparse.ArgumentParser(prog="python -m quasistatic.validation", description=__doc__.splitlines()[0])
    parser.add_argument("--folder", type=Path, default=DEFAULT_FOLDER, help="validation folder (default: ./validation)")
    parser.add_argument("--quick", action="store_true", help="leave out the slow cases (3-D runs, sweeps)")
    parser.add_argument("--whitney", type=Path, metavar="PNG", help="draw Whitney's jamming diagram to PNG and exit")
    args = parser.parse_args(argv)
    if args.whitney is not None:
        print(f"wrote {plot_whitney(args.whitney, args.folder)}")
        return 0
    results = run_validation(args.folder, include_slow=not args.quick)
    render_results(results)
    return 0 if all(r.ok for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
