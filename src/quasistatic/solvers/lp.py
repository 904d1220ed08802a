"""Frictionless forward object motion problem: one LP (paper section 2.2), by Lemke's method or HiGHS.

Velocity formulation (eq. 25, 7):  min -g.q  s.t.  Jn q >= bn.
Its duals are the normal forces; the dual LP is the force formulation
(eq. 12, 26, 27):  max bn.c  s.t.  Jn^T c + g = 0, c >= 0, and strong
duality is the power balance (eq. 19): mover power = potential-energy gain.

Small problems: the optimality conditions of this LP pair are exactly the
frictionless contact laws, a monotone LCP (the fast path's, without edges),
and Lemke's method finds a primal-dual optimal pair in a few microseconds
where a call to HiGHS costs a few hundred. Any optimal pair serves: the
primal optimal face is the same for every dual optimum, so the uniqueness
and force-range analysis below gives the same answer. When Lemke's method
ends on a ray (the LP is infeasible or unbounded) or its pair does not
check out, HiGHS solves the LP and the verdict comes from it as before.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import scipy.sparse as sp

from ..compiled import HAVE_KERNELS, analyse_frictionless
from ..jit import njit
from ..laws import Problem, RawMotion
from ..solution import Certificate, CertificateKind, Diagnosis
from ..tolerances import FORCE_RANK, JACOBI_ORTHOGONAL, LEMKE_PAIR, LP_FEASIBILITY, MODE_SPEED, MOTION_RANK, PIVOT, ZERO
from .certify.diagnose import MESSAGES, kinematic_certificate
from .numerics.forces import FrictionlessForces
from .numerics.highs import INF, solve_lp
from .numerics.lcp import PIVOTS_PER_ROW, solve_split_lcp
from .numerics.lemke import SOLUTION
from .numerics.ranges import cone_is_trivial, twist_extremes, value_ranges
from .numerics.rank import full_column_rank
from .result import BackendResult, Options, Range

__all__ = ["solve_frictionless"]


LEMKE_MAX_ROWS = 200  # largest LCP (2 twist entries per dof + contacts) solved by Lemke's method first
JACOBI_MAX = 24  # largest min(rows, cols) whose rank is found by Jacobi rotations (numerics.rank beyond)


def solve_frictionless(problem: Problem, options: Options) -> BackendResult:
    """Solve with every contact frictionless (mu ignored)."""
    data = problem.derived("lp", _Frictionless)
    Jn, bn, g = data.Jn, data.bn, data.g
    m = problem.n_contacts
    q = c = analysis = None
    if data.lemke:
        status, q, c, analysis = _lemke_pair(
            data.J, data.b, data.mu, g, data.frictional, data.base, Jn, bn, MODE_SPEED, PIVOT, PIVOTS_PER_ROW, ZERO, MOTION_RANK, FORCE_RANK
        )
        if status != SOLUTION or not analysis[0] <= LEMKE_PAIR:  # no pair, or it misses an optimality condition
            analysis = None  # HiGHS decides
    if analysis is None:
        lp = solve_lp(-g, Jn, bn, np.full(m, INF))
        if lp.status != "optimal":
            return _verdict(problem, lp.status)
        q, forces = lp.x, np.maximum(lp.row_dual, 0.0)
        analysis = _analyse(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        c = np.zeros((m, problem.dimension))
        c[:, -1] = forces
    assert q is not None and c is not None
    _, slack, support, tight, closed, motion_known, forces_known = analysis
    motion_unique = motion_known > 0 if motion_known >= 0 else full_column_rank(sp.csr_matrix(Jn[support]), MOTION_RANK)
    # {d : Jn_S d = 0, Jn_T d >= 0} is only the origin at once when Jn_S has full column rank.
    if not motion_unique and not cone_is_trivial(Jn[support], Jn[tight]):
        extremes, free = twist_extremes(q.size, Jn[support], bn[support], Jn[~support], bn[~support])
        # every dual optimal c is complementary to every primal optimum: the same forces hold at each extreme
        motion = RawMotion(q, c, tuple(extremes), bool(free), free, extreme_forces=(c,) * len(extremes))
        return BackendResult("ambiguous", _ambiguous_message(bool(free)), (motion,))
    forces_unique = forces_known > 0 if forces_known >= 0 else full_column_rank(sp.csr_matrix(Jn[closed]).T, FORCE_RANK)
    if forces_unique:
        return BackendResult("solved", "solved: one motion with unique contact forces", (RawMotion(q, c),))
    # The ranges cost two LPs per closed contact (most of a solve): worked out only when first read.
    consistent = FrictionlessForces(Jn, g, closed, problem.dimension)
    motion = RawMotion(q, c, lazy_ranges=partial(_force_ranges, Jn, g, closed), force_set=consistent)
    return BackendResult("solved", "solved: one motion; the contact forces are indeterminate", (motion,))


class _Frictionless:
    """What :func:`solve_frictionless` derives from a problem once: contiguous data and the LCP's inputs."""

    def __init__(self, problem: Problem) -> None:
        self.J, self.b, self.g = (np.ascontiguousarray(a, dtype=float) for a in (problem.J, problem.b, problem.g))
        self.Jn = np.ascontiguousarray(problem.Jn, dtype=float)
        self.bn = np.ascontiguousarray(problem.bn, dtype=float)
        self.mu = np.zeros(problem.n_contacts)  # no edges: the LP pair's optimality conditions
        self.frictional = np.zeros(0, dtype=np.int64)
        self.base = np.zeros(0)
        self.lemke = 2 * problem.n_dof + problem.n_contacts <= LEMKE_MAX_ROWS


