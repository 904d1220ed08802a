"""Cheap certificates: a verified first motion for the search, and uniqueness proven by kinematics alone.

**A verified first motion** (:func:`seed_point`). Lemke's method solves the
polyhedral LCP with the search's own edges in microseconds; its point is
rebuilt in the search's variables and every law of the form (equilibrium,
signs, complementarity) is checked here in numpy before it is used. The
certified search then starts from it, so its first mixed-integer solve (find a
motion) is skipped and only the proof that no other motion exists remains.
A point that fails the check is dropped: the search starts from nothing, as before.

**Kinematic uniqueness** (:func:`kinematically_unique`). Whatever the friction
model, every motion keeps each contact from penetrating: ``Jn q >= bn``. When
that set of twists is a single point, the motion is unique before any force
is looked at. The proof is a bound, not a numerical test (Gordan's theorem,
made quantitative). Let ``A`` be the rows of ``Jn`` closed at the found twist
``q*`` (``k`` rows, full column rank, smallest singular value ``s``) and
``t = bn_A - A q*`` (round-off). Suppose ``y > 0`` with ``A^T y = e`` (``e`` ~ 0).
For any admissible twist ``q = q* + d``: ``v = A d - t >= 0`` and
``y.v = e.d - y.t``, so every ``v_i <= (|e| |d| + |y.t|) / y_i``, hence
``|v| <= (|e| |d| + |y.t|) |1/y|``; and ``|d| <= (|v| + |t|) / s``. Together::

    |d| (1 - |e| |1/y| / s) <= (|y.t| |1/y| + |t|) / s

which bounds ``|d|`` once the bracket is positive (2-norms throughout). A
radius below half of ``SAME_TWIST`` means every motion's twist is ``q*``
within the tolerance the search itself uses to call two twists the same, so
the complete search would find one single motion there. The same bound with
every row loosened by the LP solvers' feasibility tolerance must also stay
within ``DISTINCT_TWIST`` (the search's exclusion box): nothing the
mixed-integer search could accept within its tolerance lies outside it either.
"""

from __future__ import annotations

import numpy as np

from ...laws import Problem, RawMotion
from ...laws.polyhedral import LCPForm
from ...tolerances import (
    DISTINCT_TWIST,
    LP_FEASIBILITY,
    MODE_SPEED,
    MOTION_RANK,
    PIVOT,
    SAME_TWIST,
    ZERO,
)
from ..numerics.lcp import PIVOTS_PER_ROW, LemkeInputs, lemke_motion, split_lcp_point
from ..numerics.lemke import SOLUTION

__all__ = ["seed_point", "lemke_point", "satisfies_form", "exact_motion", "kinematically_unique", "kinematic_radius"]


def seed_point(form: LCPForm) -> np.ndarray | None:
    """A point ``x = [q, cn, beta, lam]`` satisfying every law of ``form`` (checked here), or None.

    ``form`` must use unrotated edges (:func:`~quasistatic.laws.polyhedral.aligned_edges` without slips),
    as the certified search does: Lemke's kernel builds the same ones.
    """
    status, x = lemke_point(form)
    return x if status == SOLUTION and satisfies_form(form, x) else None


def lemke_point(form: LCPForm) -> tuple[int, np.ndarray]:
    """Lemke's status on ``form``'s LCP (unrotated edges, as :func:`seed_point`) and its last point as a point
    ``[q, cn, beta, lam]`` of the form: a solution, or where the path ended (no law checked)."""
    problem = form.problem
    K = form.edges.shape[1]
    data = problem.derived("fast", LemkeInputs)  # the fast path's contiguous copies, kept with the problem
    base = np.array([1.0, -1.0]) if problem.dimension == 2 else 2.0 * np.pi * np.arange(K) / K
    status, z = split_lcp_point(data.J, data.b, data.mu, data.g, data.frictional, base, PIVOT, PIVOTS_PER_ROW)
    return int(status), _form_point(form, z, data.frictional)


def exact_motion(problem: Problem) -> RawMotion | None:
    """A motion of the exact 3-D laws by the fast path's kernel (re-aligned pyramid, then Newton), or None.

    Only a candidate: the caller proves it unique, and the audit checks its laws.
    """
    status, _, q, c, _, _ = lemke_motion(problem)
    return RawMotion(q, c) if status == SOLUTION else None


