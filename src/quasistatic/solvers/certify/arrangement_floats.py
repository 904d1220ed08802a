"""The vertex certificate's commonest claim in Python floats: a checked seed is the only motion, among few planes.

A simulation step of one turning planar body proves its Lemke point the only motion (claim 2 of :mod:`.arrangement`)
on a handful of twist planes (a box tipping on a table corner under a fingertip: three planes, one triple). There the
whole-array code spends its time in about a hundred numpy calls on arrays of 3 to 10 entries, microseconds each.
This is the same proof written out on Python floats for problems of at most
:data:`~quasistatic.tolerances.FLOAT_ARRANGEMENT_PLANES` planes: the same planes and loads, the same candidate Farkas
directions and bit masks, the same vertices with their near planes and margins, the same rays, in the same order.
It only ever says "the seed is the only motion" (with the number of triples solved) or "not here"; every other
verdict (no motion, several motions listed, a continuum, too close to call) and every number a proof hands on come
from the array code, which then runs from the start.

The arithmetic is the array code's term for term, with one difference: a sum of three products is rounded after each
product and each addition, where numpy's matrix products (BLAS) fuse a multiply with the addition that follows on
most x86-64 machines. A cross or triple product may so differ in its last bit or two; both are far inside the
certificate's round-off allowance (``ARRANGEMENT_ROUNDOFF``, 1e-12 of the longest normal's cube, against 1e-16), so
each computation is a proof on its own. ``tests/test_arrangement_floats.py`` holds the two verdict for verdict, with
the same number of triples solved, on the turning run's problems, the benchmark's planar grasps and random scenes.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import NamedTuple

from ...laws.polyhedral import LCPForm
from ...tolerances import (
    ARRANGEMENT_CONTACTS,
    ARRANGEMENT_ROUNDOFF,
    DISTINCT_TWIST,
    FLOAT_ARRANGEMENT_PLANES,
    FORCE_CEILING,
    LP_FEASIBILITY,
    SAME_TWIST,
    ZERO,
)

__all__ = ["seed_is_only_motion", "EDGE_BIT_VALUES", "CLAIMS"]

Vector = tuple[float, float, float]

EDGE_BIT_VALUES = (1, 3, 2)  # by slip sign -1, 0, +1: the edge n + mu t, both, the edge n - mu t
CLAIMS = ((0.0, 0.5 * SAME_TWIST), (ZERO, 0.5 * DISTINCT_TWIST), (LP_FEASIBILITY, DISTINCT_TWIST))  # each claim's tau, how near


def seed_is_only_motion(form: LCPForm, seed_q: Sequence[float]) -> int | None:
    """The number of independent triples solved when the vertex certificate proves the seed's twist ``seed_q`` (of a
    point every law of ``form`` holds at, checked by the caller) the only motion; None when it does not here (not one
    planar body, more than ``FLOAT_ARRANGEMENT_PLANES`` planes, or any other verdict): the array code decides then."""
    problem = form.problem
    m = problem.n_contacts
    if problem.dimension != 2 or form.n_q != 3 or form.n_edges != 2 or not 0 < m <= ARRANGEMENT_CONTACTS:
        return None
    mu = problem.mu.tolist()
    if not 3 <= m + sum(f > 0.0 for f in mu) <= FLOAT_ARRANGEMENT_PLANES:
        return None
    planes = _planes(problem.J.tolist(), problem.b.tolist(), mu)
    blocked = _blocked(planes.loads, problem.g.tolist())
    if _excludes(blocked, (1 << len(planes.loads)) - 1):
        return None  # no forces balance the load whatever the twist: not the seed's claim
    vertices, count = _vertices(planes)
    held = [v for v in vertices if not _excludes(blocked, _mask(planes.slip_row, v.signs))]
    if not held or not all(_near_seed(v, seed_q) for v in held) or not _rays_excluded(planes, held, blocked):
        return None
    return count


class _Planes(NamedTuple):
    """As :class:`.arrangement._Planes`, in floats: gap rows first, then the slip rows of the frictional contacts;
    ``cross[a][c]``: ``n_a x n_c``; ``triple[p][a][c]``: ``n_p . (n_a x n_c)`` (each computed for ``a < c``, its
    other order the negation, as rounding is symmetric)."""

    normals: list[Vector]
    rhs: list[float]
    slip_row: list[int]  # per contact, its slip plane's index, or -1 without friction
    cross: list[list[Vector]]
    triple: list[list[list[float]]]
    loads: list[Vector]  # n + mu t, n - mu t per contact
    longest: float
    largest_offset: float
    dependent: float


def _planes(J: list[list[list[float]]], b: list[list[float]], mu: list[float]) -> _Planes:
    """The planes of the planar laws ``J`` (m, 2, 3), ``b`` (m, 2) (tangent row, then normal), friction ``mu``."""
    m = len(J)
    frictional = [i for i in range(m) if mu[i] > 0.0]
    normals: list[Vector] = [_vector(J[i][1]) for i in range(m)] + [_vector(J[i][0]) for i in frictional]
    rhs = [b[i][1] for i in range(m)] + [b[i][0] for i in frictional]
    slip_row = [-1] * m
    for row, i in enumerate(frictional, m):
        slip_row[i] = row
    P = len(normals)
    zero: Vector = (0.0, 0.0, 0.0)
    cross = [[zero] * P for _ in range(P)]
    triple = [[[0.0] * P for _ in range(P)] for _ in range(P)]
    for a, c in itertools.combinations(range(P), 2):
        (ux, uy, uz), (vx, vy, vz) = normals[a], normals[c]
        x, y, z = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        cross[a][c], cross[c][a] = (x, y, z), (-x, -y, -z)
        for p, (nx, ny, nz) in enumerate(normals):
            rate = nx * x + ny * y + nz * z
            triple[p][a][c], triple[p][c][a] = rate, -rate
    longest = math.sqrt(max(x * x + y * y + z * z for x, y, z in normals))
    loads: list[Vector] = []
    for i in range(m):
        (tx, ty, tz), (nx, ny, nz), f = J[i][0], J[i][1], mu[i]
        fx, fy, fz = f * tx, f * ty, f * tz
        loads += [(nx + fx, ny + fy, nz + fz), (nx - fx, ny - fy, nz - fz)]
    offset = max(abs(r) for r in rhs)
    return _Planes(normals, rhs, slip_row, cross, triple, loads, longest, offset, ARRANGEMENT_ROUNDOFF * longest**3)


def _mask(slip_row: list[int], signs: Sequence[int]) -> int:
    """The loads a sign vector's contacts may use, as a bit mask (as :func:`.arrangement._load_masks`)."""
    mask = 0
    for i, row in enumerate(slip_row):
        if signs[i] == 0:
            mask |= EDGE_BIT_VALUES[(signs[row] if row >= 0 else 0) + 1] << (2 * i)
    return mask


