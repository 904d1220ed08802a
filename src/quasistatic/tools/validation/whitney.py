"""Whitney's peg in a hole: the two-point jamming line, the grid check against it and the jamming diagram."""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

import quasistatic as qs

from .cases import DEFAULT_FOLDER, Case, load_cases, read_yaml
from .scenes import scene_data

if TYPE_CHECKING:
    from matplotlib.axes import Axes

Point = tuple[float, float]


def whitney_parameters(data: Mapping[str, Any]) -> dict[str, float]:
    """Peg radius r, contact separation l, friction mu, insertion force F_z and lambda of a Whitney peg scene.

    The scene convention of ``scenes/whitney_peg.yaml``: the tip at the origin,
    contact 0 at the tip's corner (r, 0), contact 1 on the other side at (-r, l),
    the peg loaded by ``[F_x, -F_z, M_com]``.

    Parameters
    ----------
    data : mapping
        A planar Whitney peg scene dict.

    Returns
    -------
    dict
        ``r`` [m], ``l`` [m], ``mu``, ``F_z`` [N] and ``lambda = l / (2 r mu)``.
    """
    c0, c1 = data["contacts"][0], data["contacts"][1]
    r = float(c0["point"][0])
    l = float(c1["point"][1]) - float(c0["point"][1])  # noqa: E741 - Whitney's name for it
    mu = float(c0["mu"])
    f_z = -float(data["bodies"]["peg"]["wrench"][1])
    return {"r": r, "l": l, "mu": mu, "F_z": f_z, "lambda": l / (2 * r * mu)}


def whitney_line(x: np.ndarray | float, lam: float, mu: float) -> np.ndarray | float:
    """Whitney's two-point boundary: the peg stays iff ``M/(r F_z) >= lam - mu (1 + lam) F_x/F_z``.

    Parameters
    ----------
    x : float or ndarray
        ``F_x / F_z``.
    lam, mu : float
        Whitney's lambda and the friction coefficient.

    Returns
    -------
    float or ndarray
        The boundary's ``y = M / (r F_z)`` at ``x``.
    """
    return lam - mu * (1 + lam) * x


def whitney_load(data: Mapping[str, Any], f_x: float, moment: float) -> list[float]:
    """The peg's wrench about its com for a force ``(f_x, -F_z)`` at the tip (the origin) and ``moment`` about it.

    Parameters
    ----------
    data : mapping
        A planar Whitney peg scene dict; its wrench gives ``F_z``.
    f_x : float
        Lateral force at the tip [N].
    moment : float
        Moment about the tip [N m].

    Returns
    -------
    list of float
        ``[F_x, -F_z, M_com]``.
    """
    f_z = whitney_parameters(data)["F_z"]
    cx, cy = (float(v) for v in data["bodies"]["peg"]["com"])
    force = (f_x, -f_z)
    # moment of the tip force about the com: (tip - com) x F
    return [f_x, -f_z, moment + (-cx) * force[1] - (-cy) * force[0]]


def tip_moment(data: dict[str, Any], moment: float, params: Mapping[str, Any]) -> None:
    """Load the peg with ``(F_x, -F_z)`` at its tip and ``moment`` about the tip (a bisection parameter)."""
    data["bodies"]["peg"]["wrench"] = whitney_load(data, float(params["fixed"]["F_x"]), moment)


def _whitney_status(base: Mapping[str, Any], x: float, y: float) -> str:
    """Status of the peg loaded at ``x = F_x / F_z``, ``y = M / (r F_z)``."""
    p = whitney_parameters(base)
    data = copy.deepcopy(dict(base))
    data["bodies"]["peg"]["wrench"] = whitney_load(base, x * p["F_z"], y * p["r"] * p["F_z"])
    return qs.solve(qs.load_scene(data), all_solutions=True).status


def _grid(spec: Mapping[str, Sequence[float]]) -> tuple[np.ndarray, np.ndarray]:
    """The x and y values of a grid given as ``{x: [x0, x1, nx], y: [y0, y1, ny]}``."""
    (x0, x1, nx), (y0, y1, ny) = spec["x"], spec["y"]
    return np.linspace(x0, x1, int(nx)), np.linspace(y0, y1, int(ny))


def run_whitney_grid(case: Case) -> tuple[str, list[str]]:
    """Check a ``whitney-grid`` case: every grid point off the line's margin is on the side of Whitney's line it is on.

    Parameters
    ----------
    case : Case
        Its params hold the ``grid`` and the ``margin`` (default 0.02) about the line left unchecked.

    Returns
    -------
    got : str
        One-line summary.
    failures : list of str
        One line per point that disagrees.
    """
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


