"""Compliant contact forces: of the forces a rigid motion allows, those of least elastic energy.

A statically indeterminate grasp leaves the rigid laws with a whole set of
force distributions consistent with one motion (the seed paper's section 5
names compliance as the remedy). Give the contacts springs (normal stiffness
k_n, tangential k_t) and the robot joints servo stiffness K, and the forces
that actually arise are those that minimise the complementary energy

    1/2 c^T C c,   C = blockdiag(1/k_t, ..., 1/k_n)  +  sum_robots (R J) K^-1 (R J)^T

(contact springs in series with the joints, whose compliance the contact
Jacobians ``J`` map to the contact frames ``R``) over that set: equilibrium,
open contacts unloaded, sliding contacts on their maximum-dissipation friction,
rolling ones in their cones (Menabrea / Castigliano: compatibility of the
deflections is the optimality condition of this program). With polyhedral cones
it is a convex QP (HiGHS); with exact 3-D cones a convex quadratically
constrained program (SCIP).

The least-energy forces are unique when ``C`` is positive definite on every
direction in which the consistent forces can vary (:func:`_resolves`): always
when every loaded contact has a stiffness, and otherwise only if the rigid
contacts' share is already fixed by the springs'. The result is checked by the
caller's audit like every other motion.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..laws import ModeMasks, Problem, contact_modes, slips
from ..laws.polyhedral import aligned_edges
from ..tolerances import COMPLIANCE_RANK, FORCE_RANK, LP_FEASIBILITY
from .numerics.forces import forces_at_twist, measured_forces_at_twist
from .numerics.highs import solve_lp, solve_qp
from .numerics.ranges import null_space
from .numerics.scip_model import linear, new_model, optimize

__all__ = ["CompliantForces", "StepForces", "compliance_matrix", "compliant_forces", "compliant_step"]

_PLANAR_EDGES = 2  # a 2-D cone's two edges; a frictionless 3-D contact's edges carry nothing
_FRICTIONLESS_EDGES = 4


@dataclass(frozen=True)
class CompliantForces:
    """The least-energy forces of one motion, scene-relative, or why there are none.

    Attributes
    ----------
    c : (m, d) or None
        Contact-frame forces (tangent(s), normal) on each ``body``; None when the program failed.
    unique : bool
        The compliance fixes them: no other consistent distribution has the same energy.
    energy : float
        Their complementary energy 1/2 c.C c [scene-relative force x length].
    rigid : tuple of int
        Loaded contacts without a stiffness (they make the forces non-unique when ``unique`` is False).
    reason : str
        Why ``c`` is None (the program's status), else empty.
    """

    c: np.ndarray | None
    unique: bool
    energy: float
    rigid: tuple[int, ...]
    reason: str = ""


def compliance_matrix(problem: Problem) -> np.ndarray:
    """C (m d, m d) in scene-relative units (length scale per force scale), contact frames, contact-major.

    Rigid contacts and joints contribute nothing; joint compliance couples the
    contacts of one robot (a yielding joint moves every contact beyond it).
    """
    scene, scales = problem.scene, problem.scales
    m, d = problem.n_contacts, problem.dimension
    units = scales.force / scales.length  # compliance [length/force] -> scene-relative
    C = np.zeros((m * d, m * d))
    for i, contact in enumerate(scene.contacts):
        if contact.stiffness is not None:
            block = np.full(d, 1.0 / contact.stiffness.tangential)
            block[-1] = 1.0 / contact.stiffness.normal
            C[i * d : (i + 1) * d, i * d : (i + 1) * d] = np.diag(block * units)
    driver = {mover.name: mover.robot for mover in scene.movers}
    for robot in scene.robots:
        if robot.joint_stiffness is None:
            continue
        B = np.zeros((m * d, robot.joint_velocities.size))  # contact-frame deflection per unit joint rotation
        for i, contact in enumerate(scene.contacts):
            if driver.get(contact.other) == robot.name and contact.jacobian is not None:
                B[i * d : (i + 1) * d] = problem.frames[i] @ contact.jacobian
        C += (B / robot.joint_stiffness) @ B.T * units
    return C


def compliant_forces(problem: Problem, q: np.ndarray, time_limit: float) -> CompliantForces:
    """The consistent forces of least elastic energy at the scene-relative twist ``q``."""
    C = compliance_matrix(problem)
    if problem.friction.is_polyhedral(problem.dimension):
        return _polyhedral(problem, q, C)
    return _exact(problem, q, C, time_limit)


def _polyhedral(problem: Problem, q: np.ndarray, C: np.ndarray) -> CompliantForces:
    """HiGHS's QP over the force polytope's columns ``x >= 0``, ``A x = rhs``, forces ``c = M x``."""
    count = problem.friction.edges if problem.friction.kind == "pyramid" else _PLANAR_EDGES
    if problem.dimension == 3 and problem.friction.kind == "none":
        count = _FRICTIONLESS_EDGES
    consistent = measured_forces_at_twist(problem, aligned_edges(problem, count), q)
    forces = consistent.consistent()
    M = forces.M.tocsr()
    hessian = sp.csr_matrix(M.T @ C @ M)
    n = M.shape[1]
    # Normalised to a largest entry of 1: the argmin is the same, and HiGHS's absolute optimality tolerance then
    # means the same whatever the springs' stiffness (a 1e4 N/m beam's entries are 1e-3: 3e-5 off, measured).
    unit = max(float(np.abs(hessian).max()), 1e-300)
    result = solve_qp(hessian / unit, forces.A, forces.rhs, forces.rhs, np.zeros(n), np.full(n, np.inf))
    rigid = _rigid_loaded(problem, ~consistent.fixed[consistent.polytope.normal])
    if result.status != "optimal":
        return CompliantForces(None, False, float("nan"), rigid, f"the QP is {result.status}")
    x = _polished(hessian.toarray() / unit, np.zeros(n), forces.A.toarray(), forces.rhs, result.x)
    free = ~consistent.fixed
    directions = np.asarray(M[:, free] @ null_space(forces.A.toarray()[:, free]))
    c = np.asarray(M @ x).reshape(problem.n_contacts, problem.dimension)
    return CompliantForces(c, _resolves(C, directions), 0.5 * float(x @ (hessian @ x)), rigid)


def _polished(H: np.ndarray, cost: np.ndarray, A: np.ndarray, rhs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """HiGHS's QP point made exact on its active set: the KKT system with the columns at zero held there.

    HiGHS stops within its optimality tolerance (1e-7 relative, measured on the beam); the
    equality-constrained QP on the same active set is one linear solve. Kept only when it stays
    feasible (``x >= 0``); otherwise HiGHS's point stands.
    """
    active = x > LP_FEASIBILITY
    n, rows = int(active.sum()), A.shape[0]
    kkt = np.block([[H[np.ix_(active, active)], A[:, active].T], [A[:, active], np.zeros((rows, rows))]])
    solution = np.linalg.lstsq(kkt, np.r_[-cost[active], rhs], rcond=None)[0]
    polished = np.zeros_like(x)
    polished[active] = solution[:n]
    return polished if np.all(polished >= 0.0) and np.allclose(A @ polished, rhs, atol=LP_FEASIBILITY) else x


def _exact(problem: Problem, q: np.ndarray, C: np.ndarray, time_limit: float) -> CompliantForces:
    """SCIP over the contact-frame forces: rolling contacts in their exact cones (a convex quadratic constraint each)."""
    m, d = problem.n_contacts, problem.dimension
    masks = ModeMasks.of(problem, contact_modes(problem, q))
    E = _equalities(problem, q, masks)
    rigid = _rigid_loaded(problem, masks.closed)
    rhs = np.r_[-problem.g, np.zeros(E.shape[0] - problem.n_dof)]
    unique = _resolves(C, null_space(E))
    inside = _equality_optimum(C, E, rhs, problem, masks)
    if inside is not None:
        return CompliantForces(inside.reshape(m, d), unique, 0.5 * float(inside @ C @ inside), rigid)
    import pyscipopt

    scip = new_model(time_limit)
    c = [scip.addVar(lb=None, ub=None, name=f"c{j}") for j in range(m * d)]
    for i in range(m):
        scip.chgVarLb(c[i * d + d - 1], 0.0)
        if masks.rolling[i]:  # as a norm, so SCIP's feasibility tolerance is in force units, as the audit's
            t1, t2, n = c[i * d : (i + 1) * d]
            scip.addCons(pyscipopt.sqrt(t1 * t1 + t2 * t2) <= float(problem.mu[i]) * n)
    for row, value in zip(E, rhs, strict=True):
        scip.addCons(linear(row, c) == float(value))
    energy = scip.addVar(lb=0.0, ub=None, name="energy")
    unit = max(float(np.abs(C).max()), 1e-300)  # an energy of order 1: SCIP's tolerances are absolute
    scip.addCons(_quadratic(C / unit, c) <= energy)
    scip.setObjective(energy, "minimize")
    status = optimize(scip, "compliance")
    if status != "optimal":
        return CompliantForces(None, False, float("nan"), rigid, f"SCIP's status is {status}")
    values = np.array([scip.getVal(v) for v in c])
    return CompliantForces(values.reshape(m, d), unique, 0.5 * float(values @ C @ values), rigid)


def _equality_optimum(C: np.ndarray, E: np.ndarray, rhs: np.ndarray, problem: Problem, masks: ModeMasks) -> np.ndarray | None:
    """The least-energy forces under the equalities alone, when they also lie in the cones: then the optimum, exactly.

    It minimises over a larger set, so when it is feasible no point of the true set does better
    (the common case: every rolling contact strictly inside its cone). One KKT solve, no SCIP.
    """
    rows = E.shape[0]
    kkt = np.block([[C, E.T], [E, np.zeros((rows, rows))]])
    c = np.linalg.lstsq(kkt, np.r_[np.zeros(C.shape[0]), rhs], rcond=None)[0][: C.shape[0]]
    if not np.allclose(E @ c, rhs, atol=LP_FEASIBILITY):
        return None
    forces = c.reshape(problem.n_contacts, problem.dimension)
    friction = np.linalg.norm(forces[:, :-1], axis=1)
    inside = (forces[:, -1] >= 0.0) & (~masks.rolling | (friction <= problem.mu * forces[:, -1]))
    return c if bool(np.all(inside)) else None


def _equalities(problem: Problem, q: np.ndarray, masks: ModeMasks) -> np.ndarray:
    """The linear equalities on the flattened forces (m d,): equilibrium first (``= -g``), then each ``= 0``.

    Open contacts carry nothing, frictionless ones no friction, and a sliding
    contact's friction is ``-mu cn slip/|slip|`` (Coulomb's maximum dissipation).
    """
    m, d = problem.n_contacts, problem.dimension
    rows = [problem.J.reshape(m * d, -1).T]
    slip = slips(problem, q)
    for i in range(m):
        fixed = np.zeros((0, m * d))
        if not masks.closed[i]:
            fixed = np.eye(m * d)[i * d : (i + 1) * d]
        elif masks.sliding[i]:
            direction = slip[i] / np.linalg.norm(slip[i])
            fixed = np.eye(m * d)[i * d : i * d + d - 1]
            fixed[:, i * d + d - 1] = problem.mu[i] * direction
        elif not masks.rolling[i]:  # closed and frictionless
            fixed = np.eye(m * d)[i * d : i * d + d - 1]
        rows.append(fixed)
    return np.vstack(rows)


def _quadratic(C: np.ndarray, c: list[Any]) -> Any:
    """The SCIP expression 1/2 c.C c over C's nonzero entries."""
    import pyscipopt

    rows, cols = np.nonzero(np.triu(C))
    return pyscipopt.quicksum((0.5 if r == k else 1.0) * float(C[r, k]) * c[r] * c[k] for r, k in zip(rows, cols, strict=True)) + 0.0