class _Vertex(NamedTuple):
    """One vertex kept in loose ``Q0``: its twist, each plane's sign (0 where near), ``|N_T^-1|_1`` per entry, and
    the triple's own round-off (as :class:`.arrangement._Vertices` keeps them, one row)."""

    w: Vector
    signs: tuple[int, ...]
    spread: Vector
    slack: float


def _vertices(planes: _Planes) -> tuple[list[_Vertex], int]:
    """Every vertex of an independent triple whose gap rows are not below their margin, and the number of independent
    triples (as :func:`.arrangement._vertices`)."""
    rhs, cross, triple, m = planes.rhs, planes.cross, planes.triple, len(planes.slip_row)
    P = len(rhs)
    kept: list[_Vertex] = []
    count = 0
    for i, j, k in itertools.combinations(range(P), 3):
        det = triple[i][j][k]
        if not abs(det) > planes.dependent:
            continue
        count += 1
        X0, X1, X2 = cross[j][k], cross[k][i], cross[i][j]
        ri, rj, rk = rhs[i], rhs[j], rhs[k]
        w: Vector = tuple((ri * X0[e] + rj * X1[e] + rk * X2[e]) / det for e in range(3))  # type: ignore[assignment]
        slack = ARRANGEMENT_ROUNDOFF * (planes.longest * (abs(w[0]) + abs(w[1]) + abs(w[2])) + planes.largest_offset)
        loose = LP_FEASIBILITY + slack
        signs = []
        for p in range(P):
            rates = triple[p]
            a, b, c = rates[j][k] / det, rates[k][i] / det, rates[i][j] / det
            row = a * ri + b * rj + c * rk - rhs[p]
            near = loose * (1.0 + (abs(a) + abs(b) + abs(c))) + slack
            signs.append(1 if row > near else -1 if row < -near else 0)
        if min(signs[:m]) < 0:
            continue  # below a gap row's margin: not in loose Q0
        spread: Vector = tuple((abs(X0[e]) + abs(X1[e]) + abs(X2[e])) / abs(det) for e in range(3))  # type: ignore[assignment]
        kept.append(_Vertex(w, tuple(signs), spread, slack))
    return kept, count