def whitney_sweep(folder: str | Path = DEFAULT_FOLDER, n: int = 41, refine: int = 3, jobs: int = 1) -> qs.SweepResult:
    """Sweep the peg's load over Whitney's plane with :func:`quasistatic.sweep`: ``n`` x ``n`` points, boundary refined.

    The scene is ``scenes/whitney_peg.yaml`` with its (massless) peg's reference point moved to the
    tip, so that the wrench's entries are Whitney's load itself: ``bodies.peg.wrench[0]`` = F_x over
    ``[-F_z/mu, F_z/mu]`` and ``bodies.peg.wrench[2]`` = M about the tip over ``[-r F_z, 6 r F_z]``.
    Every point is certified, with every motion listed (``all_solutions=True``).
    """
    base = read_yaml(Path(folder) / "scenes" / "whitney_peg.yaml")
    p = whitney_parameters(base)
    data = copy.deepcopy(base)
    data["bodies"]["peg"]["com"] = [0.0, 0.0]
    data["bodies"]["peg"]["wrench"] = [0.0, -p["F_z"], 0.0]
    grid = {
        "bodies.peg.wrench[0]": np.linspace(-1 / p["mu"], 1 / p["mu"], n) * p["F_z"],
        "bodies.peg.wrench[2]": np.linspace(-1.0, 6.0, n) * p["r"] * p["F_z"],
    }
    return qs.sweep(data, grid, all_solutions=True, refine=refine, jobs=jobs)


def plot_whitney(path: str | Path, folder: str | Path = DEFAULT_FOLDER, n: int = 41, refine: int = 3, jobs: int = 1) -> Path:
    """Draw Whitney's jamming diagram from :func:`whitney_sweep`, with the analytic line and the validation cases.

    Needs matplotlib (``pip install matplotlib``); uses the Agg backend.

    Parameters
    ----------
    path : path
        Picture file to write (.png, .svg, .pdf).
    folder : path
        Validation folder holding ``scenes/whitney_peg.yaml`` and the cases drawn as crosses.
    n : int
        Grid points along each axis.
    refine : int
        Bisections of each boundary between grid neighbours.
    jobs : int
        Local worker processes for the sweep.

    Returns
    -------
    Path
        ``path``.
    """
    base = read_yaml(Path(folder) / "scenes" / "whitney_peg.yaml")
    p = whitney_parameters(base)
    phases = whitney_sweep(folder, n, refine, jobs).phase_map()
    scale = (p["F_z"], p["r"] * p["F_z"])  # F_x -> x = F_x / F_z, M -> y = M / (r F_z)
    phases = dataclasses.replace(
        phases,
        names=(r"$x = F_x / F_z$", r"$y = M / (r F_z)$"),
        axes=tuple(values / s for values, s in zip(phases.axes, scale, strict=True)),
        refined=tuple((tuple(v / s for v, s in zip(values, scale, strict=True)), label) for values, label in phases.refined),
    )
    title = f"Peg in a hole, two-point contact: r = {p['r']:g} m, l = {p['l']:g} m, F_z = {p['F_z']:g} N ({n} x {n} sweep)"
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.0, 6.0))
    ax = figure.add_subplot()
    _draw_line(ax, p)
    points = _case_points(base, folder)
    if points:
        c = np.array(points)
        ax.scatter(c[:, 0], c[:, 1], s=60, marker="x", color="k", label="validation cases", zorder=4)
    qs.viz.phase_diagram(phases, ax=ax, title=title)  # the public picture API, as a user calls it
    figure.tight_layout()
    qs.viz.save(figure, path)
    return Path(path)


def _draw_line(ax: Axes, p: Mapping[str, float]) -> None:
    """Draw Whitney's analytic line across the sweep."""
    lam, mu = p["lambda"], p["mu"]
    line_x = np.linspace(-1 / mu, 1 / mu, 2)
    ax.plot(
        line_x,
        whitney_line(line_x, lam, mu),
        "k-",
        lw=2,
        label=rf"Whitney: $y = \lambda - \mu(1+\lambda)\,x$, $\lambda = {lam:g}$, $\mu = {mu:g}$",
    )


def _case_points(base: Mapping[str, Any], folder: str | Path) -> list[Point]:
    """The ``(x, y)`` loads of the validation folder's planar solve cases on the Whitney peg scene."""
    p = whitney_parameters(base)
    cases = [c for c in load_cases(folder, extruded=False) if c.scene.endswith("whitney_peg.yaml") and c.check == "solve"]
    points = []
    for case in cases:
        f_x, _, m_com = scene_data(case)["bodies"]["peg"]["wrench"]
        moment = m_com - whitney_load(base, f_x, 0.0)[2]
        points.append((f_x / p["F_z"], moment / (p["r"] * p["F_z"])))
    return points
