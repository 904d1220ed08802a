"""Whitney's peg in a hole: the two-point jamming line, the grid check against it and the jamming diagram."""

from __future__ import annotations

import copy
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


def plot_whitney(path: str | Path, folder: str | Path = DEFAULT_FOLDER, n: int = 41) -> Path:
    """Draw Whitney's jamming diagram from an ``n`` x ``n`` sweep of the library, with the analytic line.

    Needs matplotlib (``pip install matplotlib``); uses the Agg backend.

    Parameters
    ----------
    path : path
        PNG file to write.
    folder : path
        Validation folder holding ``scenes/whitney_peg.yaml`` and the cases drawn as crosses.
    n : int
        Grid points along each axis.

    Returns
    -------
    Path
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    base = read_yaml(Path(folder) / "scenes" / "whitney_peg.yaml")
    p = whitney_parameters(base)
    xs = np.linspace(-1 / p["mu"], 1 / p["mu"], n)
    ys = np.linspace(-1.0, 6.0, n)
    stays, moves = _sweep(base, xs, ys)
    fig, ax = plt.subplots(figsize=(7, 6), dpi=120)
    _draw_sweep(ax, stays, moves)
    _draw_line(ax, p)
    points = _case_points(base, folder)
    if points:
        c = np.array(points)
        ax.scatter(c[:, 0], c[:, 1], s=60, marker="x", color="k", label="validation cases")
    _decorate(ax, p, xs, ys)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    plt.close(fig)
    return path


def _sweep(base: Mapping[str, Any], xs: np.ndarray, ys: np.ndarray) -> tuple[list[Point], list[Point]]:
    """The grid points where the peg stays and those where it moves."""
    stays: list[Point] = []
    moves: list[Point] = []
    for x in xs:
        for y in ys:
            status = _whitney_status(base, float(x), float(y))
            (stays if status == "solved" else moves).append((float(x), float(y)))
    return stays, moves


def _draw_sweep(ax: Axes, stays: list[Point], moves: list[Point]) -> None:
    """Scatter the sweep: hollow red where the peg moves, blue where it stays."""
    if moves:
        m = np.array(moves)
        ax.scatter(m[:, 0], m[:, 1], s=14, marker="o", facecolors="none", edgecolors="tab:red", label="moves (unstable)")
    if stays:
        k = np.array(stays)
        ax.scatter(k[:, 0], k[:, 1], s=14, marker="o", color="tab:blue", label="stays (at rest)")


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


def _decorate(ax: Axes, p: Mapping[str, float], xs: np.ndarray, ys: np.ndarray) -> None:
    """Axis labels, title, limits, grid and the legend below the plot."""
    ax.set_xlabel(r"$x = F_x / F_z$")
    ax.set_ylabel(r"$y = M / (r F_z)$")
    ax.set_title(f"Peg in a hole, two-point contact: r = {p['r']:g} m, l = {p['l']:g} m, F_z = {p['F_z']:g} N")
    ax.set_xlim(xs[0] - 0.2, xs[-1] + 0.2)
    ax.set_ylim(ys[0] - 0.3, ys[-1] + 0.3)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8, frameon=False)
