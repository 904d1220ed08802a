"""What a sweep returns: one audited answer per point, as typed values and as a table (pyarrow)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from ..errors import BackendUnavailableError
from ..solution import LaterField, Solution, Status
from .params import SweepParam

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = ["SWEEPS_INSTALL_HINT", "PhaseKind", "PhaseMap", "SweepPoint", "SweepResult", "point_from_solution", "require_pyarrow"]

SWEEPS_INSTALL_HINT = 'install dask and pyarrow with pip install "quasistatic[sweeps]"'

PhaseKind = Literal["status", "modes"]
"""What tells two points apart in a phase diagram: the status alone, or the status and every contact's mode."""


@dataclass(frozen=True)
class SweepPoint:
    """The answer at one point of a sweep: the reported motion of an audited :class:`~quasistatic.Solution`.

    Attributes
    ----------
    index : int
        Position in :attr:`SweepResult.points`: grid points first (last parameter fastest), then refinement points.
    values : tuple of float
        Each parameter's value here, in parameter order.
    refinement : bool
        True for a point added by bisection between grid neighbours of different phase.
    status : str
        The solution's status (``solved``, ``ambiguous``, ``jammed``, ``unstable``, ``failed``).
    certified : bool
        The verdict is proven (``Solution.certified``); false marks it unproven.
    message : str
        The solution's message (or why the point could not be solved); its claim about the forces is worked out
        when first read (the table, pickling, ``==``), so a sweep that reads only statuses does not pay for it (a point
        decided in a batch, :mod:`.batched`, comes with it: the batch works it out as it proves the motion).
    motions : int
        Motions found: 1 for ``solved``, the listed ones for ``ambiguous``, 0 otherwise.
    twists : tuple of (str, tuple of float)
        Each free body's twist in the reported motion [2-D: v_x, v_y, w; 3-D: v, w].
    forces : tuple of tuple of float
        Each contact's force on its free body in the reported motion, world frame [N].
    modes : tuple of str
        Each contact's mode in the reported motion.
    seconds : float
        Wall time of the solve [s] (not compared: it differs between runs); a point decided in a batch
        (:mod:`.batched`) has its share of the batch's time.
    """

    index: int
    values: tuple[float, ...]
    refinement: bool
    status: Status
    certified: bool
    message: LaterField[str] = LaterField(required=True)  # no default: reading it from the class raises AttributeError
    motions: int = 0
    twists: tuple[tuple[str, tuple[float, ...]], ...] = ()
    forces: tuple[tuple[float, ...], ...] = ()
    modes: tuple[str, ...] = ()
    seconds: float = field(default=0.0, compare=False)

    def phase(self, kind: PhaseKind = "status") -> str:
        """The label of this point's region: its status, with the contact modes when ``kind`` is ``modes``."""
        if kind == "modes" and self.modes:
            return f"{self.status}: {' '.join(self.modes)}"
        return self.status


def point_from_solution(index: int, values: Sequence[float], refinement: bool, solution: Solution) -> SweepPoint:
    """The sweep's record of a solution (its reported motion)."""
    motions = len(solution.solutions) or int(solution.motion is not None)
    return SweepPoint(
        index=index,
        values=tuple(float(v) for v in values),
        refinement=refinement,
        status=solution.status,
        certified=solution.certified,
        message=solution.kept_message(),  # its claim about the forces worked out when read (the table, a pickle, ==)
        motions=motions,
        twists=tuple((name, _floats(t)) for name, t in solution.twists.items()),
        forces=_point_forces(solution),
        modes=tuple(solution.modes),
        seconds=float(solution.seconds),
    )


def _point_forces(solution: Solution) -> tuple[tuple[float, ...], ...]:
    """The reported motion's contact forces, without working out force ranges (a sweep keeps none)."""
    if solution.motion is None:
        return ()
    forces, _ = solution.motion.forces_and_slips()
    return tuple(_floats(f) for f in forces)


@dataclass(frozen=True)
class PhaseMap:
    """Phases over one or two parameters, for a phase diagram (``quasistatic.viz.phase_diagram``).

    Attributes
    ----------
    names : tuple of str
        The parameters drawn (x, then y when there are two).
    axes : tuple of ndarray
        The grid values along each.
    labels : ndarray of str, shape of the grid
        Each grid point's phase.
    refined : tuple of (tuple of float, str)
        Each refinement point's coordinates and phase.
    kind : str
        ``status`` or ``modes``.
    """

    names: tuple[str, ...]
    axes: tuple[np.ndarray, ...]
    labels: np.ndarray
    refined: tuple[tuple[tuple[float, ...], str], ...]
    kind: PhaseKind


