"""The polyhedral contact laws as one standard LCP, solved by Lemke's method; exact 3-D cones by re-aligned edges.

The polyhedral laws (see :mod:`quasistatic.laws.polyhedral`) form a mixed LCP:
the twist ``q`` is free and equilibrium is an equation. Splitting ``q = q+ - q-``
and pairing each half with one sign of the equilibrium residual,

    0 <= q+  _|_  -g - Jn^T cn - (D^T Jt)^T beta  >= 0
    0 <= q-  _|_   g + Jn^T cn + (D^T Jt)^T beta  >= 0

makes it a standard LCP (both rows non-negative is equilibrium) whose
twist-force coupling is skew-symmetric, so ``z^T M z = sum mu cn lam >= 0``
(the matrix is copositive). Only contacts with ``mu > 0`` get edges.

For exact 3-D cones the kernel turns each sliding contact's pyramid so one
edge lies opposite its slip and solves again, and solves the exact
fixed-mode laws (:mod:`quasistatic.laws.fixed_modes`) by Newton's method;
see :mod:`quasistatic.solvers.fast`. Everything runs in one kernel, compiled
by numba when it is installed. The frictionless LP (:mod:`quasistatic.solvers.lp`)
uses the same kernel without edges.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.linalg.lapack import dgesv

from ...compiled import HAVE_EXTENSION, NewtonTolerances
from ...compiled import exact_newton as compiled_exact_newton
from ...compiled import solve_split_lcp as compiled_split_lcp
from ...jit import njit
from ...laws import Problem
from ...laws.fixed_modes import columns, system
from ...tolerances import BASIS_FEASIBILITY, CONE_ROUNDOFF, FRICTION_ALIGNMENT, MODE_SPEED, NEWTON_DAMPING, NEWTON_STOP, PIVOT
from .lemke import SOLUTION, lemke

__all__ = [
    "solve_split_lcp",
    "split_lcp_point",
    "split_lcp_points",
    "lemke_motion",
    "exact_newton",
    "lemke_depth",
    "LemkeInputs",
    "NOT_CONVERGED",
    "PIVOTS_PER_ROW",
    "FAST_EDGES",
    "GAP_COVERING",
    "PLANAR_EDGES",
]

PIVOTS_PER_ROW = 20  # Lemke pivot cap per LCP row
NOT_CONVERGED = 3  # kernel status beyond Lemke's: neither re-alignment nor Newton's method reached the exact cone
FAST_EDGES = 6  # pyramid edges for exact 3-D cones (Newton then solves the circle; 6 was 2-3x faster than 8 on 3-D grasps, same successes)
REALIGNMENTS = 20  # most edge re-alignments for exact 3-D cones
NEWTON_ITERATIONS = 50  # most Newton iterations a set of contact modes gets (the kernel's patience: a stall never ends it early)
# Lemke's covering vector on the gap rates' rows in the fast path (1 on the others): a path that relaxes the gap
# rates less than equilibrium and friction ends sooner (grasp-3d 8 #0: 59 pivots, not 113, docs/performance.md).
GAP_COVERING = 0.3
QUICK_PATIENCE = 2  # Newton iterations without halving the residual after which a due mode switch ends the round (8 #1)
PLANAR_EDGES = np.array([1.0, -1.0])  # a 2-D cone's edges along the tangent, as the kernels build them


class LemkeInputs:
    """The kernel's inputs derived from a problem (kept with it by :meth:`Problem.derived`).

    Attributes
    ----------
    J, b, mu, g : contiguous float copies of the problem's
    frictional : (f,) indices of the contacts with mu > 0
    base : (K,) edge signs (2-D) or unrotated edge angles (3-D)
    exact : exact 3-D cones (edges re-aligned with the slips)
    """

    def __init__(self, problem: Problem) -> None:
        self.exact = problem.dimension == 3 and not problem.friction.is_polyhedral(3)
        if problem.dimension == 2:
            self.base = PLANAR_EDGES
        else:
            self.base = _edge_angles(FAST_EDGES if self.exact else problem.friction.edges).copy()  # (a copy is cheaper than arange)
        contiguous = np.ascontiguousarray  # assembly's arrays already are: each call returns its argument
        self.J, self.b, self.mu, self.g = (
            contiguous(problem.J, float),
            contiguous(problem.b, float),
            contiguous(problem.mu, float),
            contiguous(problem.g, float),
        )
        self.frictional = (self.mu > 0.0).nonzero()[0]  # (np.flatnonzero's ravel and dispatch cost twice this)


@functools.cache
def _edge_angles(count: int) -> np.ndarray:
    """The unrotated angles of a ``count``-edge pyramid (kept per count: every fresh problem derives them)."""
    return 2.0 * np.pi * np.arange(count) / count


def lemke_motion(problem: Problem, short_path: bool = False) -> tuple[int, int, np.ndarray, np.ndarray, int, int]:
    """The fast path's kernel on ``problem`` with the library's tolerances (inputs kept with the problem).

    ``short_path``: Lemke's method keeps the twist halves basic once they enter, from a covering vector of
    :data:`GAP_COVERING` on the gap rates' rows (:func:`solve_split_lcp`; the fast path's choice); else the
    textbook path (the certified method's candidate, as before).
    Returns status, stage, twist ``q``, contact-frame forces ``c``, pivots and re-alignments, as
    :func:`solve_split_lcp`.
    """
    data = problem.derived("fast", LemkeInputs)
    return solve_split_lcp(
        data.J,
        data.b,
        data.mu,
        data.g,
        data.frictional,
        data.base,
        data.exact,
        short_path,
        GAP_COVERING if short_path else 1.0,
        REALIGNMENTS,
        FRICTION_ALIGNMENT,
        MODE_SPEED,
        PIVOT,
        BASIS_FEASIBILITY,
        PIVOTS_PER_ROW,
    )


def exact_newton(
    problem: Problem, q: np.ndarray, c: np.ndarray, depth: float = 0.0, patience: int = NEWTON_ITERATIONS, one_switch: bool = False
) -> tuple[bool, np.ndarray, np.ndarray]:
    """The exact 3-D laws with the contact modes of a pyramid's motion ``(q, c)``, by the kernel's Newton method
    (the one :func:`solve_split_lcp` runs on Lemke's motion). Returns whether it converged with every mode and
    inequality kept, the twist ``q`` (n,) and forces ``c`` (m, 3).

    ``depth`` [scene velocity]: how far the start lets contacts penetrate and still counts them closed (the
    artificial variable of a Lemke point that is not a solution, :func:`lemke_depth`); 0 for a motion.
    ``patience``: Newton iterations without halving the residual after which a mode switch that is due (a
    normal force turned negative, a penetration, a slip stopped) ends the round, rather than after
    :data:`NEWTON_ITERATIONS` (the kernel's own Newton): 2 (:data:`QUICK_PATIENCE`) reaches grasp-3d 8 #1's motion
    from Lemke's ray point and takes 6 #3's in ~15x fewer evaluations of the laws, but misses 8 #0's.
    ``one_switch``: a round switches only the first contact that must switch (in index order), not all of them at
    once; with quick rounds it reaches grasp-3d 8 #0's motion from Lemke's ray point in ~45 evaluations of the laws
    (docs/performance.md), where switching all of them fails.

    Its C twin runs where the extension was built, with numba or without: about 3x faster than the numba
    kernel called from Python, 25x faster than the kernel as plain Python (grasp-3d 6 #3 and 8 #0-#3, from
    where Lemke's path ended; docs/performance.md)."""
    data = problem.derived("fast", LemkeInputs)
    newton = _newton_compiled if HAVE_EXTENSION else _newton
    return newton(data.J, data.b, data.mu, data.g, q, c, depth, patience, one_switch, MODE_SPEED, FRICTION_ALIGNMENT)


def lemke_depth(problem: Problem, q: np.ndarray) -> float:
    """The artificial variable ``z0`` of a Lemke point that is not a solution (a secondary ray's last point) [scene
    velocity]: the path solves the laws with every gap rate raised by ``z0``, so the contacts it holds closed
    penetrate at ``-z0`` and the deepest penetration of the twist ``q`` (n,) is ``z0`` (0 where none does)."""
    normal_rates = problem.J[:, -1, :] @ q - problem.b[:, -1]
    return max(0.0, -float(normal_rates.min(initial=0.0)))


_NEWTON = NewtonTolerances(CONE_ROUNDOFF, NEWTON_DAMPING, NEWTON_STOP)  # the C kernel's Newton iterations, built once


def _solve_split_lcp_compiled(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    exact: bool,
    free_twist: bool,
    gap_covering: float,
    max_realignments: int,
    dissipation_tol: float,
    mode_tol: float,
    pivot_tol: float,
    feasibility_tol: float,
    pivots_per_row: int,
) -> tuple[int, int, np.ndarray, np.ndarray, int, int]:
    """:func:`solve_split_lcp` in the extension's C, step for step (what runs without numba where it was built)."""
    args = (max_realignments, dissipation_tol, mode_tol, pivot_tol, feasibility_tol, pivots_per_row, _NEWTON)
    return compiled_split_lcp(J, b, mu, g, frictional, base, exact, free_twist, gap_covering, *args)


# Without numba: the extension's C where it was built, else this kernel as plain Python (with its steps' numpy twins).
@njit(python=_solve_split_lcp_compiled if HAVE_EXTENSION else None)
def solve_split_lcp(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    exact: bool,
    free_twist: bool,
    gap_covering: float,
    max_realignments: int,
    dissipation_tol: float,
    mode_tol: float,
    pivot_tol: float,
    feasibility_tol: float,
    pivots_per_row: int,
) -> tuple[int, int, np.ndarray, np.ndarray, int, int]:
    """Lemke on the split-twist LCP, then (exact 3-D cones) edge re-alignment.

    ``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,) as in Problem;
    ``frictional`` (f,) the contacts with ``mu > 0``; ``base`` (K,) the edge
    signs in 2-D or the unrotated edge angles in 3-D. ``free_twist``: the
    halves ``q+``, ``q-`` are Lemke's free variables (kept basic once they
    enter, :mod:`.lemke`): the twist crosses zero without leaving the basis,
    a shorter path (grasp-3d 8 #0: 113 pivots, not 143). ``gap_covering``:
    Lemke's covering vector on the gap rates' rows (1 on the others; 1 is
    the textbook start).

    Returns status (lemke's, or 3: not converged), stage (0: first solve,
    1: after re-alignment, 2: Newton's method), twist ``q`` (n,), forces
    ``c`` (m, d) in contact frames, pivots and re-alignments.
    """
    m, d, n = J.shape
    f = frictional.shape[0]
    Jn, bn, Jt, bt, mu_f = _split_rows(J, b, mu, frictional)
    offsets = np.zeros(f)
    edges = _edges(base, offsets, d - 1)
    M, qv = _assemble(Jn, Jt, bn, bt, mu_f, g, edges, frictional)
    cap = pivots_per_row * qv.shape[0]
    free = 2 * n if free_twist else 0
    covering = _covering(qv.shape[0], n, m, gap_covering)
    status, z, pivots, basis = lemke(M, qv, covering, cap, pivot_tol, free)
    q, c = _motion(z, edges, frictional, m, d, n)
    realignments = 0
    if status != SOLUTION or not exact:
        return status, 0, q, c, pivots, realignments
    slip = np.empty((f, 2))
    previous = np.inf
    while True:
        # Sliding contacts' slips, and how far their friction is from -mu cn slip/|slip|.
        error = 0.0
        for a in range(f):
            i = frictional[a]
            for s in range(2):
                slip[a, s] = -bt[a, s]
                for j in range(n):
                    slip[a, s] += Jt[a, s, j] * q[j]
            speed = np.sqrt(slip[a, 0] ** 2 + slip[a, 1] ** 2)
            if speed > mode_tol:
                scale = mu_f[a] * c[i, 2] / speed
                error = max(error, np.sqrt((c[i, 0] + scale * slip[a, 0]) ** 2 + (c[i, 1] + scale * slip[a, 1]) ** 2))
                offsets[a] = np.arctan2(-slip[a, 1], -slip[a, 0])
        if error <= dissipation_tol:
            return SOLUTION, min(realignments, 1), q, c, pivots, realignments
        if realignments == 0 or realignments == max_realignments or error > 0.5 * previous:
            # First, and whenever re-alignment stalls (a pyramid lets a slip turn within its
            # vertex's fan at no change of force): the exact laws with these contact modes.
            converged, q_exact, c_exact = _newton(J, b, mu, g, q, c, 0.0, NEWTON_ITERATIONS, False, mode_tol, dissipation_tol)
            if converged:
                return SOLUTION, 2, q_exact, c_exact, pivots, realignments
            if realignments == max_realignments:
                return NOT_CONVERGED, 2, q, c, pivots, realignments
        previous = error
        realignments += 1
        edges = _edges(base, offsets, 2)
        M, qv = _assemble(Jn, Jt, bn, bt, mu_f, g, edges, frictional)
        feasible, z = _basis_solution(M, qv, basis, feasibility_tol, free)
        if not feasible:
            status, z, more, basis = lemke(M, qv, covering, cap, pivot_tol, free)
            pivots += more
            if status != SOLUTION:
                q, c = _motion(z, edges, frictional, m, d, n)
                return status, 1, q, c, pivots, realignments
        q, c = _motion(z, edges, frictional, m, d, n)


@njit
def _covering(N: int, n: int, m: int, gap_covering: float) -> np.ndarray:
    """Lemke's covering vector (N,) on ``z = [q+, q-, cn, beta, lam]``: ``gap_covering`` on the gap rates' rows (those
    of ``cn``), 1 elsewhere."""
    covering = np.ones(N)
    covering[2 * n : 2 * n + m] = gap_covering
    return covering


def _split_rows_numpy(
    J: np.ndarray, b: np.ndarray, mu: np.ndarray, frictional: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Whole-array twin of :func:`_split_rows` for plain Python (numba compiles the loops)."""
    d = J.shape[1]
    return J[:, d - 1, :].copy(), b[:, d - 1].copy(), J[frictional, : d - 1, :], b[frictional, : d - 1], mu[frictional]


@njit(python=_split_rows_numpy)
def _split_rows(
    J: np.ndarray, b: np.ndarray, mu: np.ndarray, frictional: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Normal rows of every contact; tangent rows and mu of the frictional ones (the LCP's blocks)."""
    m, d, n = J.shape
    f = frictional.shape[0]
    Jn = np.ascontiguousarray(J[:, d - 1, :])
    bn = np.ascontiguousarray(b[:, d - 1])
    Jt = np.empty((f, d - 1, n))
    bt = np.empty((f, d - 1))
    mu_f = np.empty(f)
    for a in range(f):
        Jt[a] = J[frictional[a], : d - 1, :]
        bt[a] = b[frictional[a], : d - 1]
        mu_f[a] = mu[frictional[a]]
    return Jn, bn, Jt, bt, mu_f


@njit
def split_lcp_point(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    pivot_tol: float,
    pivots_per_row: int,
) -> tuple[int, np.ndarray]:
    """Lemke on the split-twist LCP with fixed edges (``base`` as in :func:`solve_split_lcp`, no re-alignment).

    Returns Lemke's status and its raw point ``z = [q+ (n), q- (n), cn (m), beta (f K), lam (f)]``
    (edges and slip speeds of the frictional contacts only): what a caller needs to
    rebuild every variable of the polyhedral laws, not just the motion.
    """
    m, d, n = J.shape
    f = frictional.shape[0]
    Jn, bn, Jt, bt, mu_f = _split_rows(J, b, mu, frictional)
    edges = _edges(base, np.zeros(f), d - 1)
    M, qv = _assemble(Jn, Jt, bn, bt, mu_f, g, edges, frictional)
    status, z, _, _ = lemke(M, qv, np.ones(qv.shape[0]), pivots_per_row * qv.shape[0], pivot_tol, 0)
    return status, z


@njit
def split_lcp_points(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    pivot_tol: float,
    pivots_per_row: int,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`split_lcp_point` on each of a stack of problems of one shape (``J`` (N, m, d, n), ``b`` (N, m, d),
    ``mu`` (N, m), ``g`` (N, n); the same ``frictional`` contacts): one compiled call instead of N (a call's
    dispatch costs as much as a small problem's pivots). Returns each status (N,) and raw point (N, len z)."""
    count = J.shape[0]
    n = J.shape[3]
    size = 2 * n + J.shape[1] + frictional.shape[0] * (base.shape[0] + 1)
    statuses = np.empty(count, dtype=np.int64)
    points = np.zeros((count, size))
    for k in range(count):
        status, z = split_lcp_point(J[k], b[k], mu[k], g[k], frictional, base, pivot_tol, pivots_per_row)
        statuses[k] = status
        if z.shape[0] == size:
            points[k] = z
    return statuses, points


def _newton_compiled(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    q: np.ndarray,
    c: np.ndarray,
    depth: float,
    patience: int,
    one_switch: bool,
    mode_tol: float,
    tol: float,
) -> tuple[bool, np.ndarray, np.ndarray]:
    """:func:`_newton` in the extension's C, step for step, to the bit (:func:`exact_newton` calls it where it was built)."""
    return compiled_exact_newton(J, b, mu, g, q, c, depth, patience, one_switch, mode_tol, tol, _NEWTON)


@njit
def _newton(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    q: np.ndarray,
    c: np.ndarray,
    depth: float,
    patience: int,
    one_switch: bool,
    mode_tol: float,
    tol: float,
) -> tuple[bool, np.ndarray, np.ndarray]:
    """The exact 3-D laws with fixed contact modes, by damped Newton steps, from the motion ``(q, c)``.

    Unknowns: twist ``q`` (n), normal force of each closed contact, tangential
    force of each rolling (frictional) one. Equations: equilibrium; closed
    contacts do not move along their normal; rolling ones do not slip. A
    sliding contact's friction is ``-mu cn slip/|slip|``. The modes start as
    those of ``q``, a contact closed where its gap rate is within ``depth`` of
    zero or below (a Lemke point's penetration, :func:`lemke_depth`); a closed contact whose normal force turns negative opens,
    an open one that would penetrate closes and a sliding one that stops rolls,
    and the equations are solved again (a few times at most); such a switch ends
    a round early once ``patience`` iterations have not halved the residual. With
    ``one_switch`` a round switches only the first such contact (in index order),
    the others left to the next round's answer. Returns whether
    a solution kept every mode and inequality (normal forces >= 0, rolling
    forces in their cones, sliding contacts sliding, open ones apart), and it.
    """
    m, d, n = J.shape
    kind = np.zeros(m, dtype=np.int64)  # 0 separating, 1 rolling (frictional), 2 sliding or frictionless
    for i in range(m):
        u_n, speed = _contact_speeds(J, b, q, i)
        if u_n + depth <= mode_tol:
            kind[i] = 1 if mu[i] > 0.0 and speed <= mode_tol else 2
    forces = c.copy()
    for _ in range(8):
        column, size = columns(kind, n, 2)
        x = np.zeros(size)
        x[:n] = q
        for i in range(m):
            if kind[i] > 0:
                x[column[i]] = max(forces[i, 2], 0.0)
            if kind[i] == 1:
                x[column[i] + 1] = forces[i, 0]
                x[column[i] + 2] = forces[i, 1]
        x, norm, forces = _gauss_newton(J, b, mu, g, x, kind, column, n, patience, mode_tol)
        q = x[:n].copy()
        changed = False
        for i in range(m):
            if changed and one_switch:
                break
            switched = _switched_kind(J, b, mu, q, kind, forces, i, mode_tol)
            if switched >= 0:
                kind[i] = switched
                if switched == 0:
                    forces[i, :] = 0.0
                changed = True
        if changed:
            continue
        ok = norm <= tol
        for i in range(m):
            if kind[i] == 1:
                ok = ok and np.sqrt(forces[i, 0] ** 2 + forces[i, 1] ** 2) <= mu[i] * forces[i, 2] * (1.0 + CONE_ROUNDOFF)
        return ok, q, forces
    return False, q, forces


def _contact_speeds_numpy(J: np.ndarray, b: np.ndarray, q: np.ndarray, i: int) -> tuple[float, float]:
    """Whole-array twin of :func:`_contact_speeds` for plain Python (numba compiles the loops)."""
    u = J[i].dot(q) - b[i]
    return u[2], float(np.sqrt(u[0] ** 2 + u[1] ** 2))


@njit(python=_contact_speeds_numpy)
def _contact_speeds(J: np.ndarray, b: np.ndarray, q: np.ndarray, i: int) -> tuple[float, float]:
    """Normal velocity and slip speed of contact ``i`` at twist ``q``."""
    u = -b[i].copy()
    for s in range(3):
        for j in range(q.shape[0]):
            u[s] += J[i, s, j] * q[j]
    return u[2], np.sqrt(u[0] ** 2 + u[1] ** 2)


@njit
def _gauss_newton(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    x: np.ndarray,
    kind: np.ndarray,
    column: np.ndarray,
    n: int,
    patience: int,
    mode_tol: float,
) -> tuple[np.ndarray, float, np.ndarray]:
    """Damped Newton (short least-squares steps where singular; step halving) on the fixed-mode laws, for at most
    :data:`NEWTON_ITERATIONS` iterations, or until ``patience`` of them have not halved the residual while a mode
    switch is due (:func:`_switch_due`: these modes cannot hold, so the round ends early).

    Returns the point, its largest residual and its contact forces (m, 3).
    """
    residual, jacobian, forces = system(J, b, mu, g, x, kind, column, n)
    norm = np.max(np.abs(residual))
    reference, stalled = norm, 0
    for _ in range(NEWTON_ITERATIONS):
        if norm <= NEWTON_STOP:
            break
        step = _newton_step(jacobian, residual)
        t = 1.0
        improved = False
        for _ in range(30):
            trial = x + t * step
            r_trial, j_trial, f_trial = system(J, b, mu, g, trial, kind, column, n)
            n_trial = np.max(np.abs(r_trial))
            if n_trial < norm:
                x, residual, jacobian, forces, norm = trial, r_trial, j_trial, f_trial, n_trial
                improved = True
                break
            t *= 0.5
        if not improved:
            break
        if norm <= 0.5 * reference:
            reference, stalled = norm, 0
            continue
        stalled += 1
        if stalled >= patience and _switch_due(J, b, mu, x[:n], kind, forces, mode_tol):
            break
    return x, norm, forces


@njit
def _switch_due(J: np.ndarray, b: np.ndarray, mu: np.ndarray, q: np.ndarray, kind: np.ndarray, forces: np.ndarray, mode_tol: float) -> bool:
    """Whether :func:`_newton` would switch a contact's mode at the twist ``q`` and ``forces`` (its rules after a round)."""
    due = False
    for i in range(kind.shape[0]):  # a loop, not any() over a generator: numba compiles it
        due = due or _switched_kind(J, b, mu, q, kind, forces, i, mode_tol) >= 0
    return due


@njit
def _switched_kind(
    J: np.ndarray, b: np.ndarray, mu: np.ndarray, q: np.ndarray, kind: np.ndarray, forces: np.ndarray, i: int, mode_tol: float
) -> int:
    """Contact ``i``'s mode after a Newton round at ``q`` and ``forces`` where it must switch, else -1: an open one
    that would penetrate closes, a closed one pulling (normal force < 0) opens, a sliding one that stopped rolls."""
    u_n, speed = _contact_speeds(J, b, q, i)
    if kind[i] == 0 and u_n < 0.0:
        return 1 if mu[i] > 0.0 and speed <= mode_tol else 2
    if kind[i] > 0 and forces[i, 2] < 0.0:
        return 0
    if kind[i] == 2 and mu[i] > 0.0 and speed <= mode_tol:
        return 1
    return -1


def _newton_step_numpy(jacobian: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """Whole-array twin of :func:`_newton_step` for plain Python (numba compiles the loops)."""
    normal = jacobian.T @ jacobian
    gradient = -(jacobian.T @ residual)
    largest = max(0.0, np.max(np.diag(normal))) if residual.shape[0] else 0.0
    normal += NEWTON_DAMPING * (1.0 + largest) * np.eye(residual.shape[0])
    _, step = _linear_solve(normal, gradient)
    return step


@njit(python=_newton_step_numpy)
def _newton_step(jacobian: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """Newton step ``-J^-1 r``, as ``-(J^T J + lam I)^-1 J^T r`` with a tiny ``lam``.

    The damping only matters where ``J`` is singular (indeterminate forces):
    there it picks the short step across the free directions, as least squares would.
    """
    size = residual.shape[0]
    normal = np.zeros((size, size))
    gradient = np.zeros(size)
    largest = 0.0
    for i in range(size):
        for k in range(size):
            gradient[i] -= jacobian[k, i] * residual[k]
            for j in range(i, size):
                normal[i, j] += jacobian[k, i] * jacobian[k, j]
        for j in range(i):  # symmetric: the same products (a b = b a exactly) summed in the same order, so copied
            normal[i, j] = normal[j, i]
        largest = max(largest, normal[i, i])
    for i in range(size):
        normal[i, i] += NEWTON_DAMPING * (1.0 + largest)
    _, step = _linear_solve(normal, gradient)
    return step


def _edges_numpy(base: np.ndarray, offsets: np.ndarray, t: int) -> np.ndarray:
    """Whole-array twin of :func:`_edges` for plain Python (numba compiles the loops)."""
    f, K = offsets.shape[0], base.shape[0]
    if t == 1:
        return np.broadcast_to(base[None, :, None], (f, K, 1)).copy()
    angles = base[None, :] + offsets[:, None]
    return np.stack((np.cos(angles), np.sin(angles)), axis=-1)


@njit(python=_edges_numpy)
def _edges(base: np.ndarray, offsets: np.ndarray, t: int) -> np.ndarray:
    """Edge directions (f, K, t): the 2-D signs, or 3-D angles ``base + offset`` per contact."""
    f, K = offsets.shape[0], base.shape[0]
    edges = np.empty((f, K, t))
    for a in range(f):
        for k in range(K):
            if t == 1:
                edges[a, k, 0] = base[k]
            else:
                edges[a, k, 0] = np.cos(base[k] + offsets[a])
                edges[a, k, 1] = np.sin(base[k] + offsets[a])
    return edges


def _motion_numpy(z: np.ndarray, edges: np.ndarray, frictional: np.ndarray, m: int, d: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Whole-array twin of :func:`_motion` for plain Python (numba compiles the loops)."""
    f, K, t = edges.shape
    q = z[:n] - z[n : 2 * n]
    c = np.zeros((m, d))
    c[:, d - 1] = z[2 * n : 2 * n + m]
    beta = z[2 * n + m : 2 * n + m + f * K].reshape(f, K, 1)
    c[frictional, :t] += (beta * edges).sum(axis=1)
    return q, c


@njit(python=_motion_numpy)
def _motion(z: np.ndarray, edges: np.ndarray, frictional: np.ndarray, m: int, d: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Twist ``q`` (n,) and contact-frame forces ``c`` (m, d) of ``z = [q+, q-, cn, beta, lam]``."""
    f, K, t = edges.shape
    q = z[:n] - z[n : 2 * n]
    c = np.zeros((m, d))
    for i in range(m):
        c[i, d - 1] = z[2 * n + i]
    start = 2 * n + m
    for a in range(f):
        for k in range(K):
            beta = z[start + a * K + k]
            for s in range(t):
                c[frictional[a], s] += beta * edges[a, k, s]
    return q, c


@njit
def _basis_solution(M: np.ndarray, q: np.ndarray, basis: np.ndarray, tol: float, free: int) -> tuple[bool, np.ndarray]:
    """The LCP solution with the given complementary basis (``M_SS z_S = -q_S``), and whether it is feasible (the free
    ``z[:free]`` may be negative)."""
    N = q.shape[0]
    basic = np.empty(N, dtype=np.int64)
    count = 0
    for i in range(N):
        if N <= basis[i] < 2 * N:
            basic[count] = basis[i] - N
            count += 1
    z = np.zeros(N)
    if count:
        A = np.empty((count, count))
        rhs = np.empty(count)
        for r in range(count):
            rhs[r] = -q[basic[r]]
            for s in range(count):
                A[r, s] = M[basic[r], basic[s]]
        regular, solution = _linear_solve(A, rhs)
        if not regular:  # the basis does not carry over
            return False, z
        for r in range(count):
            if basic[r] < free:
                z[basic[r]] = solution[r]
                continue
            if solution[r] < -tol:
                return False, z
            z[basic[r]] = max(solution[r], 0.0)
    for i in range(N):
        w = q[i]
        for j in range(N):
            w += M[i, j] * z[j]
        if w < -tol:
            return False, z
    return True, z


def _linear_solve_numpy(A: np.ndarray, rhs: np.ndarray) -> tuple[bool, np.ndarray]:
    """Twin of :func:`_linear_solve` for plain Python: LAPACK's ``dgesv`` (the same partial pivoting, in one call).

    Singular exactly when the kernel says so: when a pivot (a diagonal entry of ``U``) is within
    the kernel's relative threshold of zero.
    """
    n = rhs.shape[0]
    if n == 0:
        return True, rhs.copy()
    lu, _, x, info = dgesv(A, rhs)
    tiny = 1e-14 * max(np.abs(A).max(), 1e-300)
    if info != 0 or np.abs(np.diagonal(lu)).min() <= tiny:
        return False, rhs.copy()
    return True, x


@njit(python=_linear_solve_numpy)
def _linear_solve(A: np.ndarray, rhs: np.ndarray) -> tuple[bool, np.ndarray]:
    """``A x = rhs`` by Gaussian elimination with partial pivoting; False when ``A`` is singular.

    Small dense systems; written out (rather than ``np.linalg.solve``) so that
    the kernel compiles quickly and needs no exception handling.
    """
    n = rhs.shape[0]
    U = A.copy()
    x = rhs.copy()
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(U[i, j]))
    tiny = 1e-14 * max(scale, 1e-300)
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(U[i, k]) > abs(U[p, k]):
                p = i
        if abs(U[p, k]) <= tiny:
            return False, x
        if p != k:
            for j in range(n):
                U[k, j], U[p, j] = U[p, j], U[k, j]
            x[k], x[p] = x[p], x[k]
        for i in range(k + 1, n):
            factor = U[i, k] / U[k, k]
            if factor != 0.0:
                for j in range(k, n):
                    U[i, j] -= factor * U[k, j]
                x[i] -= factor * x[k]
    for k in range(n - 1, -1, -1):
        total = x[k]
        for j in range(k + 1, n):
            total -= U[k, j] * x[j]
        x[k] = total / U[k, k]
    return True, x


def _assemble_numpy(
    Jn: np.ndarray,
    Jt: np.ndarray,
    bn: np.ndarray,
    bt: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    edges: np.ndarray,
    frictional: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Whole-array twin of :func:`_assemble` for plain Python: every block in one step (numba compiles the loops)."""
    m, n = Jn.shape
    f, K, _ = edges.shape
    N = 2 * n + m + f * K + f
    cn0 = 2 * n
    b0 = cn0 + m
    l0 = b0 + f * K
    M = np.zeros((N, N))
    q = np.zeros(N)
    q[:n] = -g
    q[n : 2 * n] = g
    q[cn0:b0] = -bn
    rows = Jn
    if f:  # frictionless problems (the LP's small ones) skip the friction blocks' fixed cost
        q[b0:l0] = -np.matmul(edges, bt[:, :, None]).ravel()
        rows = np.concatenate((Jn, np.matmul(edges, Jt).reshape(f * K, n)))  # normal rows, then each edge's slip rows
    M[cn0:l0, :n] = rows
    M[cn0:l0, n : 2 * n] = -rows
    M[:n, cn0:l0] = -rows.T
    M[n : 2 * n, cn0:l0] = rows.T
    if not f:
        return M, q
    edge_rows = np.arange(b0, l0)
    slack_cols = l0 + np.repeat(np.arange(f), K)
    M[edge_rows, slack_cols] = 1.0
    M[slack_cols, edge_rows] = -1.0
    M[l0 + np.arange(f), cn0 + frictional] = mu
    return M, q


@njit(python=_assemble_numpy)
def _assemble(
    Jn: np.ndarray,
    Jt: np.ndarray,
    bn: np.ndarray,
    bt: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    edges: np.ndarray,
    frictional: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """LCP matrix ``M`` (N, N) and vector ``q`` (N,) of the split-twist polyhedral laws.

    ``Jn`` (m, n), ``bn`` (m,) for every contact; ``Jt`` (f, d-1, n), ``bt``
    (f, d-1), ``mu`` (f,), ``edges`` (f, K, d-1) for the frictional ones, whose
    contact indices are ``frictional`` (f,); ``g`` (n,) the load. Unknowns
    ``z = [q+ (n), q- (n), cn (m), beta (f K), lam (f)]``.
    """
    m, n = Jn.shape
    f, K, t = edges.shape
    N = 2 * n + m + f * K + f
    cn0 = 2 * n
    b0 = cn0 + m
    l0 = b0 + f * K
    M = np.zeros((N, N))
    q = np.zeros(N)
    for i in range(n):
        q[i] = -g[i]
        q[n + i] = g[i]
    for j in range(m):
        q[cn0 + j] = -bn[j]
        for i in range(n):
            a = Jn[j, i]
            M[cn0 + j, i] = a
            M[cn0 + j, n + i] = -a
            M[i, cn0 + j] = -a
            M[n + i, cn0 + j] = a
    for a in range(f):
        row_l = l0 + a
        M[row_l, cn0 + frictional[a]] = mu[a]
        for k in range(K):
            row = b0 + a * K + k
            rhs = 0.0
            for s in range(t):
                rhs += edges[a, k, s] * bt[a, s]
            q[row] = -rhs
            for i in range(n):
                value = 0.0
                for s in range(t):
                    value += edges[a, k, s] * Jt[a, s, i]
                M[row, i] = value
                M[row, n + i] = -value
                M[i, row] = -value
                M[n + i, row] = value
            M[row, row_l] = 1.0
            M[row_l, row] = -1.0
    return M, q
