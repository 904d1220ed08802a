"""Method ``certified``: the certified answer of ``scip``, with cheap certificates tried first.

1. Lemke's method finds a motion in microseconds (:mod:`.certify.cheap`).
2. When the contacts' non-penetration alone leaves one twist (proven by a
   bound, :func:`~.certify.cheap.kinematically_unique`), that motion is the
   only one: ``solved``, for any friction model, exact 3-D cones included.
   On exact 3-D cones, rest with every mover still is proven the only motion
   on the circles themselves when it is (:mod:`.certify.rest`: the load cannot
   do work, so loaded contacts stick, and LPs or else SCIP find no other such motion).
3. Otherwise the complete SCIP search of ``scip`` runs. For polyhedral cones
   it starts from Lemke's point once every law of the search's own form is
   checked there, so SCIP only has to prove that no other motion exists
   (measured 10-20 % faster on 2-D grasps). The 8-edge pyramid search of exact
   3-D cones is not seeded: measured, its proof then took 1.4x longer.

Everything not proven by step 2 is decided by the same search as ``scip``, so
the answers are the same; prescribed modes go straight to it.
"""

from __future__ import annotations

from ..laws import Problem, RawMotion
from ..laws.polyhedral import aligned_edges, polyhedral_form
from .certify.cheap import exact_motion, kinematically_unique, seed_point
from .certify.exact_cone import solve_exact_3d, unique_exact_motion
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
    return certified_polyhedral(problem, edges, options, seed)


def _exact_cones(problem: Problem, options: Options) -> BackendResult:
    """Exact 3-D cones: a kinematically unique exact motion is certified; otherwise the pyramid search of ``scip``."""
    if options.modes is not None:
        return solve_exact_3d(problem, options)
    motion = exact_motion(problem)
    if motion is not None and kinematically_unique(problem, motion.q):
        return unique_exact_motion(problem, motion, options, _KINEMATIC)
    proof = None if motion is None else rest_proof(problem, motion.q, options)
    if motion is not None and proof is not None:
        return unique_exact_motion(problem, motion, options, proof)
    return solve_exact_3d(problem, options)