def _resolves(C: np.ndarray, directions: np.ndarray) -> bool:
    """Whether C is positive definite on the span of ``directions`` (the ways the consistent forces may vary)."""
    if directions.size == 0:
        return True
    u, sigma, _ = np.linalg.svd(directions, full_matrices=False)
    basis = u[:, sigma > FORCE_RANK]
    if basis.shape[1] == 0:
        return True
    largest = float(np.abs(C).max(initial=0.0))
    return largest > 0.0 and float(np.linalg.eigvalsh(basis.T @ C @ basis).min()) > COMPLIANCE_RANK * largest


def _rigid_loaded(problem: Problem, closed: np.ndarray) -> tuple[int, ...]:
    """Closed contacts with no spring of their own (a joint's stiffness alone leaves a contact's friction rigid)."""
    return tuple(i for i, contact in enumerate(problem.scene.contacts) if closed[i] and contact.stiffness is None)


@dataclass(frozen=True)
class StepForces:
    """The compliant step's answer, scene-relative, or why there is none.

    Attributes
    ----------
    c : (m, d) or None
        Contact-frame forces on each ``body``.
    displacement : (k n,) or None
        The bodies' displacements over the step (length-scale units, radians), from the stuck contacts' springs.
    determined : bool
        The loaded contacts fix the displacement (otherwise it is the smallest one that fits).
    reason : str
        Why ``c`` is None, else empty.
    """

    c: np.ndarray | None
    displacement: np.ndarray | None
    determined: bool
    reason: str = ""


