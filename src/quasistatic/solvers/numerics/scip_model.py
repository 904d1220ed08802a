"""Small helpers for building SCIP models (``pyscipopt``), imported only where SCIP is used."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import SolverError
from ...stdio import captured_stderr, first_lines
from ...tolerances import LP_FEASIBILITY

__all__ = ["new_model", "linear", "optimize", "exclude_box"]


def new_model(time_limit: float) -> Any:
    """A silent SCIP model with this library's feasibility tolerance and a time limit [s]."""
    import pyscipopt

    scip = pyscipopt.Model()
    scip.hideOutput()
    scip.setParam("display/verblevel", 0)
    # Tighter makes SCIP ask SoPlex for < 1e-10, which it refuses on stdout; results are polished or checked after.
    scip.setParam("numerics/feastol", LP_FEASIBILITY)
    scip.setParam("limits/time", max(time_limit, 1e-3))  # the budget may already be spent
    return scip


def linear(row: np.ndarray, x: list[Any]) -> Any:
    """The SCIP expression ``row . x`` over the nonzero entries of ``row`` (plus 0.0, so an empty row is an expression)."""
    import pyscipopt

    return pyscipopt.quicksum(float(a) * v for a, v in zip(row, x, strict=False) if a != 0.0) + 0.0


def optimize(scip: Any, method: str) -> str:
    """Run SCIP; its status as text. A crash inside SCIP becomes the library's :class:`SolverError`."""
    with captured_stderr() as printed:  # SCIP's internal errors go to descriptor 2: kept for the message, not shown
        try:
            scip.optimize()
        except Exception as exc:  # SCIP raises bare Exceptions on internal failures
            said = first_lines(printed())
            raise SolverError(method, f"SCIP failed: {exc}" + (f" ({said})" if said else "")) from exc
    return str(scip.getStatus())


def exclude_box(scip: Any, q: list[Any], center: np.ndarray, distance: float) -> None:
    """Require some entry of the variables ``q`` to differ from ``center`` by at least ``distance`` (indicator constraints, no big-M)."""
    import pyscipopt

    choices = []
    tag = len(scip.getVars())  # unique names within the model
    for j, (var, value) in enumerate(zip(q, center, strict=True)):
        up = scip.addVar(vtype="B", name=f"up{j}_{tag}")
        down = scip.addVar(vtype="B", name=f"down{j}_{tag}")
        scip.addConsIndicator(-var <= -(float(value) + distance), up)
        scip.addConsIndicator(var <= float(value) - distance, down)
        choices += [up, down]
    scip.addCons(pyscipopt.quicksum(choices) >= 1)
