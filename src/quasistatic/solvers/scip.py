"""Method ``scip``: the certified answer. Every motion, or a proof that there is none.

Polyhedral cones (2-D, or ``pyramid:K`` in 3-D): the complete mixed-integer
search over contact modes (:mod:`.certify.search`). Exact 3-D cones: that
search on inscribed pyramids, each motion refined to the circle, and the
verdicts proven for the circle (:mod:`.certify.exact_cone`).
"""

from __future__ import annotations

from ..laws import Problem
from ..laws.polyhedral import aligned_edges
from .certify.exact_cone import solve_exact_3d
from .certify.search import certified_polyhedral
from .result import BackendResult, Options

__all__ = ["solve_certified"]


def solve_certified(problem: Problem, options: Options) -> BackendResult:
    """The certified answer: every motion, or a proof that there is none, within ``options.time_limit``."""
    options = options.start_clock()
    if not problem.friction.is_polyhedral(problem.dimension):
        return solve_exact_3d(problem, options)
    return certified_polyhedral(problem, aligned_edges(problem, problem.friction.edges), options)
