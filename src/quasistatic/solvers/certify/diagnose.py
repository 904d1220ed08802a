"""Certified verdicts when no motion exists: ``jammed`` or ``unstable``, in that order.

1. No twist keeps every contact closed or opening for the commanded mover
   motion (``Jn q >= bn`` infeasible): jammed, with a Farkas certificate.
2. No force distribution inside the friction cones balances the load:
   unstable (no quasi-static equilibrium even with the movers stopped).
3. Otherwise the commanded motion wedges the parts: jammed.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from ...laws import Problem
from ...laws.polyhedral import edge_jacobian, force_polytope
from ...solution import Certificate, CertificateKind, Diagnosis, Later, Status
from ...tolerances import KINEMATIC_MULTIPLIERS, LP_FEASIBILITY
from ..numerics.highs import solve_lp
from ..result import BackendResult

__all__ = [
    "diagnose",
    "admits_no_multipliers",
    "equilibrium_exists",
    "fall_certificate",
    "kinematic_certificate",
    "MESSAGES",
    "no_equilibrium_certificate",
    "no_motion",
]

MESSAGES = {
    Diagnosis.KINEMATIC: (
        "jammed: no motion of the free bodies is compatible with the commanded mover motion "
        "(the movers would have to penetrate them); change the commanded motion"
    ),
    Diagnosis.WEDGED: (
        "jammed: the parts could be held at rest, but friction wedges them against the commanded "
        "motion (no solution with finite forces); change the commanded motion or reduce friction"
    ),
    Diagnosis.PRESCRIBED_MODES: "jammed: no motion exists with the prescribed contact modes",
    Diagnosis.NO_EQUILIBRIUM: (
        "unstable: no quasi-static equilibrium exists within the friction cones, so the object "
        "falls, slides or accelerates; add support or friction"
    ),
}
"""The message of each diagnosis (one sentence a person can act on)."""


NO_EQUILIBRIUM_TEXT = "no equilibrium in the friction cones (LP infeasible)"


def no_motion(diagnosis: Diagnosis, certificate: Certificate) -> BackendResult:
    """The certified verdict for a proven diagnosis."""
    status: Status = "unstable" if diagnosis is Diagnosis.NO_EQUILIBRIUM else "jammed"
    return BackendResult(status, MESSAGES[diagnosis], diagnosis=diagnosis, certificate=certificate)


def kinematic_certificate(problem: Problem) -> np.ndarray | None:
    """Multipliers y >= 0 with Jn^T y = 0, bn.y = 1 (proof of infeasibility), or None.

    Accepted when they meet every row and ``y >= 0`` to ``LP_FEASIBILITY`` with ``|y|_1`` at most
    ``KINEMATIC_MULTIPLIERS``: larger ones only say that every twist misses a gap row by round-off."""
    Jn, bn = problem.Jn, problem.bn
    m, n = Jn.shape
    A = np.vstack([Jn.T, bn[None, :]])
    rhs = np.r_[np.zeros(n), 1.0]
    lp = solve_lp(np.zeros(m), A, rhs, rhs, np.zeros(m))
    if lp.status != "optimal" or np.max(np.abs(A @ lp.x - rhs), initial=0.0) > LP_FEASIBILITY:
        return None
    if np.min(lp.x, initial=0.0) < -LP_FEASIBILITY or np.abs(lp.x).sum() > KINEMATIC_MULTIPLIERS:
        return None
    return lp.x


def admits_no_multipliers(gaps: np.ndarray, q: np.ndarray, error: np.ndarray | float = 0.0) -> bool:
    """Whether a twist ``q`` whose gap rates ``Jn q - bn`` lie within ``error`` of ``gaps`` rules out every kinematic
    certificate :func:`kinematic_certificate` accepts.

    Such ``y`` has ``y >= -LP_FEASIBILITY``, ``|y|_1 <= KINEMATIC_MULTIPLIERS``, ``|Jn^T y| <= LP_FEASIBILITY`` and
    ``bn.y >= 1 - LP_FEASIBILITY``. With ``hi = max(gaps + error, 0)`` and ``lo`` the largest ``error - gaps`` (how far
    below 0 a gap rate may be), ``y.(Jn q - bn) >= -LP_FEASIBILITY sum(hi) - KINEMATIC_MULTIPLIERS lo``, while it
    equals ``(Jn^T y).q - bn.y <= LP_FEASIBILITY (|q|_1 + 1) - 1``: impossible while ``LP_FEASIBILITY (|q|_1 + sum(hi)
    + 1) + KINEMATIC_MULTIPLIERS lo < 1`` (asked here with a factor 2 to spare)."""
    hi = np.maximum(gaps + error, 0.0)
    lo = max(float(np.max(error - gaps, initial=0.0)), 0.0)
    return bool(LP_FEASIBILITY * (np.abs(q).sum() + hi.sum() + 1.0) + KINEMATIC_MULTIPLIERS * lo < 0.5)


def equilibrium_exists(problem: Problem, edges: np.ndarray) -> bool:
    """True when some forces in the (polyhedral) cones spanned by ``edges`` balance the load."""
    polytope = force_polytope(problem, edges)
    cols = polytope.A.shape[1]
    lp = solve_lp(np.zeros(cols), polytope.A, polytope.rhs, polytope.rhs, np.zeros(cols))
    return lp.status == "optimal"


def no_equilibrium_certificate(problem: Problem, edges: np.ndarray, text: str = NO_EQUILIBRIUM_TEXT) -> Certificate:
    """:func:`fall_certificate`, its LP run when the certificate's text or data is first read.

    The ``unstable`` verdict never rests on it: every caller has proven first that no equilibrium exists (an LP,
    or the planar branch and bound's checked Farkas vector). It says which way the bodies fall, which a
    simulation step or a sweep point rarely reads (1-2 ms of a 2-D solve of about as much).
    """
    found = Later(partial(fall_certificate, problem, edges, text))
    return Certificate(CertificateKind.INFEASIBLE_EQUILIBRIUM, Later(partial(_text, found)), Later(partial(_data, found)))


def _text(found: Later[Certificate]) -> str:
    return found.value().text


def _data(found: Later[Certificate]) -> tuple[float, ...]:
    return found.value().data


def fall_certificate(problem: Problem, edges: np.ndarray, text: str = NO_EQUILIBRIUM_TEXT) -> Certificate:
    """Why no force in the cones spanned by ``edges`` balances the load, with the direction of the fall when it checks.

    Farkas: no ``c >= 0`` on the cones' generators ``w`` (each normal plus mu times an edge, in wrench
    space) with ``sum c w = -g`` exactly when some twist ``y`` has ``w . y >= 0`` for every generator and
    ``g . y > 0``: along ``y`` the load does work and no contact force in the cones can take it away. That
    twist (in physical units, largest entry 1) is the certificate's data; a cone that holds the true one
    (the exact 3-D cone inside a circumscribed polygon) proves the same of the true cone.
    """
    generators = _generator_rows(problem, edges)
    m, n = generators.shape
    lp = solve_lp(problem.g, generators, np.zeros(m), np.full(m, np.inf), np.full(n, -1.0), np.full(n, 1.0), maximize=True)
    if lp.status != "optimal" or lp.objective <= LP_FEASIBILITY or np.any(generators @ lp.x < -LP_FEASIBILITY * lp.objective):
        return Certificate(CertificateKind.INFEASIBLE_EQUILIBRIUM, text)
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    physical = lp.x * units
    direction = physical / np.max(np.abs(physical))
    text += "; data: a twist along which the load does work that no force in the cones resists (v, omega of each body, largest entry 1)"
    return Certificate(CertificateKind.INFEASIBLE_EQUILIBRIUM, text, tuple(direction.tolist()))


def _generator_rows(problem: Problem, edges: np.ndarray) -> np.ndarray:
    """Each cone generator's wrench on the bodies as a row (normal, or normal plus mu times each edge), (rows, n)."""
    m, K = edges.shape[:2]
    frictional = (problem.mu > 0.0) & (K > 0)
    rows = [problem.Jn[~frictional]]
    if np.any(frictional):
        edge_rows = edge_jacobian(problem, edges).reshape(m, K, -1)[frictional]
        rows.append((problem.Jn[frictional, None, :] + problem.mu[frictional, None, None] * edge_rows).reshape(-1, problem.n_dof))
    return np.vstack(rows)


