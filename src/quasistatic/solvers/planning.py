"""The inverse problem's numerics: inputs of least cost that make a wanted twist, with given modes, satisfy the laws.

The wanted twist ``q`` is fixed, so the contact velocities are affine in the
free inputs ``p``: ``u = J q - b0 - B p``. Per contact mode:

- closed (rolling or sliding): ``u_n = 0``; separating: ``u_n >= delta`` and no force;
- rolling: ``u_t = 0``, the force anywhere in its cone;
- sliding: ``|u_t| >= delta`` and friction ``-mu c_n u_t/|u_t|``.

On polyhedral cones (2-D, and 3-D ``pyramid:K``) each sliding contact slides
one of a few ways: against one of its two edges in 2-D; on a pyramid, loading
one edge (its slip inside that edge's sector) or the two edges of a face (its
slip along the face's normal). For each choice the inputs are a QP (HiGHS) and
the forces an LP, both convex, and the cheapest feasible choice wins. On exact
3-D cones the sliding friction's direction follows the inputs; the problem is solved as an NLP (scipy's SLSQP) whose equalities are
the fixed-mode laws themselves (:func:`~quasistatic.laws.fixed_modes.system`
with the inputs as extra columns of ``J``, as the sensitivities use it), from
a start given by a QP and an LP. Every answer is checked by the caller's audit.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..laws import Problem
from ..laws.fixed_modes import ROLLING, SEPARATING, SLIDING, columns, system
from ..model import FloatArray
from ..tolerances import FIXED_MODE_RESIDUAL, PLAN_COST
from .numerics.highs import INF, solve_lp, solve_qp
from .numerics.optimize import minimize

__all__ = ["PlanModes", "PlannedInputs", "plan_inputs"]

_MAX_SLIDE_CHOICES = 2**12  # combinations of ways to slide tried: 12 sliding contacts in 2-D
_START_EDGES = 16  # the 3-D start's forces lie in a 16-sided pyramid inscribed in each cone
_NLP_ITERATIONS = 500


@dataclass(frozen=True)
class PlanModes:
    """The wanted mode of each contact as masks (m,): closed, rolling (u_t = 0), sliding (u_t != 0)."""

    closed: np.ndarray
    rolling: np.ndarray
    sliding: np.ndarray

    @classmethod
    def of(cls, modes: tuple[str, ...]) -> PlanModes:
        names = np.array(modes, dtype=object)
        return cls(names != "separating", names == "rolling", names == "sliding")


@dataclass(frozen=True)
class PlannedInputs:
    """The free inputs ``p`` (P,) [physical units], the contact-frame forces ``c`` (m, d) (scene-relative), the cost."""

    status: Literal["planned", "infeasible"]
    p: FloatArray
    c: FloatArray
    cost: float
    message: str


@dataclass(frozen=True)
class _Setup:
    problem: Problem
    q: FloatArray
    modes: PlanModes
    B: FloatArray  # (m, d, P): scene-relative contact velocity per physical free input
    hessian: FloatArray
    linear: FloatArray
    delta: float  # scene-relative smallest slip and separation speed

    @property
    def u0(self) -> FloatArray:
        """Contact velocities with every free input at zero, (m, d)."""
        return self.problem.velocities(self.q)


def plan_inputs(
    problem: Problem, q: FloatArray, modes: PlanModes, B: FloatArray, hessian: FloatArray, linear: FloatArray, delta: float
) -> PlannedInputs:
    """Least-cost free inputs (``p.H p / 2 + linear.p``) for the scene-relative twist ``q`` with ``modes``.

    ``problem`` is assembled with the free inputs at zero; ``B`` (m, d, P) maps them into ``u``: ``u = J q - b - B p``.
    """
    setup = _Setup(problem, q, modes, B, hessian, linear, delta)
    if problem.friction.is_polyhedral(problem.dimension):
        return _polyhedral(setup)
    return _spatial(setup)


# --------------------------------------------------------------------------- polyhedral cones: a QP and an LP per choice of loaded edges


@dataclass(frozen=True)
class _Slide:
    """One way a sliding contact may slide on a polyhedral cone.

    ``loads``: the tangent directions (E, t) its friction may load, with weights >= 0 summing to ``mu c_n``
    (one edge, or in 3-D the two edges of a face of the pyramid); its slip ``u_t`` then keeps
    ``r . u_t = 0`` for each row of ``level`` and ``r . u_t >= v`` for each ``(r, v)`` of ``at_least``.
    """

    loads: FloatArray
    level: tuple[FloatArray, ...]
    at_least: tuple[tuple[FloatArray, float], ...]


def _slides(setup: _Setup) -> list[_Slide]:
    """Every way one sliding contact may slide: against one of its 2 edges in 2-D; in 3-D on a pyramid, loading
    one edge ``d_j`` (its slip inside the sector where ``-d_j . u_t`` is largest) or a face (slip along its normal)."""
    delta = setup.delta
    if setup.problem.dimension == 2:
        return [_Slide(np.array([[-sign]]), (), ((np.array([sign]), delta),)) for sign in (1.0, -1.0)]
    d = np.array(_edges(setup.problem.friction.edges, 2))
    K = len(d)
    slides = []
    for j in range(K):
        after, before = d[(j + 1) % K], d[(j - 1) % K]
        slides.append(_Slide(d[[j]], (), ((-d[j], delta), (after - d[j], 0.0), (before - d[j], 0.0))))
        slides.append(_Slide(d[[j, (j + 1) % K]], (d[j] - after,), ((-d[j], delta),)))
    return slides


def _polyhedral(setup: _Setup) -> PlannedInputs:
    sliding = np.flatnonzero(setup.modes.sliding).tolist()
    # A way the inputs cannot give this contact's slip, whatever the other contacts do, is not combined with others.
    ways = [[way for way in _slides(setup) if _can_slide(setup, i, way)] for i in sliding]
    count = int(np.prod([len(w) for w in ways]))
    if count > _MAX_SLIDE_CHOICES:
        message = f"modes: the {len(sliding)} sliding contacts may slide in {count} combinations of ways, more than the planner tries"
        return _infeasible(setup, f"{message} ({_MAX_SLIDE_CHOICES})")
    best: PlannedInputs | None = None
    for choice in itertools.product(*ways):
        found = _planned_with(setup, dict(zip(sliding, choice, strict=True)))
        if found is not None and (best is None or found.cost < best.cost):
            best = found
    return best or _infeasible(setup, "no inputs give the wanted twist with these modes while the forces meet the laws")


def _can_slide(setup: _Setup, contact: int, way: _Slide) -> bool:
    """Whether some inputs meet every kinematic mode with ``contact`` sliding ``way`` (the other sliding ones free)."""
    A, lower, upper = _velocity_rows(setup, {contact: way})
    return solve_lp(np.zeros(A.shape[1]), A, lower, upper).status == "optimal"


def _planned_with(setup: _Setup, slides: dict[int, _Slide]) -> PlannedInputs | None:
    forces = _forces(setup, {i: slide.loads for i, slide in slides.items()}, edges=_rolling_edges(setup))
    if forces is None:
        return None
    A, lower, upper = _velocity_rows(setup, slides)
    result = solve_qp(setup.hessian, A, lower, upper, cost=setup.linear)
    if result.status != "optimal":
        return None
    return PlannedInputs("planned", result.x, forces, result.objective, "planned")


def _rolling_edges(setup: _Setup) -> int:
    """Edges of the pyramid a rolling force lies in: the friction model's own (2-D: both ways)."""
    return 2 if setup.problem.dimension == 2 else setup.problem.friction.edges


