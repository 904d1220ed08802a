"""Scenes too large for a method's dense matrices: an honest ``failed`` instead of gigabytes and a crash.

The frictional methods (``certified``, ``scip``, ``fast``, ``paper``) build the polyhedral
laws as dense matrices whose size grows as the square of the contacts: a box
resting on 10,000 frictional points asks for a 40,000 x 40,006 matrix (12
GiB) before the search starts, and the search itself could not finish on
16 points in 25 s. Past :data:`~quasistatic.tolerances.MAX_DENSE_BYTES` the
method is not run. When every mover is still, rest (the zero twist) is
checked with one sparse LP for forces within the friction cones: if it
exists it is returned as the motion of the ``failed`` answer (audited like
any other, never called unique).
"""

from __future__ import annotations

import numpy as np

from ..laws import ModeMasks, Problem, RawMotion
from ..tolerances import MAX_DENSE_BYTES
from .numerics.forces import least_normal_forces
from .result import BackendResult

__all__ = ["dense_bytes", "too_large"]

DENSE_METHODS = ("certified", "scip", "fast", "paper")
_EXACT_EDGES = 8  # polygon inscribed in an exact 3-D cone for the rest check (and the certified search's first)


def dense_bytes(problem: Problem, method: str) -> int:
    """Bytes of the polyhedral laws' dense complementarity matrix for ``method`` (0 for a method without one).

    Rows: normal, edge and slack conditions, ``m (K + 2)``; columns: those and
    the twist. ``K`` is 2 in 2-D and at least the first search's 8 on exact
    3-D cones, so this is a lower bound of what the method allocates.
    """
    if method not in DENSE_METHODS or problem.is_frictionless:
        return 0
    rows = problem.n_contacts * (_edges(problem) + 2)
    return 8 * rows * (rows + problem.n_dof)


def too_large(problem: Problem, method: str) -> BackendResult | None:
    """``failed`` (with the rest motion when there is one) when ``method``'s dense matrices would pass the limit; else None."""
    size = dense_bytes(problem, method)
    if size <= MAX_DENSE_BYTES:
        return None
    why = (
        f"failed: method {method!r} would build dense matrices of {size / 2**30:.1f} GiB for "
        f"{problem.n_contacts} frictional contacts (limit {MAX_DENSE_BYTES / 2**30:.0f} GiB), so it was not run"
    )
    rest = _rest(problem)
    if rest is None:
        return BackendResult("failed", why + "; no motion is known", certified=False)
    more = "; the bodies can stay at rest (the motion shown, audited), but no proof that this is the only motion"
    return BackendResult("failed", why + more, (rest,), certified=False)


def _rest(problem: Problem) -> RawMotion | None:
    """The zero twist with forces of least total normal force in the friction cones, when the movers are still."""
    if np.any(problem.b != 0.0):
        return None  # a moving mover: rest would need a proof of its own
    m = problem.n_contacts
    closed = np.ones(m, dtype=bool)
    masks = ModeMasks(closed, closed & (problem.mu > 0), ~closed)
    q = np.zeros(problem.n_dof)
    forces = least_normal_forces(problem, q, masks, _edges(problem))
    return None if forces is None else RawMotion(q, forces)


def _edges(problem: Problem) -> int:
    if problem.dimension == 2:
        return 2
    return problem.friction.edges if problem.friction.kind == "pyramid" else _EXACT_EDGES
