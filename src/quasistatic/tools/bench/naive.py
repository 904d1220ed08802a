"""Naive dense baselines through ``scipy.optimize.linprog``, for the benchmark only.

These are what one writes in an afternoon without this library: dense
matrices, one ``linprog`` call per LP, no warm starts, no certificates.

- Frictionless (any dimension): the velocity LP of the paper,
  ``min -g.q  s.t.  Jn q >= bn``; its duals are the normal forces. It reports
  ``solved`` for any optimum (it does not check whether the motion or the
  forces are unique), ``jammed`` when the LP is infeasible and ``unstable``
  when it is unbounded.
- Frictional 2-D (exact cone = two edges): brute-force enumeration of the
  4^m contact-mode patterns (separating, rolling, sliding either way), one
  feasibility LP each. Sound and complete for the motions at the LPs'
  vertices: several distinct motions give ``ambiguous``; none gives
  ``unstable`` when no equilibrium exists within the cones, else ``jammed``.
  It does not detect a continuum inside one pattern.
- Frictional 3-D: none (the exact cone is not polyhedral; a sound dense
  formulation is the certified search itself).

Results are in scene-relative units, like a backend's; :func:`to_solution`
audits them through the library's own audit (outside the timed region).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from ...check import DEFAULT_TOLERANCE
from ...laws import Problem, RawMotion
from ...solution import Solution, Status
from ...solve import audited_raw_motion

__all__ = ["NaiveResult", "naive_applicable", "solve_naive", "to_solution", "MAX_ENUMERATED_CONTACTS"]

MAX_ENUMERATED_CONTACTS = 5  # 4^5 = 1024 LPs (seconds) per solve; 4^6 takes ~10 s, 4^8 minutes
_DISTINCT = 1e-6  # scene-relative twist difference between two distinct motions


@dataclass(frozen=True)
class NaiveResult:
    """Status and motions (scene-relative) of a naive solve."""

    status: Status
    motions: tuple[RawMotion, ...] = ()


def naive_applicable(problem: Problem) -> str | None:
    """None when a naive baseline exists for this problem, else the reason it does not."""
    if problem.is_frictionless:
        return None
    if problem.dimension == 3:
        return "no naive dense baseline for frictional 3-D (the exact cone is not an LP)"
    if problem.n_contacts > MAX_ENUMERATED_CONTACTS:
        return f"mode enumeration needs 4^{problem.n_contacts} LPs (capped at {MAX_ENUMERATED_CONTACTS} contacts)"
    return None


def solve_naive(problem: Problem) -> NaiveResult:
    """The naive answer: the frictionless velocity LP, or 2-D mode enumeration."""
    reason = naive_applicable(problem)
    if reason is not None:
        raise ValueError(reason)
    return _frictionless(problem) if problem.is_frictionless else _enumerate_2d(problem)


def to_solution(problem: Problem, result: NaiveResult, tolerance: float = DEFAULT_TOLERANCE) -> Solution:
    """A Solution with each motion audited on the original scene (as ``solve`` does)."""
    motions = tuple(audited_raw_motion(problem, raw, tolerance) for raw in result.motions)
    status: Status = result.status
    if any(not m.audit.passed for m in motions):
        status = "failed"
    return Solution(
        status,
        f"{result.status} (naive scipy baseline)",
        "scipy-dense",
        str(problem.friction),
        motion=motions[0] if motions else None,
        solutions=motions if result.status == "ambiguous" else (),
    )


def _frictionless(problem: Problem) -> NaiveResult:
    Jn, bn, g = problem.Jn, problem.bn, problem.g
    res = linprog(-g, A_ub=-Jn, b_ub=-bn, bounds=(None, None), method="highs")
    if res.status == 2:
        return NaiveResult("jammed")
    if res.status == 3:
        return NaiveResult("unstable")
    if res.status != 0:
        return NaiveResult("failed")
    c = np.zeros((problem.n_contacts, problem.dimension))
    c[:, -1] = np.maximum(-res.ineqlin.marginals, 0.0)  # duals of Jn q >= bn: the normal forces
    return NaiveResult("solved", (RawMotion(np.asarray(res.x), c),))


def _enumerate_2d(problem: Problem) -> NaiveResult:
    """Every contact-mode pattern, one dense feasibility LP each."""
    m, n = problem.n_contacts, problem.n_dof
    J, b, mu = problem.J, problem.b, problem.mu
    # Variables: q (n, free), then per contact (c_t, c_n).
    equilibrium = np.hstack([np.zeros((n, n)), np.concatenate([J[i].T for i in range(m)], axis=1)])
    bounds = [(None, None)] * n + [(None, None), (0.0, None)] * m
    motions: list[RawMotion] = []
    for pattern in itertools.product(range(4), repeat=m):
        eq_rows, eq_rhs, ub_rows, ub_rhs = [equilibrium], [-problem.g], [], []
        for i, mode in enumerate(pattern):
            t, nrm = n + 2 * i, n + 2 * i + 1
            vel = np.zeros((2, n + 2 * m))
            vel[:, :n] = J[i]
            if mode == 0:  # separating: no force, u_n >= 0
                force = np.zeros((2, n + 2 * m))
                force[0, t] = force[1, nrm] = 1.0
                eq_rows.append(force)
                eq_rhs.append(np.zeros(2))
                ub_rows.append(-vel[1:])
                ub_rhs.append(-b[i, 1:])
            elif mode == 1:  # rolling: u = 0, force inside the cone
                eq_rows.append(vel)
                eq_rhs.append(b[i])
                cone = np.zeros((2, n + 2 * m))
                cone[0, t], cone[0, nrm] = 1.0, -mu[i]
                cone[1, t], cone[1, nrm] = -1.0, -mu[i]
                ub_rows.append(cone)
                ub_rhs.append(np.zeros(2))
            else:  # sliding with u_t >= 0 (mode 2) or <= 0 (mode 3): u_n = 0, force on the opposite edge
                sign = 1.0 if mode == 2 else -1.0
                edge = np.zeros((1, n + 2 * m))
                edge[0, t], edge[0, nrm] = 1.0, sign * mu[i]
                eq_rows += [vel[1:], edge]
                eq_rhs += [b[i, 1:], np.zeros(1)]
                ub_rows.append(-sign * vel[:1])
                ub_rhs.append(-sign * b[i, :1])
        res = linprog(
            np.zeros(n + 2 * m),
            A_ub=np.vstack(ub_rows) if ub_rows else None,
            b_ub=np.concatenate(ub_rhs) if ub_rhs else None,
            A_eq=np.vstack(eq_rows),
            b_eq=np.concatenate(eq_rhs),
            bounds=bounds,
            method="highs",
        )
        if res.status != 0:
            continue
        q = np.asarray(res.x[:n])
        if not any(np.max(np.abs(q - other.q)) <= _DISTINCT for other in motions):
            motions.append(RawMotion(q, np.asarray(res.x[n:]).reshape(m, 2)))
    if len(motions) == 1:
        return NaiveResult("solved", tuple(motions))
    if motions:
        return NaiveResult("ambiguous", tuple(motions))
    return NaiveResult("unstable" if not _equilibrium_exists(problem) else "jammed")


def _equilibrium_exists(problem: Problem) -> bool:
    """Can the contact forces, inside their cones, balance the load with every mover stopped?"""
    m = problem.n_contacts
    A_eq = np.concatenate([problem.J[i].T for i in range(m)], axis=1)
    cone = np.zeros((2 * m, 2 * m))
    for i in range(m):
        cone[2 * i, 2 * i], cone[2 * i, 2 * i + 1] = 1.0, -problem.mu[i]
        cone[2 * i + 1, 2 * i], cone[2 * i + 1, 2 * i + 1] = -1.0, -problem.mu[i]
    res = linprog(
        np.zeros(2 * m),
        A_ub=cone,
        b_ub=np.zeros(2 * m),
        A_eq=A_eq,
        b_eq=-problem.g,
        bounds=[(None, None), (0.0, None)] * m,
        method="highs",
    )
    return bool(res.status == 0)
