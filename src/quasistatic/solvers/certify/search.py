"""The certified search over contact modes: SCIP proves a motion exists or that none does, and lists them all.

The polyhedral laws (2-D exact cone, or a 3-D pyramid) become a mixed-integer
feasibility problem: each complementarity pair ``0 <= x _|_ w >= 0`` is an
SOS1 constraint (at most one of ``x``, ``w`` nonzero), which SCIP branches on
directly. No big-M: SOS1 constraints carry no bounds to guess (they were
measured 4 to 5 times faster than a binary with two indicator constraints on
3-D scenes). Every motion SCIP finds is excluded and the search goes on, so
the list of motions is complete. Each pattern's motions form a polyhedron
whose twist extent is measured by LPs: a single twist, or a continuum.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SolverError
from ...laws import Problem, RawMotion, contact_modes
from ...laws.polyhedral import LCPForm, polyhedral_form
from ...solution import Diagnosis
from ...tolerances import DISTINCT_TWIST, MODE_SPEED, SAME_TWIST
from ..numerics.forces import DeferredIndeterminacy
from ..numerics.highs import solve_lp
from ..numerics.ranges import polyhedron_extremes
from ..numerics.scip_model import exclude_box, linear, new_model, optimize
from ..result import BackendResult, Options
from .diagnose import MESSAGES, diagnose

__all__ = ["enumerate_motions", "certified_polyhedral", "summarise", "relative_interior_point"]

_SLIDE_MIN = 10.0 * MODE_SPEED  # scene-relative slip speed that counts as sliding when a mode is prescribed


def certified_polyhedral(problem: Problem, edges: np.ndarray, options: Options, seed: np.ndarray | None = None) -> BackendResult:
    """The complete search's verdict; ``seed``, a point satisfying every law (checked by the caller), is its first motion."""
    form = polyhedral_form(problem, edges)
    motions, complete = enumerate_motions(form, options, seed)
    if not motions:
        if not complete:
            return BackendResult("failed", "failed: the certified search hit its time limit before finding a motion")
        if options.modes is not None:
            return BackendResult("jammed", MESSAGES[Diagnosis.PRESCRIBED_MODES], diagnosis=Diagnosis.PRESCRIBED_MODES, search_complete=True)
        return diagnose(problem, edges)
    return summarise(form, motions, complete, options)


def summarise(form: LCPForm, motions: list[RawMotion], complete: bool, options: Options) -> BackendResult:
    """One motion: solved (with force ranges); several or a continuum: ambiguous."""
    if len(motions) == 1 and not motions[0].continuum and not complete:
        limit = "max_solutions (1)" if options.max_solutions <= 1 else "the time limit"
        message = (
            f"failed: one motion was found (audited, reported as the motion), but the search hit {limit} before proving it unique; raise it"
        )
        return BackendResult("failed", message, tuple(motions), certified=False, search_complete=False)
    motions = [_with_force_ranges(form, motion) for motion in motions]
    if len(motions) == 1 and not motions[0].continuum:
        return BackendResult("solved", "solved: one motion", tuple(motions), search_complete=True, claims_forces=True)
    kinds = "a continuum of motions" if len(motions) == 1 else f"{len(motions)} distinct motions"
    more = "" if complete else " (the list may be incomplete)"
    return BackendResult(
        "ambiguous",
        f"ambiguous: {kinds} satisfy the laws{more}; the rigid model cannot tell which happens",
        tuple(motions),
        search_complete=complete,
    )


def _with_force_ranges(form: LCPForm, motion: RawMotion) -> RawMotion:
    """A single motion with whether its forces are indeterminate, and their ranges, all decided when first read
    (:func:`~..numerics.forces.indeterminate_forces`; a continuum's forces vary along it, and it has no ranges).

    What is known of a solved motion's forces: every component of every contact force, friction included,
    is unique or not; the message says so (``BackendResult.claims_forces``) when it is read.
    """
    if motion.continuum:
        return motion
    return dataclasses.replace(motion, deferred=DeferredIndeterminacy(form.problem, form.edges, motion.q))


@dataclass
class _Model:
    scip: Any
    x: list[Any]  # unknowns [q, cn, beta, lam]
    w: list[Any]  # complementarity slacks, one per pair


def _build(form: LCPForm, options: Options, sos1: bool = True) -> _Model:
    """The feasibility model; complementarity by SOS1, or by a binary and two indicators when ``sos1`` is False."""
    scip = new_model(options.remaining())
    N = form.n_vars
    x = [scip.addVar(lb=None if j < form.n_q else 0.0, ub=None, name=f"x{j}") for j in range(N)]
    for row, rhs in zip(form.E_eq, form.e_eq, strict=True):
        scip.addCons(linear(row, x) == rhs)
    w = []
    for i, col in enumerate(form.pair_cols):
        wi = scip.addVar(lb=0.0, ub=None, name=f"w{i}")
        scip.addCons(linear(form.W[i], x) - wi == form.r[i])
        if sos1:
            scip.addConsSOS1([x[col], wi])
        else:
            zi = scip.addVar(vtype="B", name=f"z{i}")
            scip.addConsIndicator(x[col] <= 0.0, zi)
            scip.addConsIndicator(wi <= 0.0, zi, activeone=False)
        w.append(wi)
    _prescribe_modes(scip, form, x, options)
    return _Model(scip, x, w)