def compliant_step(problem: Problem, closing_time: float, time_limit: float) -> StepForces:
    """The forces of least complementary energy when the movers advance for ``closing_time`` [time] against the springs.

    min 1/2 c.C c - h b.c over equilibrium and the friction cones (no modes: the step starts
    unloaded), with ``h b`` each mover's advance at its contacts: Menabrea's theorem with prescribed
    displacements. Its optimality conditions are compatibility, ``J D - h b = -C c``, at every contact
    strictly inside its cone; ``D``, the bodies' displacement, is read back from those contacts.
    """
    C = compliance_matrix(problem)
    advance = (closing_time * problem.scales.velocity / problem.scales.length) * problem.b.ravel()  # [length scale]
    if problem.friction.is_polyhedral(problem.dimension):
        c, reason = _polyhedral_step(problem, C, advance)
    else:
        c, reason = _exact_step(problem, C, advance, time_limit)
    if c is None:
        return StepForces(None, None, False, reason)
    displacement, determined = _displacement(problem, C, advance, c)
    return StepForces(c, displacement, determined)


def _polyhedral_step(problem: Problem, C: np.ndarray, advance: np.ndarray) -> tuple[np.ndarray | None, str]:
    count = problem.friction.edges if problem.friction.kind == "pyramid" else _PLANAR_EDGES
    if problem.dimension == 3 and problem.friction.kind == "none":
        count = _FRICTIONLESS_EDGES
    m = problem.n_contacts
    unloaded = ModeMasks(np.ones(m, dtype=bool), problem.mu > 0, np.zeros(m, dtype=bool))  # every contact may carry load
    consistent = forces_at_twist(problem, aligned_edges(problem, count), np.zeros(problem.n_dof), unloaded)
    forces = consistent.consistent()
    M = forces.M.tocsr()
    work = np.asarray(M.T @ advance).ravel()  # the movers' advance times each column's force
    if _rigid_squeeze(problem, C, consistent.polytope.normal, forces.A, work):
        return None, _step_failure("unbounded")
    hessian = sp.csr_matrix(M.T @ C @ M)
    unit = max(float(np.abs(hessian).max()), 1e-300)
    cost = -work / unit
    n = M.shape[1]
    result = solve_qp(hessian / unit, forces.A, forces.rhs, forces.rhs, np.zeros(n), np.full(n, np.inf), cost)
    if result.status != "optimal":
        return None, _step_failure(result.status)
    x = _polished(hessian.toarray() / unit, cost, forces.A.toarray(), forces.rhs, result.x)
    return np.asarray(M @ x).reshape(m, problem.dimension), ""