@dataclass(frozen=True)
class SweepResult:
    """Every point of a sweep.

    Attributes
    ----------
    params : tuple of SweepParam
        The grid's axes, in the order given.
    points : tuple of SweepPoint
        The grid points (the Cartesian product, last parameter fastest), then the refinement points.
    reused : int
        Points read back from finished chunks (``resume``) instead of solved in this run.
    """

    params: tuple[SweepParam, ...]
    points: tuple[SweepPoint, ...]
    reused: int = field(default=0, compare=False)

    @property
    def shape(self) -> tuple[int, ...]:
        """Points along each parameter."""
        return tuple(len(p.values) for p in self.params)

    @property
    def grid(self) -> tuple[SweepPoint, ...]:
        """The grid points, in grid order (``np.reshape(..., shape)`` places them)."""
        return tuple(p for p in self.points if not p.refinement)

    @property
    def refined(self) -> tuple[SweepPoint, ...]:
        """The points added where neighbours' phases differ."""
        return tuple(p for p in self.points if p.refinement)

    def statuses(self) -> np.ndarray:
        """The grid's statuses as an array of the grid's shape."""
        return np.array([p.status for p in self.grid], dtype=object).reshape(self.shape)

    def phase_map(self, kind: PhaseKind = "status") -> PhaseMap:
        """The phases over the (one or two) parameters, for :func:`quasistatic.viz.phase_diagram`.

        Raises
        ------
        ValueError
            When the sweep has more than two parameters.
        """
        if len(self.params) > 2:
            raise ValueError(f"a phase diagram shows one or two parameters; this sweep has {len(self.params)}")
        labels = np.array([p.phase(kind) for p in self.grid], dtype=object).reshape(self.shape)
        refined = tuple((p.values, p.phase(kind)) for p in self.refined)
        return PhaseMap(tuple(p.name for p in self.params), tuple(p.values for p in self.params), labels, refined, kind)

    def to_table(self) -> pa.Table:
        """One row per point: ``index``, ``refinement``, each parameter, ``status``, ``certified``, ``message``,
        ``motions``, each body's twist entries (``twist.BODY[k]``), each contact's force entries
        (``contacts[i].force[k]``) and mode (``contacts[i].mode``); empty where a point has no motion."""
        pa = require_pyarrow()
        columns: dict[str, list[Any]] = {"index": [p.index for p in self.points], "refinement": [p.refinement for p in self.points]}
        for position, param in enumerate(self.params):
            columns[param.name] = [p.values[position] for p in self.points]
        for name in ("status", "certified", "message", "motions"):
            columns[name] = [getattr(p, name) for p in self.points]
        columns.update(_motion_columns(self.points))
        return pa.table(columns)

    def to_parquet(self, path: str | Path) -> Path:
        """Write :meth:`to_table` as a Parquet file; returns the path."""
        require_pyarrow()
        import pyarrow.parquet as pq

        pq.write_table(self.to_table(), Path(path))
        return Path(path)

    def to_csv(self, path: str | Path) -> Path:
        """Write :meth:`to_table` as a CSV file (empty cells where a point has no motion); returns the path."""
        require_pyarrow()
        import pyarrow.csv as pcsv

        pcsv.write_csv(self.to_table(), Path(path))
        return Path(path)


def require_pyarrow() -> Any:
    """pyarrow, or :class:`BackendUnavailableError` with the install line."""
    try:
        import pyarrow
    except ImportError as exc:
        raise BackendUnavailableError("pyarrow", SWEEPS_INSTALL_HINT, needed_for="sweep tables") from exc
    return pyarrow


def _motion_columns(points: Sequence[SweepPoint]) -> dict[str, list[Any]]:
    """Twist, force and mode columns over every point (a point without that entry has None there)."""
    cells: dict[str, dict[int, Any]] = {}
    for row, point in enumerate(points):
        for body, twist in point.twists:
            for k, value in enumerate(twist):
                cells.setdefault(f"twist.{body}[{k}]", {})[row] = value
        for i, force in enumerate(point.forces):
            for k, value in enumerate(force):
                cells.setdefault(f"contacts[{i}].force[{k}]", {})[row] = value
        for i, mode in enumerate(point.modes):
            cells.setdefault(f"contacts[{i}].mode", {})[row] = mode
    return {name: [column.get(row) for row in range(len(points))] for name, column in cells.items()}


def _floats(array: Any) -> tuple[float, ...]:
    return tuple(float(x) + 0.0 for x in np.asarray(array, dtype=float).ravel())
