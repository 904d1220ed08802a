"""The HiGHS wrapper (``solvers/numerics/highs.py``): a dense constraint matrix goes to HiGHS column by column
exactly as SciPy's CSC conversion holds it (every LP the same model, to the bit, as before it skipped SciPy); an LP
solved ``simplex_first`` answers as without it, its infeasible verdict resting on a checked Farkas vector (HiGHS's
dual ray), and a ray that proves nothing is not taken (the vectors' check: ``test_farkas.py``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from quasistatic.solvers.numerics import farkas, highs


@pytest.mark.parametrize("shape", [(19, 6), (1, 3), (0, 4), (7, 1)])
def test_dense_columns_are_scipy_s_csc(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(sum(shape))
    A = rng.normal(size=shape)
    A[rng.random(shape) < 0.4] = 0.0
    if A.size:
        A.flat[0] = -0.0  # a signed zero is dropped, as SciPy drops it
    start, index, value = highs._columnwise(A)
    csc = sp.csc_matrix(A)
    for ours, scipys in ((start, csc.indptr), (index, csc.indices), (value, csc.data)):
        np.testing.assert_array_equal(ours, scipys)
        assert ours.dtype == scipys.dtype


def test_a_dense_lp_answers_as_its_sparse_copy() -> None:
    A = np.array([[1.0, 0.0, 2.0], [0.0, -1.0, 1.0], [1.0, 1.0, 0.0]])
    lower, upper = np.array([1.0, -np.inf, 0.5]), np.array([4.0, 2.0, np.inf])
    cost = np.array([1.0, 2.0, -1.0])
    bounds = (np.zeros(3), np.full(3, 5.0))
    dense = highs.solve_lp(cost, A, lower, upper, *bounds)
    sparse = highs.solve_lp(cost, sp.csr_matrix(A), lower, upper, *bounds)
    assert dense.status == sparse.status == "optimal"
    np.testing.assert_array_equal(dense.x, sparse.x)
    assert dense.objective == sparse.objective


def _leaves() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """A feasible LP, an infeasible one, and a sector relaxation's leaf that HiGHS's dual simplex leaves without a
    status even with presolve off (the interior-point retry answers it: ``test_certified.py``)."""
    square = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    feasible = (square, np.array([0.0, 0.0, 0.5]), np.array([1.0, 1.0, 1.5]))
    infeasible = (square, np.array([0.0, 0.0, 2.5]), np.array([1.0, 1.0, np.inf]))
    data = {k: np.asarray(v) for k, v in json.loads((Path(__file__).parent / "data" / "highs_no_status_lp.json").read_text()).items()}
    rows = np.vstack([data["E"], data["A"]])
    lower = np.concatenate([data["e"] - 1e-7, data["a"] - 1e-7])
    upper = np.concatenate([data["e"] + 1e-7, np.full(len(data["a"]), np.inf)])
    return [feasible, infeasible, (rows, lower, upper)]


@pytest.mark.parametrize("by_fit", [True, False])
@pytest.mark.parametrize("which", [0, 1, 2])
def test_simplex_first_answers_as_without_it(which: int, by_fit: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    if not by_fit:
        monkeypatch.setattr(highs, "infeasible_by_fit", lambda *a: False)  # HiGHS's cold simplex and its ray answer
    A, lower, upper = _leaves()[which]
    cost = np.zeros(A.shape[1])
    usual, first = highs.solve_lp(cost, A, lower, upper), highs.solve_lp(cost, A, lower, upper, simplex_first=True)
    assert usual.status == first.status == ("optimal" if which == 0 else "infeasible")
    if which == 0:  # an infeasible LP's point means nothing
        np.testing.assert_array_equal(usual.x, first.x)


def test_an_infeasible_verdict_without_a_proving_ray_is_solved_again(monkeypatch: pytest.MonkeyPatch) -> None:
    n = farkas.FIT_COLUMNS + 1  # too large for the Farkas fit: x <= 1 and sum(x) >= n + 1
    A = np.vstack([np.eye(n), np.ones((1, n))])
    lower, upper = np.append(np.full(n, -np.inf), n + 1.0), np.append(np.ones(n), np.inf)
    cost = np.zeros(n)
    runs: list[str] = []
    run = highs._run
    monkeypatch.setattr(highs, "_run", lambda *a: runs.append("run") or run(*a))
    assert highs.solve_lp(cost, A, lower, upper, simplex_first=True).status == "infeasible"
    assert runs == []  # the ray proved it: one simplex run
    monkeypatch.setattr(highs, "_ray_proves_infeasible", lambda *a: False)
    assert highs.solve_lp(cost, A, lower, upper, simplex_first=True).status == "infeasible"
    assert runs == ["run"]