def _rigid_squeeze(problem: Problem, C: np.ndarray, normal: slice, A: sp.csr_matrix, work: np.ndarray) -> bool:
    """Whether the rigid contacts alone can squeeze against the advance: self-balanced forces on them doing work.

    Then the complementary energy falls without bound (those forces grow for free): no spring takes up the
    closing. An LP over the recession cone of the force polytope, its normal forces summing to at most 1.
    """
    d = problem.dimension
    rigid = np.array([C[i * d + d - 1, i * d + d - 1] == 0.0 for i in range(problem.n_contacts)], dtype=bool)
    if not rigid.any():
        return False
    n = A.shape[1]
    upper = np.full(n, np.inf)
    upper[np.arange(n)[normal][~rigid]] = 0.0  # springy contacts carry nothing in this direction
    total = sp.csr_matrix((np.ones(problem.n_contacts), (np.zeros(problem.n_contacts), np.arange(n)[normal])), shape=(1, n))
    rows = sp.vstack([A, total], format="csr")
    lower = np.r_[np.zeros(A.shape[0]), -np.inf]
    result = solve_lp(-work, rows, lower, np.r_[np.zeros(A.shape[0]), 1.0], np.zeros(n), upper)
    return result.status == "optimal" and -result.objective > LP_FEASIBILITY