@njit
def _lemke_pair(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    Jn: np.ndarray,
    bn: np.ndarray,
    mode_tol: float,
    pivot_tol: float,
    pivots_per_row: int,
    zero: float,
    motion_rank: float,
    force_rank: float,
) -> tuple[int, np.ndarray, np.ndarray, tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]]:
    """Lemke's method on the LP pair's optimality conditions (the fast kernel, no edges), then :func:`_analyse`.

    Returns Lemke's status, the twist, the contact-frame forces (normal only;
    negative round-off clipped) and the analysis of the pair, in one compiled call.
    """
    status, _, q, c, _, _ = solve_split_lcp(
        J, b, mu, g, frictional, base, False, False, 1.0, 0, 0.0, mode_tol, pivot_tol, 0.0, pivots_per_row
    )
    last = c.shape[1] - 1
    normal = c[:, last].copy()
    analysis = _analyse(Jn, bn, g, q, normal, zero, motion_rank, force_rank)
    c[:, last] = np.maximum(normal, 0.0)  # whole-array: the same body runs as plain Python without numba
    return status, q, c, analysis


def _analyse_numpy(
    Jn: np.ndarray, bn: np.ndarray, g: np.ndarray, q: np.ndarray, forces: np.ndarray, zero: float, motion_rank: float, force_rank: float
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]:
    """:func:`_analyse` in whole-array numpy calls (what runs without numba): the same verdicts, residuals to round-off."""
    n = Jn.shape[1]
    finite = bool(np.isfinite(q).all() and np.isfinite(forces).all())
    if finite:
        slack = Jn @ q - bn
    else:
        with np.errstate(invalid="ignore", over="ignore"):  # a pair that is not finite is reported as such, not warned about
            slack = Jn @ q - bn
    support = forces > zero
    closed = slack <= zero
    tight = closed & ~support
    if not (finite and np.isfinite(slack).all()):
        return np.inf, slack, support, tight, closed, 0, 0
    imbalance = g + Jn.T @ forces
    residual = float(np.concatenate((-slack, -forces, np.abs(forces * slack), np.abs(imbalance))).max(initial=0.0))
    k = int(np.count_nonzero(closed))
    forces_unique = 1 if k == 0 else (0 if k > n else _full_rank(Jn[closed], force_rank, k))
    n_support = int(np.count_nonzero(support))
    if forces_unique == 1 and not np.any(support & ~closed):  # supporting rows among independent closed ones
        motion_unique = int(n_support == n)
    else:
        motion_unique = 0 if n_support < n else _full_rank(Jn[support], motion_rank, n)
    return residual, slack, support, tight, closed, motion_unique, forces_unique


def _analyse_compiled(
    Jn: np.ndarray, bn: np.ndarray, g: np.ndarray, q: np.ndarray, forces: np.ndarray, zero: float, motion_rank: float, force_rank: float
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]:
    """:func:`_analyse` in C (what runs without numba where the ``_kernels`` extension was built): its loops and rotations."""
    return analyse_frictionless(Jn, bn, g, q, forces, zero, motion_rank, force_rank, JACOBI_ORTHOGONAL, JACOBI_MAX)


