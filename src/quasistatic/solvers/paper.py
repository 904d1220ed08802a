"""Method ``paper``: Trinkle & Hunter's own minimum-power program, solved to global optimality by SCIP.

The program and its status table live in :mod:`.certify.min_power`; this
front door refuses what the paper's formulation does not cover.
"""

from __future__ import annotations

from ..laws import Problem
from .certify.min_power import solve_min_power
from .result import BackendResult, Options

__all__ = ["solve_paper"]


def solve_paper(problem: Problem, options: Options) -> BackendResult:
    """Solve the paper's minimum-power program to global optimality.

    Parameters
    ----------
    problem : Problem
        Scene-relative laws: ``J`` (m, d, n_dof), ``b`` (m, d), ``g`` (n_dof,), ``mu`` (m,).
    options : Options
        ``time_limit`` [s] bounds the whole solve; prescribed ``modes`` are refused.

    Returns
    -------
    BackendResult
        ``solved`` with one motion (a global minimiser; uniqueness is not
        checked), or ``jammed``, ``unstable``, ``failed``.
    """
    options = options.start_clock()
    if options.modes is not None:
        return BackendResult("failed", "failed: the paper method does not take prescribed modes; use method 'scip'", certified=False)
    if problem.dimension == 3 and problem.friction.kind == "pyramid":
        return BackendResult("failed", f"failed: the paper's program uses the exact cone (eq. 8), not {problem.friction}", certified=False)
    return solve_min_power(problem, options)