def _exact_step(problem: Problem, C: np.ndarray, advance: np.ndarray, time_limit: float) -> tuple[np.ndarray | None, str]:
    import pyscipopt

    m, d = problem.n_contacts, problem.dimension
    scip = new_model(time_limit)
    c = [scip.addVar(lb=None, ub=None, name=f"c{j}") for j in range(m * d)]
    for i in range(m):
        scip.chgVarLb(c[i * d + d - 1], 0.0)
        t1, t2, n = c[i * d : (i + 1) * d]
        if problem.mu[i] > 0:
            scip.addCons(pyscipopt.sqrt(t1 * t1 + t2 * t2) <= float(problem.mu[i]) * n)
        else:
            scip.addCons(t1 == 0.0)
            scip.addCons(t2 == 0.0)
    for row, value in zip(problem.J.reshape(m * d, -1).T, -problem.g, strict=True):
        scip.addCons(linear(row, c) == float(value))
    unit = max(float(np.abs(C).max()), 1e-300)
    energy = scip.addVar(lb=None, ub=None, name="energy")
    scip.addCons(_quadratic(C / unit, c) - linear(advance / unit, c) <= energy)
    scip.setObjective(energy, "minimize")
    status = optimize(scip, "compliance")
    if status != "optimal":
        return None, _step_failure(status)
    return np.array([scip.getVal(v) for v in c]).reshape(m, d), ""


def _step_failure(status: str) -> str:
    if status == "unbounded":
        return "a rigid contact is closed by the movers' advance (no spring can take it up): the squeeze stays jammed"
    if status == "infeasible":
        return "no forces within the friction cones balance the load"
    return f"the program ended with status {status}"


def _displacement(problem: Problem, C: np.ndarray, advance: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, bool]:
    """The displacement D with ``J_i D = h b_i - (C c)_i`` at the loaded contacts (normal rows; every row where stuck).

    A contact at its friction limit gives only its normal row; an open one none.
    """
    m, d = problem.n_contacts, problem.dimension
    deflection = (C @ c.ravel()).reshape(m, d)
    target = advance.reshape(m, d) - deflection
    scale = max(float(np.abs(c).max(initial=0.0)), 1.0)
    loaded = c[:, -1] > LP_FEASIBILITY * scale
    stuck = loaded & (problem.mu > 0) & (np.linalg.norm(c[:, :-1], axis=1) < problem.mu * c[:, -1] - LP_FEASIBILITY * scale)
    rows = [problem.J[i] if stuck[i] else problem.J[i, -1:] for i in range(m) if loaded[i]]
    values = [target[i] if stuck[i] else target[i, -1:] for i in range(m) if loaded[i]]
    if not rows:
        return np.zeros(problem.n_dof), problem.n_dof == 0
    A, b = np.vstack(rows), np.concatenate(values)
    displacement = np.linalg.lstsq(A, b, rcond=None)[0]
    return displacement, null_space(A).shape[1] == 0
