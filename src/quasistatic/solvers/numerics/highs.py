"""A thin wrapper around HiGHS (``highspy``) for the LPs of this library.

One LP (:func:`solve_lp`) runs on this thread's HiGHS instance: each call
passes a whole new model and the instance's options never change, so nothing
of one call reaches the next (creating an instance costs ~0.1 ms, more than a
small LP). A :class:`WarmLP`, which keeps a basis across objectives and
switches the simplex strategy, owns an instance of its own."""

from __future__ import annotations

import os
import sys
import threading
from dataclasses import dataclass
from typing import Literal

import highspy
import numpy as np
import scipy.sparse as sp

from ...errors import SolverError
from ...tolerances import HIGHS_SMALLEST_ENTRY, LP_FEASIBILITY
from .farkas import FIT_COLUMNS, Bounds, infeasible_by_fit, proves_infeasible

__all__ = ["LPResult", "solve_lp", "solve_qp", "optimise_each", "WarmLP", "INF"]

INF = float("inf")
LPStatus = Literal["optimal", "infeasible", "unbounded", "unbounded_or_infeasible", "error"]

# Every HiGHS model status, mapped explicitly.
_STATUS: dict[highspy.HighsModelStatus, LPStatus] = {
    highspy.HighsModelStatus.kOptimal: "optimal",
    highspy.HighsModelStatus.kInfeasible: "infeasible",
    highspy.HighsModelStatus.kUnbounded: "unbounded",
    highspy.HighsModelStatus.kUnboundedOrInfeasible: "unbounded_or_infeasible",
    highspy.HighsModelStatus.kModelEmpty: "optimal",
}

_local = threading.local()


def _silence_banner() -> None:
    """Make the process's first HiGHS instance with stdout pointed at /dev/null.

    HiGHS prints a two-line banner on stdout when its first instance is
    created, before ``output_flag`` can be set; it is C++ output, so only the
    file descriptor can stop it (``--json`` output must be JSON and nothing
    else). Later instances print nothing.
    """
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no stdout at all: nothing to protect
        highspy.Highs()
        return
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            highspy.Highs()
    finally:
        os.dup2(saved, 1)
        os.close(saved)


_silence_banner()
_PRIMAL_SIMPLEX = 4  # HiGHS simplex_strategy value (its default, 1, is dual simplex)


def _new_highs() -> highspy.Highs:
    solver = highspy.Highs()
    solver.setOptionValue("output_flag", False)
    # Scene-relative data: an entry of 1e-10 is a real (tiny) tilt, not noise to drop.
    solver.setOptionValue("small_matrix_value", HIGHS_SMALLEST_ENTRY)
    return solver


def _thread_highs() -> highspy.Highs:
    """This thread's instance for single LPs (options fixed at creation, a new model each call)."""
    solver = getattr(_local, "highs", None)
    if solver is None:
        solver = _local.highs = _new_highs()
    return solver


@dataclass(frozen=True)
class LPResult:
    """Status, primal point, row duals (>= 0 on active lower bounds) and objective."""

    status: LPStatus
    x: np.ndarray
    row_dual: np.ndarray
    objective: float


def solve_lp(
    cost: np.ndarray,
    A: np.ndarray | sp.spmatrix,
    row_lower: np.ndarray,
    row_upper: np.ndarray,
    col_lower: np.ndarray | None = None,
    col_upper: np.ndarray | None = None,
    maximize: bool = False,
    simplex_first: bool = False,
) -> LPResult:
    """Solve ``min cost.x  s.t.  row_lower <= A x <= row_upper, col_lower <= x <= col_upper``.

    Columns are free unless bounds are given. Infinite bounds use ``float('inf')``.

    ``simplex_first``, for LPs that are mostly infeasible (a branch and bound's leaves). A small dense LP (at most
    :data:`.farkas.FIT_COLUMNS` columns) is proven infeasible without HiGHS where a non-negative fit finds a
    Farkas vector for it with every row loosened by ``LP_FEASIBILITY`` more (:func:`.farkas.infeasible_by_fit`:
    microseconds, where a HiGHS run costs ~0.3-1 ms; an LP that close to a point is left to HiGHS's tolerance).
    A larger one is solved by the simplex without presolve first, and where it finds the LP infeasible and its
    dual ray proves it (:func:`_ray_proves_infeasible`), that is the answer. Otherwise the LP is solved as
    without ``simplex_first``, so an optimal point is the same.
    """
    if cost.size == 0:  # HiGHS calls a model without columns "empty" whatever its rows demand
        return _without_columns(row_lower, row_upper)
    rows, columns = (row_lower, row_upper), (col_lower, col_upper)
    small = not sp.issparse(A) and A.shape[1] <= FIT_COLUMNS
    if simplex_first and small and infeasible_by_fit(np.asarray(A), rows, columns, LP_FEASIBILITY):
        return _infeasible(cost.size, A.shape[0])
    solver = _load(_thread_highs(), cost, A, row_lower, row_upper, col_lower, col_upper, maximize)
    if simplex_first and not small:  # (a small LP the fit left is mostly feasible: the usual run answers it at once)
        if _cold_simplex(solver) == "infeasible" and _ray_proves_infeasible(solver, A, rows, columns):
            return _result(solver, cost, maximize, "infeasible")
        solver.clearSolver()
    return _run(solver, cost, maximize)