def _prescribe_modes(scip: Any, form: LCPForm, x: list[Any], options: Options) -> None:
    if options.modes is None:
        return
    problem = form.problem
    m = problem.n_contacts
    lam0 = form.n_q + m + m * form.n_edges
    for i, mode in enumerate(options.modes):
        if mode is None:
            continue
        normal = problem.Jn[i]
        if mode == "separating":
            scip.addCons(linear(normal, x) >= problem.bn[i] + _SLIDE_MIN)
            continue
        scip.addCons(linear(normal, x) <= problem.bn[i])
        if mode == "rolling":
            for row, rhs in zip(problem.Jt[i], problem.bt[i], strict=True):
                scip.addCons(linear(row, x) == rhs)
        else:
            scip.addCons(x[lam0 + i] >= _SLIDE_MIN)


def enumerate_motions(form: LCPForm, options: Options, seed: np.ndarray | None = None) -> tuple[list[RawMotion], bool]:
    """Every distinct motion (up to ``options.max_solutions``), and whether the search was complete.

    ``seed``: a point ``x`` of the form already known to satisfy every law (checked by the
    caller, e.g. Lemke's): it is taken as the first motion found, so SCIP's first solve
    (find any motion) is skipped; the rest of the search is unchanged.

    A single motion is excluded by a box around its twist (so the many
    degenerate patterns that share it are excluded at once). A continuum is
    excluded as a set: some pair its pattern holds at zero must move away
    from zero. A cut on the pattern's binaries would not do: a face of a
    larger continuum (the level grasp's sliding-rolling edge of its
    sliding-sliding slip) shares binaries with it and would hide it.

    SCIP's LP solver occasionally fails on the SOS1 model's relaxations; the
    search then starts again on the indicator form, which is slower but was
    measured robust on the same scenes.
    """
    try:
        return _enumerate(form, options, sos1=True, seed=seed)
    except SolverError:
        return _enumerate(form, options, sos1=False, seed=seed)


def _enumerate(form: LCPForm, options: Options, sos1: bool, seed: np.ndarray | None) -> tuple[list[RawMotion], bool]:
    model = _build(form, options, sos1)
    scip = model.scip
    motions: list[RawMotion] = []
    if seed is not None:
        _record(form, model, seed, form.W @ seed - form.r, motions, options)
        if len(motions) >= options.max_solutions:
            return motions, False
    while True:
        if options.remaining() <= 0.0:
            return motions, False
        scip.setParam("limits/time", options.remaining())
        status = optimize(scip, "scip")
        options.report(len(motions), int(scip.getNNodes()))
        if status == "infeasible":
            return motions, True
        if scip.getNSols() == 0:
            return motions, False
        best = scip.getBestSol()
        xs = np.array([scip.getSolVal(best, v) for v in model.x])
        ws = np.array([scip.getSolVal(best, v) for v in model.w])
        scip.freeTransform()
        _record(form, model, xs, ws, motions, options)
        if len(motions) >= options.max_solutions:
            return motions, False


def _record(form: LCPForm, model: _Model, xs: np.ndarray, ws: np.ndarray, motions: list[RawMotion], options: Options) -> None:
    """The motion of the solution ``(xs, ws)``, added to ``motions`` when new, and excluded from the model."""
    zs = _pattern(xs[form.pair_cols], ws)
    motion = _pattern_motion(form, xs, zs, options)
    if not any(_same(form.problem, motion, other) for other in motions):
        motions.append(motion)
    if motion.continuum:
        _exclude_polyhedron(model.scip, model, zs, form)
    else:
        exclude_box(model.scip, model.x[: form.n_q], xs[: form.n_q], DISTINCT_TWIST)