def diagnose(
    problem: Problem,
    inner_edges: np.ndarray,
    outer_edges: np.ndarray | None = None,
    equilibrium: bool | None = None,
    admissible: bool = False,
) -> BackendResult:
    """Explain why no motion exists. ``inner_edges`` span cones inside the true ones.

    For the exact 3-D cone pass ``outer_edges`` too (a polygon around the circle):
    no equilibrium with the outer cones proves none with the exact ones. ``equilibrium``: whether
    one exists in the inner cones, when the caller has decided it (the planar branch and bound's
    root: a balancing fit, or a checked Farkas vector); None runs the LP. ``admissible``: the caller
    holds a twist ``q`` whose gap rates ``Jn q - bn`` rule out every multipliers the kinematic check accepts
    (:func:`admits_no_multipliers`: none below round-off); then its LP is not run.
    """
    multipliers = None if admissible else kinematic_certificate(problem)
    if multipliers is not None:
        return no_motion(
            Diagnosis.KINEMATIC, Certificate(CertificateKind.FARKAS, "kinematic (Farkas multipliers)", tuple(multipliers.tolist()))
        )
    if equilibrium_exists(problem, inner_edges) if equilibrium is None else equilibrium:
        text = "equilibrium exists; no motion found by the complete search"
        return no_motion(Diagnosis.WEDGED, Certificate(CertificateKind.COMPLETE_SEARCH, text))
    if outer_edges is None or not equilibrium_exists(problem, outer_edges):
        return no_motion(Diagnosis.NO_EQUILIBRIUM, no_equilibrium_certificate(problem, inner_edges if outer_edges is None else outer_edges))
    return BackendResult(
        "failed",
        "failed: no motion was found, and whether the exact cones admit an equilibrium is too close to call",
    )