@njit(python=_analyse_compiled if HAVE_KERNELS else _analyse_numpy)
def _analyse(
    Jn: np.ndarray, bn: np.ndarray, g: np.ndarray, q: np.ndarray, forces: np.ndarray, zero: float, motion_rank: float, force_rank: float
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]:
    """What the verdict needs of a primal-dual pair ``(q, forces)``.

    Returns the largest violation of the optimality conditions (primal and dual
    feasibility, complementarity; infinite when a value is not finite), the
    slacks ``Jn q - bn``, the masks of supporting (force > ``zero``), tight but
    unloaded, and closed (slack <= ``zero``) contacts, whether the supporting
    normals have full column rank (singular values > ``motion_rank``, as
    :func:`.numerics.ranges.null_space`: then the motion is unique) and whether the closed
    ones are independent (singular values > ``force_rank``: then the forces are
    unique), each 1 (yes), 0 (no) or -1 (a matrix too large for Jacobi
    rotations: the caller decides with a sparse test). One SVD at most in the
    usual case: independent closed normals make their supporting subset independent too.
    """
    m, n = Jn.shape
    slack = np.empty(m)
    residual = 0.0
    for i in range(m):
        s = -bn[i]
        for j in range(n):
            s += Jn[i, j] * q[j]
        slack[i] = s
        residual = max(residual, -s, -forces[i], abs(forces[i] * s))
    for j in range(n):
        e = g[j]
        for i in range(m):
            e += Jn[i, j] * forces[i]
        residual = max(residual, abs(e))
    support = forces > zero
    closed = slack <= zero
    tight = closed & ~support
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(forces)) and np.all(np.isfinite(slack))):
        return np.inf, slack, support, tight, closed, 0, 0
    k = int(np.sum(closed))
    forces_unique = 1 if k == 0 else (0 if k > n else _full_rank(Jn[closed], force_rank, k))
    n_support = int(np.sum(support))
    if forces_unique == 1 and not np.any(support & ~closed):  # supporting rows among independent closed ones
        motion_unique = int(n_support == n)
    else:
        motion_unique = 0 if n_support < n else _full_rank(Jn[support], motion_rank, n)
    return residual, slack, support, tight, closed, motion_unique, forces_unique


@njit
def _full_rank(A: np.ndarray, tol: float, rank: int) -> int:
    """1 when ``A`` has ``rank`` singular values above ``tol`` (absolute: the data are scene-relative), else 0;
    -1 when ``A`` is too large for Jacobi rotations (O(k^3) a sweep, and LAPACK's time depends on its threads)."""
    if A.shape[0] == 0 or A.shape[1] == 0:
        return int(rank == 0)
    if min(A.shape) > JACOBI_MAX:
        return -1
    return int(np.sum(_singular_values(A) > tol) == rank)


def _singular_values_numpy(A: np.ndarray) -> np.ndarray:
    """:func:`_singular_values` by LAPACK (what runs without numba: one call, where the rotations in Python loops cost
    milliseconds); sorted, largest first. Below ``JACOBI_MAX`` columns OpenBLAS runs it on one thread whatever its setting."""
    return np.linalg.svd(A, compute_uv=False)


@njit(python=_singular_values_numpy)
def _singular_values(A: np.ndarray) -> np.ndarray:
    """Singular values of a small matrix by one-sided Jacobi rotations (Hestenes), unsorted.

    The columns of ``A`` (or of ``A^T``, whichever has fewer) are rotated in
    pairs until every pair is orthogonal to working precision; their norms are
    then the singular values, each to high relative accuracy (Demmel & Veselic
    1992). For the few-by-few matrices here this is several times cheaper
    than a LAPACK call through its wrappers.
    """
    W = A.copy() if A.shape[0] >= A.shape[1] else A.T.copy()
    rows, cols = W.shape
    for _ in range(60):
        rotated = False
        for p in range(cols - 1):
            for q in range(p + 1, cols):
                alpha = beta = gamma = 0.0
                for i in range(rows):
                    alpha += W[i, p] * W[i, p]
                    beta += W[i, q] * W[i, q]
                    gamma += W[i, p] * W[i, q]
                if gamma == 0.0 or abs(gamma) <= JACOBI_ORTHOGONAL * np.sqrt(alpha * beta):
                    continue
                rotated = True
                # tan of the rotation, sign(z) / (|z| + sqrt(1 + z^2)) with z = (beta - alpha) / (2 gamma), times 2|gamma|
                # above and below: a column rotated to nearly zero (a rank-deficient A) makes z ~ 1e165, and z^2
                # overflowed (a numpy warning without numba); this form divides by at least 2|gamma| and overflows nowhere.
                diff = beta - alpha
                sign = 1.0 if diff == 0.0 or (diff > 0.0) == (gamma > 0.0) else -1.0
                t = sign * 2.0 * abs(gamma) / (abs(diff) + np.hypot(2.0 * gamma, diff))
                cos = 1.0 / np.sqrt(1.0 + t * t)
                sin = cos * t
                for i in range(rows):
                    wp, wq = W[i, p], W[i, q]
                    W[i, p] = cos * wp - sin * wq
                    W[i, q] = sin * wp + cos * wq
        if not rotated:
            break
    sigma = np.empty(cols)
    for j in range(cols):
        total = 0.0
        for i in range(rows):
            total += W[i, j] * W[i, j]
        sigma[j] = np.sqrt(total)
    return sigma