def _ray_proves_infeasible(solver: highspy.Highs, A: np.ndarray | sp.spmatrix, rows: Bounds, columns: Bounds) -> bool:
    """Whether HiGHS's dual ray of the infeasible LP just solved is a Farkas vector (:func:`.farkas.proves_infeasible`)."""
    _, exists, ray = solver.getDualRay()  # type: ignore[attr-defined]  # missing from highspy 1.16's stubs
    return bool(exists) and proves_infeasible(np.asarray(ray), A, rows, columns)


def solve_qp(
    hessian: sp.spmatrix,
    A: np.ndarray | sp.spmatrix,
    row_lower: np.ndarray,
    row_upper: np.ndarray,
    col_lower: np.ndarray | None = None,
    col_upper: np.ndarray | None = None,
    cost: np.ndarray | None = None,
) -> LPResult:
    """Solve the convex QP ``min 1/2 x.H x + cost.x  s.t.  row_lower <= A x <= row_upper, col_lower <= x <= col_upper``.

    ``hessian`` (n, n) must be symmetric positive semi-definite; a fresh HiGHS instance
    solves it (a Hessian would otherwise stay on this thread's LP instance).
    """
    n = hessian.shape[0]
    if n == 0:
        return _without_columns(row_lower, row_upper)
    cost = np.zeros(n) if cost is None else cost
    solver = _load(_new_highs(), cost, A, row_lower, row_upper, col_lower, col_upper, False)
    lower = sp.tril(sp.csc_matrix(hessian)).tocsc()  # HiGHS reads the lower triangle, column by column
    lower.eliminate_zeros()
    matrix = highspy.HighsHessian()
    matrix.dim_ = n
    matrix.format_ = highspy.HessianFormat.kTriangular
    matrix.start_ = lower.indptr
    matrix.index_ = lower.indices
    matrix.value_ = lower.data
    try:
        solver.passHessian(matrix)
    except Exception as exc:  # a crash inside HiGHS, not a status
        raise SolverError("highs", f"HiGHS failed: {exc}") from exc
    result = _run(solver, cost, False)
    objective = 0.5 * float(result.x @ (hessian @ result.x)) + float(cost @ result.x) if result.status == "optimal" else float("nan")
    return LPResult(result.status, result.x, result.row_dual, objective)


def _infeasible(n: int, m: int) -> LPResult:
    """An LP proven infeasible without HiGHS: no point, no duals."""
    return LPResult("infeasible", np.zeros(n), np.zeros(m), float("nan"))


def _without_columns(row_lower: np.ndarray, row_upper: np.ndarray) -> LPResult:
    """An LP with no unknowns: feasible exactly when every row's range holds 0 (each row is 0)."""
    feasible = bool(np.all(np.asarray(row_lower) <= 0.0) and np.all(np.asarray(row_upper) >= 0.0))
    return LPResult("optimal" if feasible else "infeasible", np.zeros(0), np.zeros(len(row_lower)), 0.0 if feasible else float("nan"))


def optimise_each(
    objectives: list[tuple[np.ndarray, bool]],
    A: np.ndarray | sp.spmatrix,
    row_lower: np.ndarray,
    row_upper: np.ndarray,
    col_lower: np.ndarray | None = None,
    col_upper: np.ndarray | None = None,
) -> list[LPResult]:
    """Solve one feasible set for each ``(cost, maximize)`` in turn, as :func:`solve_lp` would (see :class:`WarmLP`)."""
    if not objectives:
        return []
    model = WarmLP(A, row_lower, row_upper, col_lower, col_upper)
    return [model.optimise(cost, maximize) for cost, maximize in objectives]


