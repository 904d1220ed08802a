"""Method ``fast``: one motion by Lemke's method on the polyhedral LCP; exact 3-D cones by re-aligned edges.

The polyhedral laws become one standard LCP by splitting the twist
(:mod:`.numerics.lcp`), which Lemke's method solves on a shorter path than
the textbook one: the twist's halves are free variables (kept basic once they
enter), and the covering vector is :data:`~.numerics.lcp.GAP_COVERING` on the
gap rates' rows (grasp-3d 8 #0: 59 pivots instead of 143, and its ray ends
where Newton's first start converges; the certified method's candidate keeps
the textbook path).

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

Where Lemke cannot answer (a secondary ray, its pivot cap, or an exact-cone
refinement that did not converge), a complete method takes over. A ray is no
proof that no motion exists: Lemke's path reaches only solutions of index +1
(``sgn det M_SS``), and some scenes' motions all have index -1 (docs/performance.md).
On exact 3-D cones the point where the path ended is tried first as a start of
Newton's method, as above (with quick mode switches, then quick rounds that switch
one contact at a time, then with the contacts the path held closed, penetrating by
its artificial variable, closed: it converges on some scenes whose pyramid LCP has
no solution Lemke reaches; a motion it returns keeps every mode and inequality).

- One planar body: a motion at a vertex of the contacts' gap-rate and slip
  planes (:func:`~.certify.arrangement.motion_vertex`); where no vertex holds
  one, the vertex certificate proves that no motion exists.
- Otherwise (several bodies, 3-D), and where the vertices decide nothing: the
  mode branch and bound (:mod:`.certify.patterns`) stopped at its first
  motion, on the problem's own polyhedral laws (exact 3-D cones: an inscribed
  8-edge pyramid, whose Lemke point, a solution or where its path ended, is
  first tried as a start of Newton's method; then the first of its motions from which Newton's method, as
  above, converges to the exact cones; where none does, or equilibrium is too
  close to call, the same with 32 edges); a closed tree proves that no motion
  exists. Past the branch and bound's node budget, SCIP's complete search
  (:func:`~.certify.search.enumerate_motions`) stopped at its first motion.

What it proves: nothing about the motions it finds, which are never claimed
unique (no ambiguous either), and force ranges are not checked. When a
complete method proves that no motion exists, the answer is ``jammed`` or
``unstable`` with that certificate (:func:`~.certify.diagnose.diagnose`). On
exact 3-D cones the pyramid's proof holds for the circle for a kinematic jam,
or no equilibrium even in the circumscribed pyramid; a wedge is proven by the
exact cones' sector relaxation (:mod:`.certify.wedge`), whose points are tried
as starts of Newton's method.
Otherwise ``failed`` says why, so that the caller can fall back to the
certified search. Prescribed contact modes are not supported.

Lemke's method and Newton's run in one kernel, compiled by numba when it is installed.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..laws import Problem, RawMotion
from ..laws.polyhedral import aligned_edges, polyhedral_form
from ..solution import Certificate, CertificateKind, Diagnosis
from .certify.arrangement import NO_VERTEX_PROOF, VertexVerdict, motion_vertex, prove_by_vertices
from .certify.cheap import lemke_point
from .certify.diagnose import diagnose, no_motion
from .certify.patterns import NO_MOTION_PROOF, PatternVerdict, prove_by_patterns
from .certify.search import enumerate_motions
from .certify.wedge import exact_cones_jam
from .numerics.lcp import FAST_EDGES, NEWTON_ITERATIONS, NOT_CONVERGED, QUICK_PATIENCE, exact_newton, lemke_depth, lemke_motion
from .numerics.lemke import PIVOT_LIMIT, RAY, SOLUTION
from .result import BackendResult, Options

__all__ = ["solve_fast", "FAST_EDGES"]

_SOLVED = "solved: one motion (fast path; uniqueness and force ranges not checked)"
_EXACT_STAGES = (  # how an exact 3-D answer was reached, by the kernel's stage
    f"{FAST_EDGES}-edge pyramid: every sliding contact's slip already opposed an edge",
    "pyramid edges re-aligned with the slips",
    "exact laws solved by Newton's method with the contact modes of the pyramid's motion",
)
# Inscribed pyramids of the exact cones' fallback (the certified search's two): Newton failed from 6 edges'
# motions on grasp-3d 8 #0; 32 where 8 leave it undecided (3 of 400 random 3-D scenes).
FALLBACK_EDGES = (8, 32)
_EXACT_FROM_RELAXATION = "exact laws solved by Newton's method from a point of the exact cones' sector relaxation"
_NOT_EXACT = "no motion of the 8- or 32-edge pyramid converged to the exact cones by Newton's method"
_FRICTIONLESS_PROOF = "no admissible twist, or no equilibrium: without friction either proves that no motion exists"
_EXACT_FROM_PYRAMID = "exact laws solved by Newton's method with the contact modes of the branch and bound's pyramid motion"
_FROM_LEMKE_END = "Newton's method from where Lemke's path ended"
_EXACT_FROM_LEMKE_END = "exact laws solved by Newton's method with the contact modes of the last point of Lemke's path"


def solve_fast(problem: Problem, options: Options) -> BackendResult:
    """One motion satisfying the laws, by Lemke's method, else by the complete fallback (module docstring).

    Parameters
    ----------
    problem : Problem
        Scene-relative contact laws; any friction model (2-D, 3-D pyramid, 3-D exact).
    options : Options
        ``modes``: prescribed modes are not supported (``failed``); ``time_limit``: the fallback's searches.

    Returns
    -------
    BackendResult
        ``solved`` with one motion (twist ``q`` (k n,), contact-frame forces
        ``c`` (m, d)), not certified; ``jammed`` or ``unstable`` proven by the
        fallback, with its certificate; or ``failed`` with the reason.
    """
    if options.modes is not None:
        return BackendResult("failed", "failed: the fast path (Lemke's method) cannot prescribe contact modes", certified=False)
    status, stage, q, c, pivots, realignments = lemke_motion(problem, short_path=True)
    if status != SOLUTION:
        lemke = _why_lemke_failed(int(status), int(stage), int(pivots))
        if status in (RAY, PIVOT_LIMIT) and _is_exact(problem):
            found = _from_lemke_end(problem, q, c, (("lemke", lemke), ("method", _FROM_LEMKE_END)))
            if found is not None:
                return found
        return _complete_fallback(problem, options, lemke)
    notes: tuple[tuple[str, object], ...] = (("method", "lemke"), ("pivots", int(pivots)), ("realignments", int(realignments)))
    if _is_exact(problem):
        notes += (("exact_cone", _EXACT_STAGES[int(stage)]),)
    return BackendResult("solved", _SOLVED, (RawMotion(q, c),), certified=False, notes=notes)


def _complete_fallback(problem: Problem, options: Options, lemke: str) -> BackendResult:
    """Where Lemke's method found nothing: one motion by a complete method, or its proof that none exists.

    Exact 3-D cones: the 8-edge pyramid first; where its motions do not converge to the exact cones, or whether
    the exact cones admit an equilibrium is too close to call, the 32-edge pyramid (as the certified search).
    """
    options = options.start_clock()
    if problem.friction.kind == "none" and problem.dimension == 3:  # in the plane the vertex proof is cheaper still
        verdict = _frictionless_no_motion(problem, lemke)
        if verdict is not None:
            return verdict
    if problem.dimension == 2 or problem.friction.is_polyhedral(3):
        return _on_pyramid(problem, options, lemke, problem.friction.edges, exact=False) or _failed(lemke)
    for count in FALLBACK_EDGES:
        result = _on_pyramid(problem, options, lemke, count, exact=True)
        if result is not None:
            return result
    return _failed(f"{lemke}; {_NOT_EXACT}, or whether the exact cones admit an equilibrium was too close to call")


def _frictionless_no_motion(problem: Problem, lemke: str) -> BackendResult | None:
    """Without friction the laws are the optimality conditions of an LP (twists meeting the gap rows, forces
    balancing the load), so a motion exists wherever an admissible twist and an equilibrium both do: a kinematic
    Farkas certificate, or a certificate of no equilibrium, proves by itself that none exists, and no search is
    needed. None where both exist (a motion Lemke's path missed: the search finds it)."""
    verdict = diagnose(problem, aligned_edges(problem, problem.friction.edges))
    if verdict.diagnosis in (Diagnosis.KINEMATIC, Diagnosis.NO_EQUILIBRIUM):
        return verdict.with_notes(certificate=_FRICTIONLESS_PROOF, lemke=lemke)
    return None


def _on_pyramid(problem: Problem, options: Options, lemke: str, count: int, exact: bool) -> BackendResult | None:
    """The fallback on the polyhedral laws with ``count`` edges (exact cones: an inscribed pyramid); None where a
    finer pyramid may decide (exact cones only)."""
    edges = aligned_edges(problem, count)
    form = polyhedral_form(problem, edges)
    notes: tuple[tuple[str, object], ...] = (("lemke", lemke),)
    point = motion_vertex(form)
    if point is not None:
        return _found(RawMotion(point[: form.n_q], form.forces(point)), notes + (("method", "arrangement vertex"),))
    vertices = prove_by_vertices(form, None)
    if vertices.verdict is VertexVerdict.NONE:
        verdict = diagnose(problem, edges, equilibrium=vertices.equilibrium, admissible=vertices.admissible)
        return verdict.with_notes(certificate=NO_VERTEX_PROOF, lemke=lemke)
    accept = _Acceptance(problem, exact)
    hint = lemke_point(form)[1] if form.n_edges > 2 else None  # 3-D: where Lemke ended orders the tree (2x fewer nodes)
    if exact and hint is not None:  # that point as a start of Newton's method: cheaper than the tree, where it converges
        found = _from_lemke_end(problem, hint[: form.n_q], form.forces(hint), notes + (("method", f"{_FROM_LEMKE_END} ({count} edges)"),))
        if found is not None:
            return found
    proof = prove_by_patterns(form, None, remaining=options.remaining, stop_at=accept, hint_x=hint)
    if proof.verdict is PatternVerdict.FOUND and accept.motion is not None:
        return _found(accept.motion, notes + (("method", f"mode branch and bound ({count} edges)"), *accept.notes))
    if proof.verdict is PatternVerdict.NONE:
        return _no_motion(problem, options, edges, exact, proof.equilibrium, lemke, NO_MOTION_PROOF)
    if proof.verdict is not PatternVerdict.UNDECIDED:
        return None  # pyramid motions, none of which Newton's method carried to the exact cones
    motions, complete = enumerate_motions(form, dataclasses.replace(options, max_solutions=1))
    if motions and accept(motions[0]) and accept.motion is not None:
        return _found(accept.motion, notes + (("method", f"SCIP search ({count} edges)"), *accept.notes))
    if complete and not motions:
        return _no_motion(problem, options, edges, exact, None, lemke, "no motion found by the complete SCIP search")
    return None if motions else _failed(f"{lemke}; the complete search found no motion within its time limit")


class _Acceptance:
    """Which motion of the fallback's polyhedral laws answers: any (polyhedral friction), or on exact 3-D cones
    one from which Newton's method converges to the exact laws (``motion`` then holds the exact motion)."""

    def __init__(self, problem: Problem, exact: bool) -> None:
        self.problem, self.exact = problem, exact
        self.motion: RawMotion | None = None
        self.notes: tuple[tuple[str, object], ...] = (("exact_cone", _EXACT_FROM_PYRAMID),) if exact else ()

    def __call__(self, motion: RawMotion) -> bool:
        if not self.exact:
            self.motion = RawMotion(motion.q, motion.c)  # a continuum's inner point
            return True
        self.motion = _exact_from(self.problem, motion.q, motion.c)
        return self.motion is not None


def _no_motion(
    problem: Problem, options: Options, edges: np.ndarray, exact: bool, equilibrium: bool | None, lemke: str, proof: str
) -> BackendResult | None:
    """The verdict of a complete search that found no motion: proven ``jammed`` or ``unstable``. On exact cones
    an inscribed pyramid's proof holds for a kinematic jam, or no equilibrium even in the circumscribed pyramid;
    a wedge needs its own proof (:func:`_exact_wedge`); equilibrium too close to call: None (a finer pyramid)."""
    outer = edges / np.cos(np.pi / edges.shape[1]) if exact else None  # circumscribed: no equilibrium there, none in the circle
    verdict = diagnose(problem, edges, outer, equilibrium=equilibrium)
    if exact and verdict.diagnosis is Diagnosis.WEDGED:
        return _exact_wedge(problem, options, lemke)
    if verdict.status == "failed":
        return None  # equilibrium in the circumscribed pyramid, none in the inscribed: a finer one may decide
    return verdict.with_notes(certificate=proof, lemke=lemke)


def _exact_wedge(problem: Problem, options: Options, lemke: str) -> BackendResult:
    """The inscribed pyramid wedges: proven for the exact cones by the sector relaxation (:mod:`.certify.wedge`), or
    a relaxed point from which Newton's method reaches an exact motion (the relaxation then stops), else ``failed``."""
    found: list[RawMotion] = []

    def is_motion(q: np.ndarray) -> bool:
        converged, q_exact, c_exact = exact_newton(problem, q, np.zeros((problem.n_contacts, 3)))
        if converged:
            found.append(RawMotion(q_exact, c_exact))
        return bool(converged)

    proven, sectors, method = exact_cones_jam(problem, options, None, is_motion)
    if proven:
        text = f"no solution of the exact laws relaxed to slip sectors (up to {sectors} per contact; {method})"
        return no_motion(Diagnosis.WEDGED, Certificate(CertificateKind.SECTOR_RELAXATION, text)).with_notes(lemke=lemke)
    if found:
        return _found(found[-1], (("lemke", lemke), ("method", "sector relaxation"), ("exact_cone", _EXACT_FROM_RELAXATION)))
    return _failed(f"{lemke}; the inscribed pyramid wedges, and the exact cones' sector relaxation decided nothing")


def _is_exact(problem: Problem) -> bool:
    """Exact 3-D cones, where Newton's method on the fixed-mode laws checks every law of a motion it returns."""
    return problem.dimension == 3 and not problem.friction.is_polyhedral(3)


def _exact_from(
    problem: Problem, q: np.ndarray, c: np.ndarray, depth: float = 0.0, patience: int = NEWTON_ITERATIONS, one_switch: bool = False
) -> RawMotion | None:
    """The exact laws solved by Newton's method with the contact modes of ``(q, c)`` (any point, no law checked; a
    contact penetrating by at most ``depth`` counts as closed; ``patience`` and ``one_switch`` as
    :func:`.numerics.lcp.exact_newton`), or None where it does not converge with every mode and inequality kept."""
    converged, q_exact, c_exact = exact_newton(problem, q, c, depth, patience, one_switch)
    return RawMotion(q_exact, c_exact) if converged else None


def _from_lemke_end(problem: Problem, q: np.ndarray, c: np.ndarray, notes: tuple[tuple[str, object], ...]) -> BackendResult | None:
    """Exact cones: a motion by Newton's method from where a Lemke path ended (a ray's last point, or a pyramid's
    solution), often near an exact motion that no pyramid's Lemke path reaches; None where it does not converge.

    Three starts, the notes ``newton_patience`` and ``newton_switches`` say which converged. First the point's own
    contact modes, with rounds that switch modes as soon as two iterations stall (:data:`QUICK_PATIENCE`: grasp-3d
    8 #1's motion, and 6 #3's in ~15x fewer evaluations of the laws); every contact that must switch does. Then
    the same, a round switching only the first of them (grasp-3d 8 #0's motion in ~45 evaluations: switching all
    three of its pulling contacts at once leads elsewhere). Then the contacts the path held closed start closed
    (a ray's last point solves the laws with every gap rate raised by the artificial variable, so they penetrate
    by it, :func:`lemke_depth`), with the kernel's full rounds (8 #0's motion too, in ~1,000 evaluations). (With
    the depth first, random scene 7139 got a third motion, audited, that SCIP's list misses; this order keeps the
    earlier one.)"""
    patience, switches = QUICK_PATIENCE, "all"
    motion = _exact_from(problem, q, c, 0.0, patience)
    if motion is None:
        switches = "first"
        motion = _exact_from(problem, q, c, 0.0, patience, one_switch=True)
    if motion is None:  # the depth only where the quick starts failed (8 #0, 8 #1 and 6 #3 never read it)
        patience, switches = NEWTON_ITERATIONS, "all"
        motion = _exact_from(problem, q, c, lemke_depth(problem, q), patience)
    if motion is None:
        return None
    notes += (("exact_cone", _EXACT_FROM_LEMKE_END), ("newton_patience", patience), ("newton_switches", switches))
    return _found(motion, notes)


def _found(motion: RawMotion, notes: tuple[tuple[str, object], ...]) -> BackendResult:
    """The fallback's motion, uncertified as the fast path's are."""
    return BackendResult("solved", _SOLVED, (motion,), certified=False, notes=notes)


def _why_lemke_failed(status: int, stage: int, pivots: int) -> str:
    when = " after re-aligning the pyramid edges" if stage else ""
    return {
        RAY: f"Lemke's method ended on a secondary ray{when} ({pivots} pivots)",
        PIVOT_LIMIT: f"Lemke's method hit its pivot limit{when} ({pivots} pivots)",
        NOT_CONVERGED: "the pyramid's motion did not converge to one of the exact cones "
        "(edge re-alignment, then Newton's method with its contact modes)",
    }[status]


def _failed(why: str) -> BackendResult:
    return BackendResult("failed", f"failed: {why} (fast path; the certified method can decide)", certified=False)
