"""The paper's own program: Trinkle & Hunter's minimum-power problem, solved to global optimality by SCIP.

Method ``paper`` (:mod:`quasistatic.solvers.paper`) is this program; the
exact-cone search also calls it to confirm a wedge it cannot prove otherwise.

The paper minimises the power ``P_zc`` of the non-constraint forces (load and
friction, eq. 6) over the object twist, subject to non-penetration (7), the
friction cones (10) and friction opposing slip (23), (24). Read literally, the
normal forces in (10) are free variables of that program: nothing ties the
friction magnitude to the load, so with fixed movers the minimum puts every
friction force to zero and returns the frictionless motion (a block resting on
a 20 degree slope with mu = 0.5 runs downhill). The paper closes the program through
its dual: the normal forces are the multipliers of (7) (``lambda = c_a``), the
dual constraints (13), (17) hold at the optimum, and there the power balance
(19) ``P_c <= P_zc`` is an equality. This module solves that closure as one
program, in scene-relative units (``u_i = J_i q - b_i``, frames: tangents
then normal)::

    minimise   P_zc - P_c = -g.q + sum_i mu_i c_n,i s_i - sum_i c_i.b_i      eq. (6) minus eq. (12)
    over       q (n_dof), c (m, d), s (m)
    subject to Jn q >= bn                                  (7)  non-penetration
               sum_i J_i^T c_i + g = 0                      (13) equilibrium, c_n = lambda
               ||c_t,i|| <= mu_i c_n,i,  c_n,i >= 0         (8)-(10), (17)
               s_i >= ||Jt_i q - bt_i||                     slip speed

``mu_i c_n,i s_i`` is the friction dissipation of (6) with the friction forces
of (10), (23), (24) at their maximum-dissipation value: bilinear in the unknown
normal force and the twist, so the program is nonconvex. ``P_c`` is the power
the movers put in through the contact forces (eq. 12; with a tangentially
moving mover also through friction, as in the audit's power balance). By
equilibrium the objective equals ``sum c_n u_n + sum (mu c_n ||u_t|| + c_t.u_t)
>= 0`` (weak duality, eq. 19): zero exactly where complementarity and maximum
dissipation hold. The global minimum 0 is therefore the paper's prediction,
and any point of positive value "defies conservation of energy" (the paper,
after eq. 19). ``P_c <= P_zc`` is added as the bound ``T >= 0`` on the
objective's epigraph variable ``T``, so a point of value 0 is proven globally
optimal the moment it is found. The cone is the paper's exact one (eq. 8);
``pyramid:K`` is refused.

SCIP meets constraints to 1e-7; the twist it returns is then polished by
Newton's method on the laws with its contact modes fixed, and the forces are
recovered at the polished twist (the least total normal force among those
that satisfy the laws there: in a statically indeterminate grasp the
program's own forces are any of many).

SCIP status to ours:

==================  ============================================  ===========
SCIP status         condition                                     ours
==================  ============================================  ===========
any                 a point with ``T <= POWER_GAP`` was found       ``solved``
``optimal``,        min ``T > POWER_GAP`` proven                   ``jammed`` (wedged)
``duallimit``
``infeasible``      Farkas certificate that (7) is infeasible     ``jammed``
``infeasible``      no force in the cones balances the load       ``unstable``
``infeasible``      neither (infeasible only within the bounds)   ``failed``
other               (time/node limit, interrupted, ...)           ``failed``
==================  ============================================  ===========

The paper's "unbounded power" is, by duality, the infeasibility of (13), (17),
which is checked directly: every variable here is bounded, so SCIP itself never
reports ``unbounded``. The bounds (``TWIST_BOUND``, ``FORCE_BOUND``) are 1000
times the scene's scales (movers' speeds and loads are at most 1). They do not
limit ``solved`` (a point of gap 0 is a global minimum whatever the bounds),
but a ``solved`` twist or force at its bound is ``failed`` (the minimisers run
on beyond it). A wedged ``jammed`` is proven within the bounds: no motion needs
less than 1000 times the scene's speeds and loads. There the infimum of the
gap is typically approached at the force bound (jamming is "no motion with
finite forces"), so a bound being approached is no reason to doubt it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...laws import ModeMasks, Problem, RawMotion
from ...laws.fixed_modes import FixedModeLaws
from ...solution import Certificate, CertificateKind, Diagnosis
from ...tolerances import LEAST_SQUARES_STEP, MODE_SPEED, POLISHED_RESIDUAL, POWER_GAP, RECOVERED_POWER_GAP
from ..numerics.optimize import least_squares
from ..numerics.scip_model import new_model, optimize
from ..result import BackendResult, Options
from .diagnose import kinematic_certificate, no_motion

__all__ = ["solve_min_power", "TWIST_BOUND", "FORCE_BOUND"]

TWIST_BOUND = 1e3  # |q_j| <= this (scene-relative: 1000 times the fastest mover)
FORCE_BOUND = 1e3  # c_n <= this (scene-relative: 1000 times the largest load)
_ACTIVE = 0.999  # a value beyond this fraction of its bound counts as at the bound
POLISH_MAX = 500  # most unknowns polished by Newton's method
_FORMULATION = "Trinkle & Hunter eq. 6, 7, 10, 23, 24 with the dual's equilibrium (13), (17); minimises P_zc - P_c of eq. 19"


@dataclass
class _Model:
    scip: Any
    q: list[Any]
    c: list[list[Any]]  # per contact: tangential entries, then normal
    gap: Any  # epigraph variable T of P_zc - P_c


def solve_min_power(problem: Problem, options: Options) -> BackendResult:
    """Solve the paper's minimum-power program to global optimality, on the clock of ``options``.

    Returns
    -------
    BackendResult
        ``solved`` with one motion (a global minimiser; uniqueness is not
        checked, so not certified), or ``jammed``, ``unstable`` (certified), ``failed``.
    """
    model = _build(problem, options.remaining())
    model.scip.setParam("limits/primal", POWER_GAP)  # stop at a point of gap 0: a global minimum by eq. 19
    model.scip.setParam("limits/dual", POWER_GAP)  # stop once the minimum is proven positive: no motion
    status = _optimize(model)
    notes: dict[str, Any] = {"formulation": _FORMULATION, "scip_status": status}
    if model.scip.getNSols() > 0:
        q, gap = _best(model)
        if gap <= POWER_GAP:
            return _solved(problem, options, model, q, notes)
    if status in ("optimal", "duallimit") and model.scip.getDualbound() > POWER_GAP / 2:
        return _wedged(model).with_notes(**notes)
    if status == "infeasible":
        return _infeasible(problem, options.remaining()).with_notes(**notes)
    message = f"failed: SCIP stopped with status {status!r} before proving a global minimum"
    return BackendResult("failed", message, certified=False).with_notes(**notes)


def _solved(problem: Problem, options: Options, model: _Model, q: np.ndarray, notes: dict[str, Any]) -> BackendResult:
    """Global minimum 0: the twist is the paper's prediction; the forces are the least normal ones at it."""
    if np.max(np.abs(q), initial=0.0) >= _ACTIVE * TWIST_BOUND:
        message = f"failed: the minimiser found has a twist entry at its bound {TWIST_BOUND:g}, so the minimisers run on beyond it"
        message += " (an unbounded continuum of motions? method 'scip' lists them)"
        return BackendResult("failed", message, certified=False).with_notes(**notes)
    best = model.scip.getBestSol()
    refined = _refine(problem, q, np.array([[model.scip.getSolVal(best, v) for v in c_i] for c_i in model.c]))
    c = None
    for twist in ([] if refined is None else [refined]) + [q]:
        recovered = _forces_at(problem, twist, options.remaining())
        if recovered is not None:
            c, notes["power_gap"] = recovered
            notes["polished"] = twist is refined
            q = twist
            break
    if c is None:
        return BackendResult("failed", "failed: no contact forces satisfy the laws at the minimiser's twist", certified=False).with_notes(
            **notes
        )
    if np.max(c[:, -1], initial=0.0) >= _ACTIVE * FORCE_BOUND:
        message = f"failed: the minimiser needs a normal force at its bound {FORCE_BOUND:g}"
        return BackendResult("failed", message, certified=False).with_notes(**notes)
    notes["uniqueness"] = "not checked: one global minimiser is returned; method 'scip' lists every motion"
    notes["forces"] = "least total normal force among the forces consistent with the twist"
    message = "solved: the paper's global minimum-power prediction (P_zc = P_c, eq. 19)"
    return BackendResult("solved", message, (RawMotion(q, c),), certified=False).with_notes(**notes)