def _form_point(form: LCPForm, z: np.ndarray, frictional: np.ndarray) -> np.ndarray:
    """The kernel's ``[q+, q-, cn, beta, lam]`` (frictional contacts only) as the form's ``[q, cn, beta, lam]``."""
    n, (m, K) = form.n_q, form.edges.shape[:2]
    f = frictional.size
    q = z[:n] - z[n : 2 * n]
    beta = np.zeros((m, K))
    beta[frictional] = z[2 * n + m : 2 * n + m + f * K].reshape(f, K)
    lam = np.zeros(m)
    lam[frictional] = z[2 * n + m + f * K :]
    # A frictionless contact's slip speed is free of its force (beta = 0): the least one its edges accept.
    frictionless = np.ones(m, dtype=bool)
    frictionless[frictional] = False
    if frictionless.any():  # (a mask, not np.setdiff1d, and no np.r_: each costs more than the arithmetic here)
        slip_along = (form.W[m : m + m * K, :n] @ q - form.r[m : m + m * K]).reshape(m, K)
        lam[frictionless] = np.maximum(0.0, (-slip_along[frictionless]).max(axis=1, initial=0.0))
    return np.concatenate([q, z[2 * n : 2 * n + m], beta.ravel(), lam])


def satisfies_form(form: LCPForm, x: np.ndarray) -> bool:
    """Equilibrium, signs and complementarity of ``x`` hold to ``ZERO`` (scene-relative)."""
    # (array methods, not np.max and np.min: their dispatch costs more than these few-entry reductions)
    equilibrium = np.abs(form.E_eq @ x - form.e_eq).max(initial=0.0)
    if not equilibrium <= ZERO:
        return False
    w = form.W @ x - form.r
    pairs = x[form.pair_cols]
    signs = min(pairs.min(initial=0.0), w.min(initial=0.0))
    complementarity = np.minimum(np.abs(pairs), np.abs(w)).max(initial=0.0)
    return bool(signs >= -ZERO and complementarity <= ZERO)


def kinematically_unique(problem: Problem, q: np.ndarray) -> bool:
    """True when every twist the contacts allow (``Jn q' >= bn``) is ``q`` itself, proven by the bound above.

    Both radii are checked: the exact rows (within half ``SAME_TWIST``) and the rows loosened by
    ``LP_FEASIBILITY`` (within ``DISTINCT_TWIST``), so the complete search would agree.
    """
    gap = problem.Jn @ q - problem.bn
    closed = np.abs(gap) <= MODE_SPEED
    A, t = problem.Jn[closed], -gap[closed]
    bound = _GordanBound.of(A)  # one SVD serves both radii
    if bound is None:
        return False
    return bound.radius(t) <= 0.5 * SAME_TWIST and bound.radius(np.abs(t) + LP_FEASIBILITY) <= DISTINCT_TWIST


def kinematic_radius(A: np.ndarray, t: np.ndarray) -> float:
    """Largest ``|d|`` (2-norm) with ``A d >= t``, bounded by Gordan multipliers; ``inf`` when no bound is found.

    ``A`` (k, n): rows of the normal Jacobian; ``t`` (k,): small right-hand sides.
    """
    bound = _GordanBound.of(A)
    return np.inf if bound is None else bound.radius(t)


class _GordanBound:
    """What the bound reads of ``A`` alone: its smallest singular value ``s``, the multipliers ``y`` (largest 1),
    ``|1/y|`` and the bracket ``1 - |A^T y| |1/y| / s``; :meth:`radius` adds the right-hand sides."""

    def __init__(self, s: float, y: np.ndarray, inverse: float, bracket: float) -> None:
        self.s, self.y, self.inverse, self.bracket = s, y, inverse, bracket

    @classmethod
    def of(cls, A: np.ndarray) -> _GordanBound | None:
        """None when ``A`` bounds nothing (too few rows, rank deficient, no positive multipliers, too far from ``A^T y = 0``)."""
        k, n = A.shape
        if k <= n:  # a pointed cone needs more rows than unknowns
            return None
        u, sigma, _ = np.linalg.svd(A, full_matrices=True)
        s = float(sigma[-1])
        if s <= MOTION_RANK:
            return None
        null = u[:, n:]  # left null space of A: every y with A^T y = 0
        y = null @ (null.T @ np.ones(k))  # the all-ones vector's part in it; Gordan multipliers when positive
        top = float(np.max(y, initial=0.0))
        if top <= 0.0 or float(np.min(y)) <= MOTION_RANK * top:
            return None
        y = y / top
        inverse = float(np.linalg.norm(1.0 / y))
        e = float(np.linalg.norm(A.T @ y))
        bracket = 1.0 - e * inverse / s
        if bracket < 0.5:  # the multipliers are too far from A^T y = 0 to bound anything
            return None
        return cls(s, y, inverse, bracket)

    def radius(self, t: np.ndarray) -> float:
        """The bound on ``|d|`` for right-hand sides ``t``."""
        return float((abs(float(self.y @ t)) * self.inverse + float(np.linalg.norm(t))) / (self.s * self.bracket))
