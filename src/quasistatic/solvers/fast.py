"""Method ``fast``: one motion by Lemke's method on the polyhedral LCP; exact 3-D cones by re-aligned edges.

The polyhedral laws become one standard LCP by splitting the twist
(:mod:`.numerics.lcp`), which Lemke's method solves.

Exact 3-D cones: solve with an inscribed 6-edge pyramid, then turn each
sliding contact's pyramid so one edge lies exactly opposite its slip and
solve again (first from the previous complementary basis, which usually
still holds), until every sliding contact's friction is
``-mu cn slip/|slip|``. Rolling contacts' forces lie in the inscribed
pyramid, hence in the exact cone, so a converged answer satisfies the exact
laws. Before the first re-alignment, and whenever re-alignment stalls (a
pyramid lets a slip turn within its vertex's fan at no change of force, so
two motions can take turns), the exact laws are solved by Newton's method
with the contact modes of the current motion (:mod:`quasistatic.laws.fixed_modes`) (opening a contact whose normal
force turns negative, closing one that would penetrate); that answer is kept
only if every inequality holds, else re-alignment goes on.

What it proves: nothing. It finds one motion, or reports ``failed`` (Lemke
ended on a secondary ray or hit its pivot cap, or the exact-cone refinement
did not converge) so that the caller can fall back to the certified search. A ray is
no proof that no motion exists: Lemke's path reaches only solutions of index +1
(``sgn det M_SS``), and some scenes' motions all have index -1 (docs/performance.md). It never
reports jammed, unstable or ambiguous, checks neither uniqueness nor force
ranges, and cannot prescribe contact modes.

Everything numeric runs in one kernel, compiled by numba when it is installed.
"""

from __future__ import annotations

from ..laws import Problem, RawMotion
from .numerics.lcp import FAST_EDGES, NOT_CONVERGED, lemke_motion
from .numerics.lemke import PIVOT_LIMIT, RAY, SOLUTION
from .result import BackendResult, Options

__all__ = ["solve_fast", "FAST_EDGES"]

_SOLVED = "solved: one motion (fast path; uniqueness and force ranges not checked)"
_EXACT_STAGES = (  # how an exact 3-D answer was reached, by the kernel's stage
    f"{FAST_EDGES}-edge pyramid: every sliding contact's slip already opposed an edge",
    "pyramid edges re-aligned with the slips",
    "exact laws solved by Newton's method with the contact modes of the pyramid's motion",
)


def solve_fast(problem: Problem, options: Options) -> BackendResult:
    """One motion satisfying the laws, by Lemke's method; ``failed`` when it finds none.

    Parameters
    ----------
    problem : Problem
        Scene-relative contact laws; any friction model (2-D, 3-D pyramid, 3-D exact).
    options : Options
        Only ``modes`` is read: prescribed modes are not supported (``failed``).

    Returns
    -------
    BackendResult
        ``solved`` with one motion (twist ``q`` (k n,), contact-frame forces
        ``c`` (m, d)), not certified, or ``failed`` with the reason.
    """
    if options.modes is not None:
        return BackendResult("failed", "failed: the fast path (Lemke's method) cannot prescribe contact modes", certified=False)
    status, stage, q, c, pivots, realignments = lemke_motion(problem)
    if status != SOLUTION:
        return _failed(int(status), int(stage), int(pivots))
    notes: tuple[tuple[str, object], ...] = (("method", "lemke"), ("pivots", int(pivots)), ("realignments", int(realignments)))
    if problem.dimension == 3 and not problem.friction.is_polyhedral(3):
        notes += (("exact_cone", _EXACT_STAGES[int(stage)]),)
    return BackendResult("solved", _SOLVED, (RawMotion(q, c),), certified=False, notes=notes)


def _failed(status: int, stage: int, pivots: int) -> BackendResult:
    when = " after re-aligning the pyramid edges" if stage else ""
    why = {
        RAY: f"Lemke's method ended on a secondary ray{when} ({pivots} pivots): no motion found "
        "(there may be none, or only motions its path cannot reach)",
        PIVOT_LIMIT: f"Lemke's method hit its pivot limit{when} ({pivots} pivots)",
        NOT_CONVERGED: "the pyramid's motion did not converge to one of the exact cones "
        "(edge re-alignment, then Newton's method with its contact modes)",
    }[status]
    return BackendResult("failed", f"failed: {why} (fast path; the certified method can decide)", certified=False)