def _refine(problem: Problem, q: np.ndarray, c: np.ndarray) -> np.ndarray | None:
    """Newton (trust-region least squares) on the fixed-mode laws with the contact modes of SCIP's point.

    SCIP meets each constraint to 1e-7; in an ill-conditioned scene that moves
    the twist much more. With the modes fixed the laws are smooth equations
    (:mod:`quasistatic.laws.fixed_modes`). Returns None unless they are met to
    ``POLISHED_RESIDUAL``, or when there are more than ``POLISH_MAX`` unknowns
    (a 1000-box pile); the caller then checks SCIP's own twist against the laws.
    """
    u = problem.velocities(q)
    tol = MODE_SPEED * max(1.0, float(np.max(np.abs(q), initial=0.0)))
    loaded = c[:, -1] > MODE_SPEED
    closed = (u[:, -1] <= tol) | loaded
    rubbing = closed & (problem.mu > 0)
    inside = np.linalg.norm(c[:, :-1], axis=1) < problem.mu * c[:, -1] - MODE_SPEED  # force off the cone: no slip
    rolling = rubbing & ((np.linalg.norm(u[:, :-1], axis=1) <= tol) | inside)
    laws = FixedModeLaws(problem, ModeMasks(closed, rolling, rubbing & ~rolling))
    if laws.size > POLISH_MAX:
        return None
    x0 = laws.start(q, c, nonnegative=False)
    fit = least_squares(
        laws.residual,
        x0,
        jac=laws.jacobian,
        xtol=LEAST_SQUARES_STEP,
        ftol=LEAST_SQUARES_STEP,
        gtol=LEAST_SQUARES_STEP,
        max_nfev=100 * x0.size,
    )
    return laws.motion(fit.x)[0] if np.max(np.abs(laws.residual(fit.x)), initial=0.0) <= POLISHED_RESIDUAL else None