def _near_seed(vertex: _Vertex, q: Sequence[float]) -> bool:
    """Whether the vertex, with its loose twists, is near the seed's twist (as :func:`.arrangement._near_seed`)."""
    w, spread, slack = vertex.w, vertex.spread, vertex.slack
    offset = (abs(w[0] - q[0]), abs(w[1] - q[1]), abs(w[2] - q[2]))
    return all(offset[e] + (tau + slack) * spread[e] <= within for tau, within in CLAIMS for e in range(3))


def _rays_excluded(planes: _Planes, held: list[_Vertex], blocked: list[int]) -> bool:
    """Whether every ray leaving the held vertices along a line where two of their near planes meet, kept in loose
    ``Q0``, has its loads excluded (as :func:`.arrangement._edges_excluded` without ``apart``)."""
    m, dependent, triple = len(planes.slip_row), planes.dependent, planes.triple
    parallel = dependent**2 / planes.longest**2
    for signs in dict.fromkeys(v.signs for v in held):
        near = [p for p, s in enumerate(signs) if s == 0]
        gaps = [index for index, p in enumerate(near) if p < m]
        for a, c in itertools.combinations(near, 2):
            x, y, z = planes.cross[a][c]
            if not x * x + y * y + z * z > parallel:
                continue
            along = [triple[p][a][c] for p in near]
            along = [0.0 if abs(rate) <= dependent else rate for rate in along]
            for ray in (along, [-rate for rate in along]):
                if any(ray[index] < 0.0 for index in gaps):
                    continue  # a near gap row falls along it: it leaves loose Q0
                ray_signs = list(signs)
                for p, rate in zip(near, ray, strict=True):
                    ray_signs[p] = 1 if rate > 0.0 else -1 if rate < 0.0 else 0
                if not _excludes(blocked, _mask(planes.slip_row, ray_signs)):
                    return False
    return True


def _blocked(loads: list[Vector], g: list[float]) -> list[int]:
    """Per useful candidate Farkas direction, the loads it excludes as a bit mask (as :meth:`.arrangement._Exclusions.of`):
    ``-g``, ``-g`` less its part along each load, and both normals of the plane of each pair of loads. A direction and
    its negation share their products up to sign (rounding is symmetric), so each normal's are computed once."""
    gx, gy, gz = -g[0], -g[1], -g[2]
    margin = math.sqrt(len(g)) * LP_FEASIBILITY
    directions: list[Vector] = [(gx, gy, gz)]
    for x, y, z in loads:
        scale = (x * gx + y * gy + z * gz) / max(x * x + y * y + z * z, 1e-300)
        directions.append((gx - scale * x, gy - scale * y, gz - scale * z))
    blocked: list[int] = []
    for x, y, z in directions:
        reserve = (x * gx + y * gy + z * gz) - margin * math.sqrt(x * x + y * y + z * z)
        if reserve > 0.0:
            blocked.append(_bits([x * lx + y * ly + z * lz for lx, ly, lz in loads], reserve))
    for (ux, uy, uz), (vx, vy, vz) in itertools.combinations(loads, 2):
        x, y, z = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        toward, length = x * gx + y * gy + z * gz, margin * math.sqrt(x * x + y * y + z * z)
        rates = [x * lx + y * ly + z * lz for lx, ly, lz in loads]
        if toward - length > 0.0:
            blocked.append(_bits(rates, toward - length))
        if -toward - length > 0.0:
            blocked.append(_bits([-rate for rate in rates], -toward - length))
    return blocked


def _bits(rates: list[float], reserve: float) -> int:
    """The loads whose rate along a direction, times ``FORCE_CEILING``, stays below its reserve, as a bit mask."""
    bits = 0
    for k, rate in enumerate(rates):
        if rate * FORCE_CEILING < reserve:
            bits |= 1 << k
    return bits


def _excludes(blocked: list[int], mask: int) -> bool:
    """Whether one direction excludes every load of ``mask``."""
    return any(not mask & ~bits for bits in blocked)


def _vector(values: Sequence[float]) -> Vector:
    return (values[0], values[1], values[2])