class WarmLP:
    """One feasible set passed to HiGHS once, optimised for one objective after another.

    Each objective starts from the previous optimal basis (a range needs two
    LPs per unknown: warm starts make the second and later ones a few pivots
    each). Owns its HiGHS instance.
    """

    def __init__(
        self,
        A: np.ndarray | sp.spmatrix,
        row_lower: np.ndarray,
        row_upper: np.ndarray,
        col_lower: np.ndarray | None = None,
        col_upper: np.ndarray | None = None,
    ) -> None:
        self.n = A.shape[1]
        self._solver = _load(_new_highs(), np.zeros(self.n), A, row_lower, row_upper, col_lower, col_upper, False)
        self._columns = np.arange(self.n, dtype=np.int32)
        self._warm = False

    def optimise(self, cost: np.ndarray, maximize: bool = False) -> LPResult:
        self._solver.changeColsCost(self.n, self._columns, -cost if maximize else cost)  # always minimised, as in _load
        if not self._warm:
            self._warm = True
            return _run(self._solver, cost, maximize)
        # A new objective leaves the last optimal basis primal feasible: primal simplex goes on from it
        # (measured 2x faster than HiGHS's default dual simplex on the 100-box pile's force ranges).
        self._solver.setOptionValue("simplex_strategy", _PRIMAL_SIMPLEX)
        return _run(self._solver, cost, maximize)


def _load(
    solver: highspy.Highs,
    cost: np.ndarray,
    A: np.ndarray | sp.spmatrix,
    row_lower: np.ndarray,
    row_upper: np.ndarray,
    col_lower: np.ndarray | None,
    col_upper: np.ndarray | None,
    maximize: bool,
) -> highspy.Highs:
    n = cost.size
    m = A.shape[0]
    start, index, value = _columnwise(A)
    lp = highspy.HighsLp()
    lp.num_col_ = n
    lp.num_row_ = m
    lp.col_cost_ = -cost if maximize else cost
    lp.col_lower_ = np.full(n, -INF) if col_lower is None else col_lower
    lp.col_upper_ = np.full(n, INF) if col_upper is None else col_upper
    lp.row_lower_ = row_lower
    lp.row_upper_ = row_upper
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = start
    lp.a_matrix_.index_ = index
    lp.a_matrix_.value_ = value
    try:
        solver.passModel(lp)
    except Exception as exc:  # a crash inside HiGHS, not a status
        raise SolverError("highs", f"HiGHS failed: {exc}") from exc
    return solver


def _columnwise(A: np.ndarray | sp.spmatrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``A``'s nonzeros column by column (HiGHS's ``kColwise``: column starts, row indices, values), as
    ``scipy.sparse.csc_matrix(A)`` holds them; a dense ``A`` without SciPy's conversion (~65 us of an LP's ~0.7 ms
    on the sector relaxation's small leaves)."""
    if sp.issparse(A):
        matrix = sp.csc_matrix(A)
        return matrix.indptr, matrix.indices, matrix.data
    columns = np.asarray(A, dtype=float).T
    nonzero = columns != 0.0
    start = np.zeros(columns.shape[0] + 1, dtype=np.int32)
    np.cumsum(nonzero.sum(axis=1), out=start[1:])
    return start, np.nonzero(nonzero)[1].astype(np.int32), columns[nonzero]


def _run(solver: highspy.Highs, cost: np.ndarray, maximize: bool) -> LPResult:
    status = _solve(solver)
    if status in ("infeasible", "unbounded_or_infeasible", "error"):
        # HiGHS's presolve has called a feasible, degenerate LP infeasible (tiny entries it keeps, rows
        # redundant to round-off: a pattern of a peg sliding in a slot), or a warm-started simplex has
        # stopped without a status (kUnknown: a continuum's extent in the same slot); either is confirmed,
        # or answered, by the simplex alone from a cold start before anyone relies on it.
        status = _cold_simplex(solver)
    if status == "error":
        # The dual simplex can stop without a status on thin, degenerate sets (a sector relaxation's leaf of
        # four coplanar sliding supports, narrow sectors); the interior-point method answers them.
        solver.setOptionValue("solver", "ipm")
        solver.clearSolver()
        status = _solve(solver)
        solver.setOptionValue("solver", "choose")
    return _result(solver, cost, maximize, status)


def _cold_simplex(solver: highspy.Highs) -> LPStatus:
    """The loaded LP solved by the simplex alone (no presolve), from a cold start."""
    solver.setOptionValue("presolve", "off")
    solver.clearSolver()
    status = _solve(solver)
    solver.setOptionValue("presolve", "choose")
    return status


def _result(solver: highspy.Highs, cost: np.ndarray, maximize: bool, status: LPStatus) -> LPResult:
    """The solved LP's point, row duals and objective, with ``status``."""
    n = cost.size
    m = solver.getNumRow()
    solution = solver.getSolution()
    x = np.array(solution.col_value) if n else np.zeros(0)
    duals = np.array(solution.row_dual) if m else np.zeros(0)
    if maximize:
        duals = -duals
    objective = float(cost @ x) if status == "optimal" else float("nan")
    return LPResult(status, x, duals, objective)


def _solve(solver: highspy.Highs) -> LPStatus:
    try:
        solver.run()
    except Exception as exc:  # a crash inside HiGHS, not a status
        raise SolverError("highs", f"HiGHS failed: {exc}") from exc
    return _STATUS.get(solver.getModelStatus(), "error")