def _wedged(model: _Model) -> BackendResult:
    """A positive global minimum: no twist and balanced forces conserve power, so no motion exists."""
    lower = model.scip.getDualbound()
    text = f"P_zc - P_c >= {lower:.3g} > 0 (SCIP) for every |q| <= {TWIST_BOUND:g}, c_n <= {FORCE_BOUND:g}"
    return no_motion(Diagnosis.WEDGED, Certificate(CertificateKind.GLOBAL_OPTIMUM, text))


def _infeasible(problem: Problem, time_limit: float) -> BackendResult:
    """No feasible point: (7) has no solution (jammed) or (13), (17) have none (unstable)."""
    multipliers = kinematic_certificate(problem)
    if multipliers is not None:
        text = "kinematic (Farkas multipliers): no twist satisfies (7)"
        return no_motion(Diagnosis.KINEMATIC, Certificate(CertificateKind.FARKAS, text, tuple(multipliers.tolist())))
    scip = _new_model(time_limit)
    _add_forces(scip, problem, None)
    if optimize(scip, "paper") == "infeasible":
        text = "no forces in the friction cones satisfy (13), (17): the power (6) is unbounded below"
        return no_motion(Diagnosis.NO_EQUILIBRIUM, Certificate(CertificateKind.INFEASIBLE_EQUILIBRIUM, text))
    return BackendResult("failed", "failed: the program is infeasible only within its variable bounds")


def _forces_at(problem: Problem, q: np.ndarray, time_limit: float) -> tuple[np.ndarray, float] | None:
    """:func:`_recovered_forces` with each sliding contact's friction exactly ``-mu cn slip/|slip|``, else without that."""
    return _recovered_forces(problem, q, time_limit, exact_sliding=True) or _recovered_forces(problem, q, time_limit, exact_sliding=False)


def _recovered_forces(problem: Problem, q: np.ndarray, time_limit: float, exact_sliding: bool) -> tuple[np.ndarray, float] | None:
    """Forces (m, d) meeting the laws at twist ``q`` and their power gap; None if the laws fail.

    With q fixed the power gap ``sum c_n u_n + sum (mu c_n ||u_t|| + c_t.u_t)``
    is linear in c and each term is >= 0 inside the cones, so two convex
    solves suffice: the least gap (it must be at most ``RECOVERED_POWER_GAP``: the
    twist carries SCIP's tolerance), then the least total normal force
    within that gap. With ``exact_sliding``, a sliding contact's friction is
    pinned to ``-mu cn slip/|slip|`` (maximum dissipation to the letter, not
    only to the gap's tolerance). The cones are the exact (second-order) ones of eq. 8,
    not the polygons of :mod:`..numerics.forces`: this program is the
    independent cross-check of the certified search, so it does not share
    its polyhedral force code.
    """
    import pyscipopt

    u = problem.velocities(q)
    if np.min(u[:, -1], initial=0.0) < -RECOVERED_POWER_GAP:  # the twist violates (7)
        return None
    least = 0.0
    for stage in ("gap", "force"):
        scip = _new_model(time_limit)
        c = _add_forces(scip, problem, FORCE_BOUND)
        terms = []
        for i, c_i in enumerate(c):
            speed = float(np.linalg.norm(u[i, :-1]))
            if exact_sliding and problem.mu[i] > 0 and speed > MODE_SPEED:
                for k in range(problem.dimension - 1):
                    scip.addCons(c_i[k] == -float(problem.mu[i] * u[i, k] / speed) * c_i[-1])
            terms.append((max(u[i, -1], 0.0) + problem.mu[i] * speed) * c_i[-1])
            terms += [float(u[i, k]) * c_i[k] for k in range(problem.dimension - 1) if problem.mu[i] > 0]
        gap = pyscipopt.quicksum(terms)
        if stage == "gap":
            scip.setObjective(gap, "minimize")
        else:
            scip.addCons(gap <= max(least, 0.0) + 0.1 * RECOVERED_POWER_GAP)
            scip.setObjective(pyscipopt.quicksum(c_i[-1] for c_i in c), "minimize")
        if optimize(scip, "paper") != "optimal":
            return None
        if stage == "gap":
            least = scip.getObjVal()
            if least > RECOVERED_POWER_GAP:
                return None
    best = scip.getBestSol()
    return np.array([[scip.getSolVal(best, v) for v in c_i] for c_i in c]), least


