"""Infeasible LPs proven by checked Farkas vectors (``solvers/numerics/farkas.py``): a vector proves only what it
bounds, a non-negative fit finds one for a small infeasible LP (then HiGHS is not asked), and an LP infeasible by
less than the slack, or feasible, is left to HiGHS."""

from __future__ import annotations

import numpy as np
import pytest

from quasistatic.solvers.numerics import farkas, highs

SQUARE = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])  # x1, x2 <= 1 and x1 + x2 >= top
INF = np.inf


def _rows(top: float) -> farkas.Bounds:
    return np.array([-INF, -INF, top]), np.array([1.0, 1.0, INF])


def test_a_farkas_vector_proves_only_what_it_bounds() -> None:
    rows = _rows(2.5)  # 0 = y.(A x) >= 2.5 - 2 with y = (-1, -1, 1)
    assert farkas.proves_infeasible(np.array([-1.0, -1.0, 1.0]), SQUARE, rows, (None, None))
    assert not farkas.proves_infeasible(np.array([1.0, 1.0, -1.0]), SQUARE, rows, (None, None))  # the other sign
    assert not farkas.proves_infeasible(np.array([-1.0, -1.0, 1.0]), SQUARE, _rows(1.5), (None, None))  # (1, 0.5) is a point
    assert not farkas.proves_infeasible(np.array([-1.0, -1.0, 1.0]), SQUARE, rows, (None, None), slack=0.2)  # 0.5 - 3 * 0.2 < 0
    # A^T y = (0, 1): x2 free bounds nothing; x2 <= 1 bounds it
    assert not farkas.proves_infeasible(np.array([-1.0, 0.0, 1.0]), SQUARE, rows, (None, None))
    assert farkas.proves_infeasible(np.array([-1.0, 0.0, 1.0]), SQUARE, rows, (None, np.array([INF, 1.0])))


def test_round_off_in_a_vector_is_not_read_as_an_unbounded_term() -> None:
    A = np.vstack([SQUARE, SQUARE[2]])
    rows = (np.append(_rows(2.5)[0], -1.0), np.append(_rows(2.5)[1], INF))  # a fourth row x1 + x2 >= -1
    assert farkas.proves_infeasible(np.array([-1.0, -1.0, 1.0, -1e-14]), A, rows, (None, None))
    assert not farkas.proves_infeasible(np.array([-1.0, -1.0, 1.0, -1e-3]), A, rows, (None, None))


@pytest.mark.parametrize(("top", "slack", "proven"), [(2.5, 0.0, True), (2.5, 0.1, True), (2.0 + 1e-9, 1e-7, False), (1.5, 0.0, False)])
def test_a_fit_finds_the_vector_of_a_small_infeasible_lp(top: float, slack: float, proven: bool) -> None:
    assert farkas.infeasible_by_fit(SQUARE, _rows(top), (None, None), slack) is proven


def test_a_fit_reads_column_bounds() -> None:
    # x1 + x2 >= 2.5 alone has points; with 0 <= x <= 1 it has none
    A, rows = SQUARE[2:], (np.array([2.5]), np.array([INF]))
    assert not farkas.infeasible_by_fit(A, rows, (None, None), 0.0)
    assert farkas.infeasible_by_fit(A, rows, (np.zeros(2), np.ones(2)), 0.0)


def test_a_large_lp_is_left_to_highs() -> None:
    n = farkas.FIT_COLUMNS + 1
    A = np.vstack([np.eye(n), np.ones((1, n))])
    rows = (np.append(np.full(n, -INF), n + 1.0), np.append(np.ones(n), INF))
    assert not farkas.infeasible_by_fit(A, rows, (None, None), 0.0)
    assert highs.solve_lp(np.zeros(n), A, *rows, simplex_first=True).status == "infeasible"


def test_simplex_first_answers_a_proven_lp_without_highs(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_highs(*args: object) -> None:
        raise AssertionError("HiGHS was asked")

    monkeypatch.setattr(highs, "_load", no_highs)
    assert highs.solve_lp(np.zeros(2), SQUARE, *_rows(2.5), simplex_first=True).status == "infeasible"
    with pytest.raises(AssertionError):
        highs.solve_lp(np.zeros(2), SQUARE, *_rows(1.5), simplex_first=True)  # feasible: HiGHS answers