def _velocity_rows(setup: _Setup, slides: dict[int, _Slide]) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Rows ``lower <= A p <= upper`` of the kinematic modes, each sliding contact in ``slides`` sliding its way."""
    u0, B, delta, modes = setup.u0, setup.B, setup.delta, setup.modes
    t = u0.shape[1] - 1
    rows: list[FloatArray] = []
    lower: list[float] = []
    upper: list[float] = []

    def add(row: FloatArray, low: float, high: float) -> None:
        rows.append(row)
        lower.append(low)
        upper.append(high)

    for i in range(u0.shape[0]):
        # u = u0 - B p, so a bound l <= r . u <= h reads r . u0 - h <= r . B p <= r . u0 - l
        if not modes.closed[i]:
            add(B[i, t], -INF, u0[i, t] - delta)
            continue
        add(B[i, t], u0[i, t], u0[i, t])
        if modes.rolling[i]:
            for s in range(t):
                add(B[i, s], u0[i, s], u0[i, s])
        elif i in slides:
            for r in slides[i].level:
                level = float(r @ u0[i, :t])
                add(r @ B[i, :t], level, level)
            for r, least in slides[i].at_least:
                add(r @ B[i, :t], -INF, float(r @ u0[i, :t]) - least)
    P = B.shape[2]
    return (np.array(rows).reshape(len(rows), P), np.array(lower), np.array(upper))


def _forces(setup: _Setup, loads: dict[int, FloatArray], edges: int) -> FloatArray | None:
    """Contact-frame forces (m, d) in equilibrium with the modes: a sliding frictional contact's friction ``mu c_n``
    spread over its ``loads`` (tangent directions, (E, d - 1)), a rolling force in a pyramid of ``edges``
    inscribed in its cone (exact in 2-D), other closed contacts pushing along their normals."""
    problem, modes = setup.problem, setup.modes
    m, d, n = problem.n_contacts, problem.dimension, problem.n_dof
    t = d - 1
    directions = _edges(edges, t)
    # Unknowns: per closed contact a plain normal force (unless it slides with friction), and one weight per edge
    # it may load (its normal force's share; the friction mu times it along the edge).
    blocks: list[tuple[int, FloatArray | None]] = []
    for i in np.flatnonzero(modes.closed).tolist():
        if i in loads:
            blocks += [(i, e) for e in loads[i]]
            continue
        blocks.append((i, None))
        if modes.rolling[i] and problem.mu[i] > 0:
            blocks += [(i, e) for e in directions]
    columns = [problem.J[i, t] + (0.0 if e is None else problem.mu[i] * e @ problem.J[i, :t]) for i, e in blocks]
    A = np.array(columns).reshape(len(columns), n).T  # (n, unknowns): sum of J^T c = -g
    result = solve_lp(np.zeros(A.shape[1]), A, -problem.g, -problem.g, np.zeros(A.shape[1]), None)
    if result.status != "optimal":
        return None
    c = np.zeros((m, d))
    for (i, e), w in zip(blocks, result.x, strict=True):
        c[i, t] += w
        if e is not None:
            c[i, :t] += problem.mu[i] * w * e
    return c


def _edges(count: int, t: int) -> list[FloatArray]:
    """Unit tangent directions of an inscribed pyramid: both ways in 2-D, ``count`` around the circle in 3-D."""
    if t == 1:
        return [np.array([1.0]), np.array([-1.0])]
    angles = 2 * np.pi * np.arange(count) / count
    return [np.array([np.cos(a), np.sin(a)]) for a in angles]


def _infeasible(setup: _Setup, message: str) -> PlannedInputs:
    P = setup.B.shape[2]
    return PlannedInputs("infeasible", np.zeros(P), np.zeros(setup.u0.shape), float("nan"), message)


# --------------------------------------------------------------------------- 3-D: the fixed-mode laws as NLP constraints


def _spatial(setup: _Setup) -> PlannedInputs:
    start = _spatial_start(setup)
    if start is None:
        return _infeasible(setup, "no start: the inputs or the forces cannot meet the modes' linear conditions")
    nlp = _SpatialNLP(setup)
    z0 = nlp.pack(*start)
    scale = abs(nlp.cost(z0)) or 1.0  # SLSQP's stopping rule is absolute: the cost in units of its start
    result = minimize(
        lambda z: nlp.cost(z) / scale,
        z0,
        jac=lambda z: nlp.cost_gradient(z) / scale,
        method="SLSQP",
        constraints=[
            {"type": "eq", "fun": nlp.equalities, "jac": nlp.equality_jacobian},
            {"type": "ineq", "fun": nlp.inequalities, "jac": nlp.inequality_jacobian},
        ],
        options={"maxiter": _NLP_ITERATIONS, "ftol": PLAN_COST},
    )
    p, c = nlp.unpack(result.x)
    if (
        float(np.max(np.abs(nlp.equalities(result.x)), initial=0.0)) > FIXED_MODE_RESIDUAL
        or np.min(nlp.inequalities(result.x), initial=0.0) < -FIXED_MODE_RESIDUAL
    ):
        return _infeasible(setup, f"the NLP found no inputs that meet the laws ({result.message})")
    return PlannedInputs("planned", p, c, float(nlp.cost(result.x)), "planned")


def _spatial_start(setup: _Setup) -> tuple[FloatArray, FloatArray] | None:
    """Inputs from the QP with each sliding contact slipping along its slip at zero input (or its first tangent), and
    forces from the LP with friction against that slip and rolling forces in inscribed pyramids."""
    u0, t = setup.u0, setup.problem.dimension - 1
    directions = np.zeros((u0.shape[0], t))
    for i in np.flatnonzero(setup.modes.sliding):
        speed = np.linalg.norm(u0[i, :t])
        directions[i] = u0[i, :t] / speed if speed > setup.delta else np.eye(t)[0]
    A, lower, upper = _velocity_rows(setup, {})
    extra_rows, extra_values = [], []
    for i in np.flatnonzero(setup.modes.sliding):
        # u_t = (2 delta) e_i: the start slips along e_i, comfortably past delta
        for s in range(t):
            extra_rows.append(setup.B[i, s])
            extra_values.append(u0[i, s] - 2 * setup.delta * directions[i, s])
    if extra_rows:
        A = np.vstack([A, np.array(extra_rows)])
        lower, upper = np.r_[lower, extra_values], np.r_[upper, extra_values]
    inputs = solve_qp(setup.hessian, A, lower, upper, cost=setup.linear)
    loads = {int(i): -directions[[i]] for i in np.flatnonzero(setup.modes.sliding & (setup.problem.mu > 0))}
    forces = _forces(setup, loads, edges=_START_EDGES)
    if inputs.status != "optimal" or forces is None:
        return None
    return inputs.x, forces


class _SpatialNLP:
    """Unknowns ``z = (p, the closed contacts' force unknowns of the fixed-mode laws)``; the twist is fixed."""

    def __init__(self, setup: _Setup) -> None:
        self.setup = setup
        problem = setup.problem
        self.n, self.P, self.t = problem.n_dof, setup.B.shape[2], problem.dimension - 1
        modes = setup.modes
        self.kind = np.where(modes.closed, np.where(modes.rolling & (problem.mu > 0), ROLLING, SLIDING), SEPARATING).astype(np.int64)
        self.J = np.ascontiguousarray(np.concatenate([problem.J, -setup.B], axis=2))
        self.g = np.concatenate([problem.g, np.zeros(self.P)])
        self.b, self.mu = np.ascontiguousarray(problem.b), np.ascontiguousarray(problem.mu)
        self.column, self.size = columns(self.kind, self.n + self.P, self.t)
        self.keep = np.r_[0 : self.n, self.n + self.P : self.size]
        self._still = modes.rolling & (problem.mu == 0)  # frictionless, asked to roll: a kinematic wish, no law

    def pack(self, p: FloatArray, c: FloatArray) -> FloatArray:
        z = np.zeros(self.size - self.n)
        z[: self.P] = p
        for i in np.flatnonzero(self.kind != SEPARATING):
            z[self.column[i] - self.n] = c[i, self.t]
            if self.kind[i] == ROLLING:
                z[self.column[i] - self.n + 1 : self.column[i] - self.n + 1 + self.t] = c[i, : self.t]
        return z

    def _x(self, z: FloatArray) -> FloatArray:
        return np.concatenate([self.setup.q, z])

    def _system(self, z: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return system(self.J, self.b, self.mu, self.g, self._x(z), self.kind, self.column, self.n + self.P)

    def unpack(self, z: FloatArray) -> tuple[FloatArray, FloatArray]:
        return z[: self.P].copy(), self._system(z)[2]

    def cost(self, z: FloatArray) -> float:
        p = z[: self.P]
        return float(0.5 * p @ self.setup.hessian @ p + self.setup.linear @ p)

    def cost_gradient(self, z: FloatArray) -> FloatArray:
        gradient = np.zeros_like(z)
        gradient[: self.P] = self.setup.hessian @ z[: self.P] + self.setup.linear
        return gradient

    def equalities(self, z: FloatArray) -> FloatArray:
        """The fixed-mode laws at the wanted twist, and no slip at frictionless contacts asked to roll."""
        u, _ = self._velocities(z)
        return np.concatenate([self._system(z)[0][self.keep], u[self._still, : self.t].ravel()])

    def equality_jacobian(self, z: FloatArray) -> FloatArray:
        laws = self._system(z)[1][np.ix_(self.keep, np.arange(self.n, self.size))]
        still = np.zeros((int(self._still.sum()) * self.t, z.size))
        still[:, : self.P] = -self.setup.B[self._still, : self.t].reshape(-1, self.P)
        return np.vstack([laws, still])

    def _velocities(self, z: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Contact velocities (m, d) and their derivative in ``p`` (m, d, P)."""
        setup = self.setup
        return setup.u0 - np.einsum("mdP,P->md", setup.B, z[: self.P]), -setup.B

    def inequalities(self, z: FloatArray) -> FloatArray:
        return self._inequality_parts(z)[0]

    def inequality_jacobian(self, z: FloatArray) -> FloatArray:
        return self._inequality_parts(z)[1]

    def _inequality_parts(self, z: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Non-negative values: separation past delta, normal forces, rolling cones, slip speed past delta."""
        u, du = self._velocities(z)
        t, delta, P = self.t, self.setup.delta, self.P
        values: list[float] = []
        rows: list[FloatArray] = []

        def add(value: float, row: FloatArray) -> None:
            values.append(value)
            rows.append(row)

        for i in range(self.kind.shape[0]):
            row = np.zeros_like(z)
            if self.kind[i] == SEPARATING:
                row[:P] = du[i, t]
                add(u[i, t] - delta, row)
                continue
            col = self.column[i] - self.n
            cn = z[col]
            row[col] = 1.0
            add(cn, row)
            if self.kind[i] == ROLLING:
                ct = z[col + 1 : col + 1 + t]
                cone = np.zeros_like(z)
                cone[col], cone[col + 1 : col + 1 + t] = 2 * self.mu[i] ** 2 * cn, -2 * ct
                add(self.mu[i] ** 2 * cn * cn - float(ct @ ct), cone)
            elif self.setup.modes.sliding[i]:
                slip = np.zeros_like(z)
                slip[:P] = 2 * u[i, :t] @ du[i, :t]
                add(float(u[i, :t] @ u[i, :t]) - delta * delta, slip)
        return np.array(values), np.array(rows).reshape(len(rows), z.size)