def _new_model(time_limit: float) -> Any:
    import pyscipopt

    scip = new_model(time_limit)
    scip.setParam("limits/absgap", POWER_GAP / 10)
    scip.setHeuristics(pyscipopt.SCIP_PARAMSETTING.FAST)  # the default NLP multistart costs ~1 s a solve and rarely helps here
    return scip


def _build(problem: Problem, time_limit: float) -> _Model:
    """The program above as a SCIP model."""
    import pyscipopt

    scip = _new_model(time_limit)
    c = _add_forces(scip, problem, FORCE_BOUND)
    q = [scip.addVar(lb=-TWIST_BOUND, ub=TWIST_BOUND) for _ in range(problem.n_dof)]
    dissipation = []
    for i in range(problem.n_contacts):
        u = [_affine(problem.J[i, k], q) - float(problem.b[i, k]) for k in range(problem.dimension)]
        scip.addCons(u[-1] >= 0.0)  # (7)
        if problem.mu[i] > 0:
            # the largest slip speed with |q| <= TWIST_BOUND (triangle inequality)
            s = scip.addVar(lb=0.0, ub=float(TWIST_BOUND * np.abs(problem.Jt[i]).sum() + np.abs(problem.bt[i]).sum()))
            _norm_at_most(scip, u[:-1], s)
            power = scip.addVar(lb=0.0, ub=None)  # >= 0: a load a hair below zero times a large s cannot lower the gap
            scip.addCons(power >= float(problem.mu[i]) * c[i][-1] * s)
            dissipation.append(power)
    supplied = pyscipopt.quicksum(float(problem.b[i, k]) * c[i][k] for i, k in zip(*np.nonzero(problem.b), strict=True))
    gap = scip.addVar(lb=0.0, ub=None)  # P_c <= P_zc (eq. 19) as the bound T >= 0
    scip.addCons(gap >= -_affine(problem.g, q) + pyscipopt.quicksum(dissipation) - supplied)
    scip.setObjective(gap, "minimize")
    return _Model(scip, q, c, gap)


def _add_forces(scip: Any, problem: Problem, bound: float | None) -> list[list[Any]]:
    """Force variables (normal ones in ``[0, bound]``), their cones (10) and equilibrium (13)."""
    import pyscipopt

    m, d, n = problem.J.shape
    c = []
    for i in range(m):
        mu = float(problem.mu[i])
        t_bound = 0.0 if mu == 0 else None if bound is None else mu * bound
        c_i = [scip.addVar(lb=None if t_bound is None else -t_bound, ub=t_bound) for _ in range(d - 1)]
        c_i.append(scip.addVar(lb=0.0, ub=bound))
        c.append(c_i)
        if mu > 0:
            _norm_at_most(scip, c_i[:-1], mu * c_i[-1])  # (8), (10)
    for j in range(n):  # (13): sum_i J_i^T c_i = -g
        rows = zip(*np.nonzero(problem.J[:, :, j]), strict=True)
        scip.addCons(pyscipopt.quicksum(float(problem.J[i, k, j]) * c[i][k] for i, k in rows) == -float(problem.g[j]))
    return c


def _norm_at_most(scip: Any, x: list[Any], bound: Any) -> None:
    """``||x|| <= bound`` for 1 or 2 affine entries (3-D: in norm form, accurate near the apex)."""
    import pyscipopt

    if len(x) == 1:
        scip.addCons(x[0] <= bound)
        scip.addCons(-x[0] <= bound)
    else:
        v = [scip.addVar(lb=None, ub=None) for _ in x]
        for v_k, x_k in zip(v, x, strict=True):
            scip.addCons(v_k == x_k)
        scip.addCons(pyscipopt.sqrt(v[0] * v[0] + v[1] * v[1]) <= bound)


def _affine(row: np.ndarray, x: list[Any]) -> Any:
    import pyscipopt

    return pyscipopt.quicksum(float(a) * v for a, v in zip(row, x, strict=True) if a) + 0.0


def _optimize(model: _Model) -> str:
    return optimize(model.scip, "paper")


def _best(model: _Model) -> tuple[np.ndarray, float]:
    """Twist and power gap of SCIP's best point."""
    best = model.scip.getBestSol()
    return np.array([model.scip.getSolVal(best, v) for v in model.q]), float(model.scip.getSolVal(best, model.gap))