def _force_ranges(Jn: np.ndarray, g: np.ndarray, closed: np.ndarray) -> tuple[Range, ...]:
    """Normal-force ranges over the dual optimal face of a unique motion whose forces are not unique.

    Why "not unique" is decided without these LPs, by the rank of the closed
    contacts' normals alone: the forces of the motion ``q`` are the dual
    optimal face ``F = {c >= 0 : Jn^T c = -g, c_i = 0 where contact i is open}``.
    By Goldman and Tucker's strict complementarity a primal-dual optimal pair
    exists with ``slack_i + c_i > 0`` for every i, so a contact closed at every
    primal optimum carries force at some point of ``F``; with the motion
    unique, every contact closed at ``q`` does. Take ``c*`` in the relative
    interior of ``F``: it is positive on every closed contact, so ``c* + t z``
    stays in ``F`` for small ``|t|`` and any ``z`` with ``Jn_C^T z = 0``
    supported on the closed set ``C``, and ``F``'s dimension is
    ``|C| - rank(Jn_C)``. So some range has positive width exactly when the
    closed normals are dependent (``tests/test_frictionless.py`` checks the two
    agree on random scenes).
    """
    columns = np.flatnonzero(closed)
    closed_ranges = iter(value_ranges(sp.csr_matrix(Jn[closed]).T, -g, np.arange(columns.size), np.zeros(columns.size)))
    return tuple(next(closed_ranges) if is_closed else (0.0, 0.0) for is_closed in closed.tolist())


def _verdict(problem: Problem, status: str) -> BackendResult:
    """Jammed or unstable, each confirmed by a checked certificate."""
    Jn, g = problem.Jn, problem.g
    m, n = Jn.shape
    multipliers = kinematic_certificate(problem)
    if multipliers is not None:
        certificate = Certificate(CertificateKind.FARKAS, "kinematic (Farkas multipliers)", tuple(multipliers.tolist()))
        return BackendResult("jammed", MESSAGES[Diagnosis.KINEMATIC], diagnosis=Diagnosis.KINEMATIC, certificate=certificate)
    # Unstable: a twist d with Jn d >= 0 and g.d > 0 does unbounded work; box |d| <= 1 keeps the LP bounded.
    ray = solve_lp(g, Jn, np.zeros(m), np.full(m, INF), np.full(n, -1.0), np.full(n, 1.0), maximize=True)
    if ray.status == "optimal" and ray.objective > LP_FEASIBILITY and np.all(Jn @ ray.x >= -LP_FEASIBILITY * ray.objective):
        # In physical units (v, omega per body, in scene order), scaled to a unit largest entry: a direction, not a speed.
        units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
        physical = ray.x * units
        direction = physical / np.max(np.abs(physical))
        text = "a twist along which the load does unbounded work (v, omega of each body, largest entry 1)"
        certificate = Certificate(CertificateKind.RAY, text, tuple(direction.tolist()))
        return BackendResult("unstable", _UNSTABLE_RAY, diagnosis=Diagnosis.NO_EQUILIBRIUM, certificate=certificate)
    return BackendResult("failed", f"failed: HiGHS reported {status} but no certificate could be checked")


_UNSTABLE_RAY = (
    "unstable: no quasi-static equilibrium exists (the load can do unbounded work), so the "
    "object falls or accelerates; add support or friction"
)


def _ambiguous_message(unbounded: bool) -> str:
    extent = "unbounded" if unbounded else "bounded"
    return (
        f"ambiguous: an {extent} continuum of motions satisfies the laws "
        "(frictionless contacts leave it undetermined); its extreme motions are listed"
    )
