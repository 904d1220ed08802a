"""Exact circular Coulomb cones in 3-D: a certified pyramid search, then exact refinement.

An inscribed pyramid is exact for rolling contacts (its forces lie inside the
cone) and for a sliding contact whose slip is exactly opposite one of its
edges (the force then lies on the cone, opposite the slip). So: find every
motion with an 8-edge pyramid by the certified search, then refine each one by
solving the exact laws with its contact modes fixed (smooth equations, by a bounded
trust-region least-squares solve from the pyramid motion).

What is proven: ``unstable`` (no equilibrium even in a pyramid circumscribing
the exact cone) and kinematic ``jammed`` (a Farkas certificate). The list of
motions is complete for the pyramid; each reported motion satisfies the exact
laws (the audit checks it), but motions of the exact cone that the pyramid
misses are not excluded by proof, and the details say so.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.optimize

from ..evaluate import MODE_TOLERANCE, RawMotion
from ..problem import Problem
from .base import BackendResult, Options, contact_modes
from .diagnose import UNSTABLE, diagnose, equilibrium_exists
from .polyhedral import aligned_edges, polyhedral_form
from .scip import enumerate_motions, summarise

__all__ = ["solve_exact_3d"]

EDGES = 8
FINER_EDGES = (32, 256)  # polygons tried when 8 edges cannot decide between unstable and at rest
SEARCH_EDGES = 32  # the most edges the mixed-integer search is run with (its size grows with them)
RANGE_EDGES = 64  # polygon used for force ranges at rolling contacts (inner, within 0.12 %)
DISSIPATION_TOL = 1e-8  # scene-relative force misalignment accepted as exact


def solve_exact_3d(problem: Problem, options: Options) -> BackendResult:
    """Certified pyramid search, then exact-cone refinement of every motion found."""
    result = _search(problem, options, EDGES)
    for count in FINER_EDGES:
        if result is not None:
            return result
        result = _finer(problem, options, count)
    return result or BackendResult(
        "failed",
        f"failed: no motion was found, and whether the exact cones admit an equilibrium is too close to call "
        f"(undecided with {FINER_EDGES[-1]}-edge polygons inside and outside the circle, searched with {SEARCH_EDGES})",
    )


def _search(problem: Problem, options: Options, count: int) -> BackendResult | None:
    """Motions of a ``count``-edge pyramid refined to the exact cone; None when undecided."""
    edges = aligned_edges(problem, count)
    motions, complete = enumerate_motions(polyhedral_form(problem, edges), options)
    if not motions:
        if not complete:
            return BackendResult("failed", "failed: the certified search hit its time limit before finding a motion")
        verdict = diagnose(problem, edges, edges / np.cos(np.pi / count))
        return None if verdict.status == "failed" else verdict
    return _refined_result(problem, motions, complete, options, count)


def _finer(problem: Problem, options: Options, count: int) -> BackendResult | None:
    """Decide with ``count``-edge polygons: no equilibrium outside proves unstable; one inside calls for a finer search."""
    edges = aligned_edges(problem, count)
    if not equilibrium_exists(problem, edges / np.cos(np.pi / count)):
        certificate = f"no equilibrium in {count}-edge pyramids around the exact cones"
        return BackendResult("unstable", UNSTABLE, details={"certificate": certificate})
    if equilibrium_exists(problem, edges) and count <= SEARCH_EDGES:
        return _search(problem, options, count)
    return None


def _refined_result(problem: Problem, motions: list[RawMotion], complete: bool, options: Options, count: int) -> BackendResult:
    refined = [_refine(problem, motion) for motion in motions]
    if any(r is None for r in refined):
        return BackendResult("failed", "failed: a motion of the pyramid model did not converge to one of the exact cone")
    unique: list[RawMotion] = []
    for motion in refined:
        if motion is not None and not any(_same_exact(problem, motion, other) for other in unique):
            unique.append(motion)
    range_form = polyhedral_form(problem, aligned_edges(problem, RANGE_EDGES, _slips(problem, unique[0].q)))
    result = summarise(range_form, unique, complete, options)
    details = {**result.details, "exact_cone": f"motions refined from a {count}-edge pyramid; completeness proven for the pyramid"}
    return dataclasses.replace(result, details=details)


def _same_exact(problem: Problem, a: RawMotion, b: RawMotion) -> bool:
    return (
        a.continuum == b.continuum
        and bool(np.max(np.abs(a.q - b.q)) <= 1e-7)
        and contact_modes(problem, a.q) == contact_modes(problem, b.q)
    )


def _slips(problem: Problem, q: np.ndarray) -> np.ndarray:
    return np.einsum("mtn,n->mt", problem.Jt, q) - problem.bt


def _refine(problem: Problem, motion: RawMotion) -> RawMotion | None:
    """Bounded Gauss-Newton (trust region, normal forces >= 0) on the exact laws with the pyramid motion's contact modes.

    With the modes fixed, the exact laws are smooth equations: equilibrium,
    closed contacts do not open, rolling ones do not slip, and a sliding one's
    friction is ``-mu cn slip/|slip|``. Returns None when they have no
    solution near the pyramid motion that keeps every mode and inequality.

    A pyramid continuum is refined from its interior point: the pyramid lets a
    slip turn within a face's fan at no change of force, the circle does not,
    so the exact motion is often unique. It stays a continuum (with the
    pyramid's extremes) only where the exact equations leave a twist direction
    free at the solution (a null vector of their Jacobian with a twist part).
    """
    if not motion.continuum and _max_dissipation_error(problem, motion) <= DISSIPATION_TOL:
        return motion
    modes = np.array(contact_modes(problem, motion.q))
    # A frictionless contact carries only a normal force and may slip freely: no slip equation for it.
    frictional = problem.mu > 0
    closed, rolling, sliding = modes != "separating", (modes == "rolling") & frictional, (modes == "sliding") & frictional
    n, m = problem.n_dof, problem.n_contacts
    n_closed, n_rolling = int(closed.sum()), int(rolling.sum())

    def unpack(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q = x[:n]
        u = np.einsum("mdn,n->md", problem.J, q) - problem.b
        c = np.zeros((m, 3))
        c[closed, 2] = x[n : n + n_closed]
        c[rolling, :2] = x[n + n_closed :].reshape(n_rolling, 2)
        speed = np.linalg.norm(u[sliding, :2], axis=1, keepdims=True)
        c[sliding, :2] = -problem.mu[sliding, None] * c[sliding, 2:3] * u[sliding, :2] / np.maximum(speed, 1e-300)
        return q, u, c

    def residual(x: np.ndarray) -> np.ndarray:
        _, u, c = unpack(x)
        balance = np.einsum("mdn,md->n", problem.J, c) + problem.g
        return np.concatenate([balance, u[closed, 2], u[rolling, :2].ravel()])

    x0 = np.concatenate([motion.q, motion.c[closed, 2], motion.c[rolling, :2].ravel()])
    lower = np.r_[np.full(n, -np.inf), np.zeros(n_closed), np.full(2 * n_rolling, -np.inf)]
    x0[n : n + n_closed] = np.maximum(x0[n : n + n_closed], 0.0)
    fit = scipy.optimize.least_squares(
        residual, x0, bounds=(lower, np.inf), method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200 * x0.size
    )
    q, u, c = unpack(fit.x)
    refined = RawMotion(q, c)
    # A sliding contact may come to rest (its force then sits on the cone): still a solution.
    new_modes = np.array(contact_modes(problem, q))
    same = np.where(frictional, new_modes == modes, (new_modes == "separating") == (modes == "separating"))
    keeps_modes = bool(np.all(same | (sliding & (new_modes == "rolling"))))
    inside = np.all(c[:, 2] >= -1e-12) and np.all(
        np.linalg.norm(c[rolling, :2], axis=1) <= problem.mu[rolling] * c[rolling, 2] + 1e-12
    )
    converged = float(np.max(np.abs(residual(fit.x)), initial=0.0)) <= 1e-10
    if not (converged and keeps_modes and inside):
        return None
    if motion.continuum and _twist_is_free(fit.jac, n):
        return RawMotion(q, c, motion.extremes, motion.unbounded)
    return refined


def _twist_is_free(jacobian: np.ndarray, n_twist: int) -> bool:
    """True when the equations' Jacobian has a null vector that moves the twist (a local continuum)."""
    _, sigma, vt = np.linalg.svd(np.asarray(jacobian), full_matrices=True)
    rank = int(np.sum(sigma > 1e-8 * max(1.0, float(sigma[0]) if sigma.size else 1.0)))
    return bool(np.any(np.linalg.norm(vt[rank:, :n_twist], axis=1) > 1e-6))


def _max_dissipation_error(problem: Problem, motion: RawMotion) -> float:
    """Largest distance of a sliding contact's friction force from -mu cn slip/|slip|."""
    slip = _slips(problem, motion.q)
    worst = 0.0
    for i, s in enumerate(slip):
        speed = float(np.linalg.norm(s))
        if speed > MODE_TOLERANCE:
            target = -problem.mu[i] * motion.c[i, -1] * s / speed
            worst = max(worst, float(np.linalg.norm(motion.c[i, :-1] - target)))
    return worst
