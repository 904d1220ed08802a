"""The closed-form extent of a polyhedron whose equalities leave a line, against HiGHS's 2 n warm LPs.

``line_axis_extents`` stands in for the 2 n LPs of a 3-D branch-and-bound leaf, so it must report what they
report: empty or not, the same free directions, and the same distinct optima, wherever it answers at all.
"""

from __future__ import annotations

import numpy as np
import pytest

from quasistatic.solvers.numerics.highs import WarmLP
from quasistatic.solvers.numerics.line_extent import AxisExtents, line_axis_extents
from quasistatic.tolerances import SAME_TWIST


def by_lps(E: np.ndarray, e: np.ndarray, A: np.ndarray, a: np.ndarray) -> AxisExtents | None:
    """The least and largest value of each entry, by HiGHS, as the branch and bound measures a leaf."""
    n = E.shape[1]
    model = WarmLP(np.vstack([E, A]), np.concatenate([e, a]), np.concatenate([e, np.full(a.size, np.inf)]))
    extremes: list[np.ndarray] = []
    free: list[int] = []
    for j in range(n):
        for maximize in (False, True):
            lp = model.optimise(np.eye(1, n, j)[0], maximize)
            if lp.status == "infeasible":
                return AxisExtents(empty=True)
            if lp.status == "unbounded":
                free.append(j + 1 if maximize else -(j + 1))
            elif lp.status != "optimal":
                return None
            elif not any(np.max(np.abs(lp.x - p)) <= SAME_TWIST for p in extremes):
                extremes.append(lp.x)
    return AxisExtents(empty=False, extremes=tuple(extremes), free=tuple(free))


def random_line_polyhedron(rng: np.random.Generator, n: int, rows: int) -> tuple[np.ndarray, ...]:
    """Equalities of rank n - 1 (one row repeated as a combination of two) through a point, inequalities around it."""
    E = rng.normal(size=(n - 1, n))
    E = np.vstack([E, E[0] + 2.0 * E[1]])
    point = rng.normal(size=n)
    A = rng.normal(size=(rows, n))
    a = A @ point - rng.uniform(-0.5, 1.0, size=rows)  # some rows cut the point off: empty lines occur too
    return E, E @ point, A, a


def assert_same(closed: AxisExtents, lps: AxisExtents) -> None:
    assert closed.empty == lps.empty and closed.free == lps.free
    assert len(closed.extremes) == len(lps.extremes)
    for mine in closed.extremes:
        assert min(np.max(np.abs(mine - theirs)) for theirs in lps.extremes) <= 1e-8


@pytest.mark.parametrize("seed", range(4))
def test_the_closed_form_reports_what_the_lps_report_on_random_lines(seed: int) -> None:
    rng = np.random.default_rng(seed)
    kinds = set()
    for _ in range(40):
        E, e, A, a = random_line_polyhedron(rng, n=int(rng.integers(3, 7)), rows=int(rng.integers(1, 9)))
        closed, lps = line_axis_extents(E, e, A, a), by_lps(E, e, A, a)
        assert closed is not None and lps is not None
        assert_same(closed, lps)
        kinds.add("empty" if closed.empty else "ray or line" if closed.free else "segment")
    assert kinds == {"empty", "ray or line", "segment"}  # every case met


def test_a_line_with_no_row_to_end_it_is_left_to_highs() -> None:
    E = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    A = np.array([[1.0, 0.0, 0.0]])  # parallel to the line, met everywhere on it
    assert line_axis_extents(E, np.zeros(2), A, np.array([-1.0])) is None  # HiGHS picks a point on a whole line


def test_ranks_other_than_a_line_and_disagreeing_equalities_are_left_to_highs() -> None:
    plane = np.array([[1.0, 0.0, 0.0]])
    assert line_axis_extents(plane, np.zeros(1), np.eye(3), np.zeros(3)) is None
    point = np.eye(3)
    assert line_axis_extents(point, np.zeros(3), np.eye(3), np.zeros(3)) is None
    disagree = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    assert line_axis_extents(disagree, np.array([0.0, 1.0, 0.0]), np.eye(3), -np.ones(3)) is None


def test_a_row_just_past_the_tolerance_is_too_close_to_call() -> None:
    E = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    A = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    assert line_axis_extents(E, np.zeros(2), A, np.array([2e-8, 0.0, -1.0])) is None  # within 1e-7: HiGHS decides
    empty = line_axis_extents(E, np.zeros(2), A, np.array([1e-5, 0.0, -1.0]))
    assert empty is not None and empty.empty
    segment = line_axis_extents(E, np.zeros(2), A, np.array([-1e-9, 0.0, -1.0]))
    assert segment is not None and not segment.empty and len(segment.extremes) == 2 and not segment.free