def _pattern(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """1 where a pair's variable is held at zero, 0 where its slack is (the smaller one; SOS1 zeroes one exactly)."""
    return (np.abs(x) <= np.abs(w)).astype(int)


def _exclude_polyhedron(scip: Any, model: _Model, pattern: np.ndarray, form: LCPForm) -> None:
    """Leave the polyhedron of ``pattern``: some variable or slack it holds at zero reaches DISTINCT_TWIST."""
    import pyscipopt

    held = [model.x[col] if zi else w for col, w, zi in zip(form.pair_cols, model.w, pattern, strict=True)]
    leave = []
    for var in held:
        flag = scip.addVar(vtype="B")
        scip.addConsIndicator(-var <= -DISTINCT_TWIST, flag)
        leave.append(flag)
    scip.addCons(pyscipopt.quicksum(leave) >= 1)


def _pattern_motion(form: LCPForm, x: np.ndarray, z: np.ndarray, options: Options) -> RawMotion:
    """The motion (single twist or continuum) of one complementarity pattern."""
    N = form.n_vars
    cols = form.pair_cols
    fixed_zero = np.eye(N)[cols[z == 1]]
    A_eq = np.vstack([form.E_eq, fixed_zero, form.W[z == 0]])
    b_eq = np.r_[form.e_eq, np.zeros(len(fixed_zero)), form.r[z == 0]]
    A_in, b_in = form.W[z == 1], form.r[z == 1]
    A_eq, b_eq, A_in, b_in = _with_prescribed_modes(form, options, A_eq, b_eq, A_in, b_in)
    lower = np.r_[np.full(form.n_q, -np.inf), np.zeros(N - form.n_q)]
    points, free = polyhedron_extremes(form.n_q, A_eq, b_eq, A_in, b_in, lower)
    extremes = [p[: form.n_q] for p in points]
    unbounded = bool(free)
    # One extreme (the 2n LPs' optima within SAME_TWIST of each other) is one twist, that vertex: SCIP's own point
    # meets the rows to its tolerance only, and where the twist is large (150 x the scene's speed) it was more
    # than SAME_TWIST off it, so a single motion was listed twice, once as a "continuum" of that one extreme.
    continuum = unbounded or len(extremes) > 1
    if not continuum:
        return RawMotion(extremes[0] if extremes else x[: form.n_q], form.forces(x), (), False)
    # Represent a continuum by a point inside it, so its modes are those of its interior:
    # every inequality as slack as it can be, the pairs' own variables (slip speeds) included.
    free_pairs = np.eye(N)[cols[z == 0]]
    x = relative_interior_point(A_eq, b_eq, np.vstack([A_in, free_pairs]), np.r_[b_in, np.zeros(len(free_pairs))], lower, x)
    forces = tuple(form.forces(p) for p in points)  # each extreme's own: the pattern's forces vary over it
    return RawMotion(x[: form.n_q], form.forces(x), tuple(extremes), unbounded, free, extreme_forces=forces)


def relative_interior_point(
    A_eq: np.ndarray, b_eq: np.ndarray, A_in: np.ndarray, b_in: np.ndarray, lower: np.ndarray, fallback: np.ndarray
) -> np.ndarray:
    """A point of the polyhedron whose inequalities are as slack as possible (each capped at 1)."""
    N, k = A_eq.shape[1], A_in.shape[0]
    A = np.block([[A_eq, np.zeros((A_eq.shape[0], k))], [A_in, -np.eye(k)]])
    lo = np.r_[b_eq, b_in]
    hi = np.r_[b_eq, np.full(k, np.inf)]
    cost = np.r_[np.zeros(N), np.ones(k)]
    lp = solve_lp(cost, A, lo, hi, np.r_[lower, np.zeros(k)], np.r_[np.full(N, np.inf), np.ones(k)], maximize=True)
    return lp.x[:N] if lp.status == "optimal" else fallback


def _with_prescribed_modes(
    form: LCPForm, options: Options, A_eq: np.ndarray, b_eq: np.ndarray, A_in: np.ndarray, b_in: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Prescribed modes as extra rows: rolling pins the slip, the others bound it away from zero."""
    if options.modes is None:
        return A_eq, b_eq, A_in, b_in
    problem = form.problem
    m = problem.n_contacts
    lam0 = form.n_q + m + m * form.n_edges
    rows, rhs = [A_in], [b_in]
    eq_rows, eq_rhs = [A_eq], [b_eq]
    for i, mode in enumerate(options.modes):
        row = np.zeros(form.n_vars)
        if mode == "rolling":
            block = np.zeros((problem.dimension, form.n_vars))
            block[:, : form.n_q] = problem.J[i]
            eq_rows.append(block)
            eq_rhs.append(problem.b[i])
        elif mode == "separating":
            row[: form.n_q] = problem.Jn[i]
            rows.append(row[None])
            rhs.append(np.array([problem.bn[i] + _SLIDE_MIN]))
        elif mode == "sliding":
            row[lam0 + i] = 1.0
            rows.append(row[None])
            rhs.append(np.array([_SLIDE_MIN]))
    return np.vstack(eq_rows), np.concatenate(eq_rhs), np.vstack(rows), np.concatenate(rhs)


def _same(problem: Problem, a: RawMotion, b: RawMotion) -> bool:
    """Same motion: equal twists, or continua with the same modes and the same extremes.

    Continua are compared by their modes too: the slip-down family of a level
    grasp and its rolling-sliding edge share every finite extreme, yet are
    different motions.
    """
    if a.continuum != b.continuum or a.unbounded != b.unbounded:
        return False
    if not a.continuum:
        return bool(np.max(np.abs(a.q - b.q)) <= SAME_TWIST)
    if contact_modes(problem, a.q) != contact_modes(problem, b.q):
        return False
    return len(a.extremes) == len(b.extremes) and all(any(np.max(np.abs(e - f)) <= SAME_TWIST for f in b.extremes) for e in a.extremes)
