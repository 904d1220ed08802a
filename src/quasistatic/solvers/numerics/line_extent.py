"""The extent along each twist entry of a polyhedron ``{q : E q = e, A q >= a}`` whose equalities leave a line.

The 3-D mode branch and bound measures a leaf's polyhedron of twists with 2 n
warm LPs (the least and the largest value of each entry). Most leaves of a
3-D push have equalities of rank n - 1: the polyhedron is then a segment, a
ray, a line or empty, and the 2 n optima are its two ends, read off in closed
form (one SVD of E and one pass over the rows of A) instead of HiGHS's 2 n
simplex runs, which cost about 3.6 ms a leaf. The answer is given only where it
is clear at HiGHS's own feasibility tolerance; anything closer (an interval
empty or not within that tolerance, inconsistent equalities, a rank that is
not exactly n - 1) is ``None``, and the caller runs the LPs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...tolerances import LINE_NULL_SPACE, LINE_PARALLEL_ROW, LINE_RANK, LP_FEASIBILITY, SAME_TWIST

__all__ = ["AxisExtents", "line_axis_extents"]


@dataclass(frozen=True)
class AxisExtents:
    """What the 2 n LPs over a polyhedron would report, in their order.

    Attributes
    ----------
    empty : bool
        No twist meets the rows.
    extremes : tuple of arrays
        The distinct optima (within ``SAME_TWIST``), minimum then maximum of entry 0, 1, ...
    free : tuple of int
        ``+(j + 1)`` where entry ``j`` grows without bound, ``-(j + 1)`` where it falls without bound.
    """

    empty: bool
    extremes: tuple[np.ndarray, ...] = ()
    free: tuple[int, ...] = ()


def line_axis_extents(E: np.ndarray, e: np.ndarray, A: np.ndarray, a: np.ndarray) -> AxisExtents | None:
    """The least and largest value of each entry over ``{q : E q = e, A q >= a}`` where ``E`` has rank n - 1;
    ``None`` where that rank does not hold exactly or the answer is too close to HiGHS's tolerance to call."""
    line = _line(E, e)
    if line is None:
        return None
    q0, d = line
    interval = _interval(A @ q0 - a, A @ d, np.linalg.norm(A, axis=1))
    if interval is None or interval == _EMPTY:
        return None if interval is None else AxisExtents(empty=True)
    ends = (None if interval[0] == -np.inf else q0 + interval[0] * d, None if interval[1] == np.inf else q0 + interval[1] * d)
    return _extents(ends, d)


_EMPTY = (np.inf, -np.inf)


def _line(E: np.ndarray, e: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """A point and a unit direction of ``{q : E q = e}`` where it is exactly a line (rank n - 1, consistent)."""
    n = E.shape[1]
    if E.shape[0] < n - 1 or n < 2:
        return None
    U, s, Vt = np.linalg.svd(E)
    if s[0] == 0.0 or s[n - 2] <= LINE_RANK * s[0] or (s.size >= n and s[n - 1] > LINE_NULL_SPACE * s[0]):
        return None
    q0 = Vt[: n - 1].T @ ((U[:, : n - 1].T @ e) / s[: n - 1])
    if np.max(np.abs(E @ q0 - e)) > 0.01 * LP_FEASIBILITY:
        return None  # the equalities disagree (or nearly): HiGHS decides
    return q0, Vt[n - 1]


def _interval(slack: np.ndarray, rate: np.ndarray, norms: np.ndarray) -> tuple[float, float] | None:
    """The range of ``t`` with ``slack + t rate >= 0`` on every row; ``_EMPTY``, or ``None`` where it is too close."""
    lo, hi = -np.inf, np.inf
    for s_i, r_i, norm in zip(slack.tolist(), rate.tolist(), norms.tolist(), strict=True):
        if abs(r_i) <= LINE_PARALLEL_ROW * norm:  # a row parallel to the line: met everywhere or nowhere
            if s_i < -10 * LP_FEASIBILITY:
                return _EMPTY
            if s_i < -0.1 * LP_FEASIBILITY:
                return None
        elif r_i > 0:
            lo = max(lo, -s_i / r_i)
        else:
            hi = min(hi, -s_i / r_i)
    if hi >= lo:
        return lo, hi
    return _EMPTY if hi < lo - 10 * LP_FEASIBILITY else None


def _extents(ends: tuple[np.ndarray | None, np.ndarray | None], d: np.ndarray) -> AxisExtents | None:
    """The LPs' answers, entry by entry, minimum first: an entry along ``d`` is least at one end and largest at
    the other (or unbounded past a missing end); an entry the line leaves constant is met at either end."""
    extremes: list[np.ndarray] = []
    free: list[int] = []
    for j, slope in enumerate(d.tolist()):
        for maximize in (False, True):
            if abs(slope) <= LINE_PARALLEL_ROW:
                end = ends[0] if ends[0] is not None else ends[1]
            else:
                end = ends[1] if (slope > 0) == maximize else ends[0]
                if end is None:
                    free.append(j + 1 if maximize else -(j + 1))
                    continue
            if end is None:
                return None  # a whole line: HiGHS picks the point
            if not any(np.max(np.abs(end - p)) <= SAME_TWIST for p in extremes):
                extremes.append(end)
    return AxisExtents(empty=False, extremes=tuple(extremes), free=tuple(free))
