"""Method ``certified``: the certified answer of ``scip``, with cheap certificates tried first.

1. Lemke's method finds a motion in microseconds (:mod:`.certify.cheap`).
2. When the contacts' non-penetration alone leaves one twist (proven by a
   bound, :func:`~.certify.cheap.kinematically_unique`), that motion is the
   only one: ``solved``, for any friction model, exact 3-D cones included.
   On exact 3-D cones, rest with every mover still is proven the only motion
   on the circles themselves when it is (:mod:`.certify.rest`: the load cannot
   do work, so loaded contacts stick, and LPs or else SCIP find no other such motion).
3. One planar body: the vertices and edges of the contacts' gap-rate and slip planes
   (:mod:`.certify.arrangement`, whole-array 3x3 solves and checked Farkas directions)
   prove Lemke's (or a vertex's) twist the only motion, or that none exists (then
   ``jammed``/``unstable`` by :func:`~.certify.diagnose.diagnose`, told when a vertex
   keeps every contact open), or list every motion when they are isolated twists
   (``ambiguous``), for most problems; where it proves nothing, step 4.
4. Planar and 3-D pyramid problems: a branch and bound over each contact's mode
   (separating, rolling, sliding either way in 2-D; on a pyramid's vertex or
   face in 3-D), whose nodes are pruned by checked Farkas
   vectors (no forces balance the load), singular-value bounds on the twists
   the closed contacts leave, and LP statuses (:mod:`.certify.patterns`), proves
   that every motion has Lemke's twist (``solved``), or, without a Lemke point,
   that no motion exists (then ``jammed``/``unstable`` as the search would say,
   :func:`~.certify.diagnose.diagnose`), or lists every motion (``ambiguous``:
   each pattern that holds one gives a single twist or a continuum, its
   extremes measured by LPs). It needs no SCIP; where a pattern is too close
   to call, or past its node budget or ``max_solutions``, it proves nothing
   and step 5 runs. On exact 3-D cones the same proof replaces the SCIP search
   on the inscribed 8-edge pyramid wherever it decides (:mod:`.certify.exact_cone`).
5. Otherwise the complete SCIP search of ``scip`` runs. For polyhedral cones
   it starts from Lemke's point once every law of the search's own form is
   checked there, so SCIP only has to prove that no other motion exists
   (measured 10-20 % faster on 2-D grasps). The 8-edge pyramid search of exact
   3-D cones is not seeded: measured, its proof then took 1.4x longer.

Everything not proven by steps 2-4 is decided by the same search as ``scip``, so
the answers are the same; prescribed modes go straight to it.
"""

from __future__ import annotations

from ..laws import Problem, RawMotion
from ..laws.polyhedral import aligned_edges, polyhedral_form
from .certify.arrangement import NO_VERTEX_PROOF, VERTEX_LISTING_PROOF, VERTEX_PROOF, VertexVerdict, prove_by_vertices
from .certify.cheap import exact_motion, kinematically_unique, seed_point
from .certify.diagnose import diagnose
from .certify.exact_cone import solve_exact_3d, unique_exact_motion
from .certify.patterns import ENUMERATION_PROOF, NO_MOTION_PROOF, PATTERN_PROOF, PatternVerdict, prove_by_patterns
from .certify.rest import rest_proof
from .certify.search import certified_polyhedral, summarise
from .result import BackendResult, Options

__all__ = ["solve_cheap_certified"]

_KINEMATIC = "non-penetration alone leaves one twist (Gordan multipliers bound every admissible twist)"


def solve_cheap_certified(problem: Problem, options: Options) -> BackendResult:
    """The certified answer (as ``scip``): every motion, or a proof that there is none, within ``options.time_limit``."""
    options = options.start_clock()
    if not problem.friction.is_polyhedral(problem.dimension):
        return _exact_cones(problem, options)
    edges = aligned_edges(problem, problem.friction.edges)
    if options.modes is not None:
        return certified_polyhedral(problem, edges, options)
    form = polyhedral_form(problem, edges)
    seed = seed_point(form)
    if seed is not None and kinematically_unique(problem, seed[: form.n_q]):
        motion = RawMotion(seed[: form.n_q], form.forces(seed))
        return summarise(form, [motion], True, options).with_notes(certificate=_KINEMATIC)
    vertices = prove_by_vertices(form, seed, options.max_solutions)
    if vertices.verdict is VertexVerdict.UNIQUE and vertices.seed is not None:
        motion = RawMotion(vertices.seed[: form.n_q], form.forces(vertices.seed))
        return summarise(form, [motion], True, options).with_notes(certificate=VERTEX_PROOF)
    if vertices.verdict is VertexVerdict.ENUMERATED:
        options.report(len(vertices.motions), 0)  # as the SCIP search reports its steps
        motions = [RawMotion(x[: form.n_q], form.forces(x)) for x in vertices.motions]
        return summarise(form, motions, True, options).with_notes(certificate=VERTEX_LISTING_PROOF)
    if vertices.verdict is VertexVerdict.NONE:
        return diagnose(problem, edges, equilibrium=vertices.equilibrium, admissible=vertices.admissible).with_notes(
            certificate=NO_VERTEX_PROOF
        )
    proof = prove_by_patterns(form, seed, options.max_solutions, options.remaining)
    if proof.verdict is PatternVerdict.UNIQUE and proof.seed is not None:
        motion = RawMotion(proof.seed[: form.n_q], form.forces(proof.seed))
        return summarise(form, [motion], True, options).with_notes(certificate=PATTERN_PROOF)
    if proof.verdict is PatternVerdict.ENUMERATED:
        options.report(len(proof.motions), proof.nodes)  # as the SCIP search reports its steps
        return summarise(form, list(proof.motions), True, options).with_notes(certificate=ENUMERATION_PROOF)
    if proof.verdict is PatternVerdict.NONE:
        return diagnose(problem, edges, equilibrium=proof.equilibrium).with_notes(certificate=NO_MOTION_PROOF)
    return certified_polyhedral(problem, edges, options, seed)


def _exact_cones(problem: Problem, options: Options) -> BackendResult:
    """Exact 3-D cones: a kinematically unique exact motion is certified; otherwise the pyramid search of ``scip``."""
    if options.modes is not None:
        return solve_exact_3d(problem, options, by_patterns=True)
    motion = exact_motion(problem)
    if motion is not None and kinematically_unique(problem, motion.q):
        return unique_exact_motion(problem, motion, options, _KINEMATIC)
    proof = None if motion is None else rest_proof(problem, motion.q, options)
    if motion is not None and proof is not None:
        return unique_exact_motion(problem, motion, options, proof)
    return solve_exact_3d(problem, options, by_patterns=True)
