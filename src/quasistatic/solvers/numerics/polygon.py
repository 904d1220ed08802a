"""The vertices of a polygon given by half-planes, and the ball around it, compiled: the mode branch and bound's plane
of twists.

Where a node's closed rows leave a plane of twists, its inequality rows cut a polygon from it
(:func:`..certify.patterns._on_plane`): ``rates[k] . x + reserve[k] >= 0`` for the rows kept. A few to twenty rows,
thousands of nodes: numpy's calls cost ~60 us a polygon there, these loops ~2 us. The polygon's twists are then
bounded by a ball, or found in the seed's box (:func:`polygon_ball`: ~20 numpy calls, ~25 us, where the loops take
~2 us). With numba the loops below are compiled; without it, the same loops in C (``quasistatic._kernels``, where the
default install built it), else the same arithmetic in whole-array numpy calls.
"""

from __future__ import annotations

import math

import numpy as np

from ...compiled import HAVE_KERNELS
from ...compiled import polygon_ball as compiled_polygon_ball
from ...compiled import polygon_vertices as compiled_polygon_vertices
from ...jit import njit

__all__ = ["polygon_vertices", "polygon_ball", "UNBOUNDED", "NEAR_SEED"]

UNBOUNDED = -1  # polygon_vertices' answer for a polygon not known to be bounded (or too close to call)
NEAR_SEED = -1.0  # polygon_ball's answer for a polygon whose twists all lie in the seed's box


def _polygon_vertices_numpy(
    rates: np.ndarray, reserve: np.ndarray, rows: np.ndarray, parallel: float, skew: float, slack: float, vertices: np.ndarray
) -> int:
    """:func:`polygon_vertices` in whole-array numpy calls (without numba or the C extension)."""
    slope, reserve = rates[rows], reserve[rows]
    norms = np.sqrt(slope[:, 0] * slope[:, 0] + slope[:, 1] * slope[:, 1])
    flat = norms == 0.0
    if flat.any():
        if (reserve[flat] < 0.0).any():
            return 0
        slope, reserve, norms = slope[~flat], reserve[~flat], norms[~flat]
    angles = np.sort(np.arctan2(slope[:, 1], slope[:, 0]))
    if angles.size < 3 or max(float(np.max(np.diff(angles))), float(angles[0] + 2.0 * math.pi - angles[-1])) >= math.pi - skew:
        return UNBOUNDED
    i, j = np.triu_indices(angles.size, 1)
    a, b, c, d = slope[i, 0], slope[i, 1], slope[j, 0], slope[j, 1]
    det = a * d - b * c
    sine = np.abs(det) / (norms[i] * norms[j])
    meet = sine >= skew
    if np.any(~meet & (sine > parallel)):
        return UNBOUNDED
    a, b, c, d, det, ri, rj = a[meet], b[meet], c[meet], d[meet], det[meet], reserve[i[meet]], reserve[j[meet]]
    x, y = (b * rj - d * ri) / det, (c * ri - a * rj) / det  # where two lines meet
    values = slope[:, :1] * x + slope[:, 1:] * y + reserve[:, None]
    lenient = slack * (norms[:, None] * np.sqrt(x * x + y * y) + np.abs(reserve)[:, None])
    inside = (values >= -lenient).all(axis=0)
    count = int(np.count_nonzero(inside))
    vertices[:count, 0], vertices[:count, 1] = x[inside], y[inside]
    return count


@njit(python=compiled_polygon_vertices if HAVE_KERNELS else _polygon_vertices_numpy)
def polygon_vertices(
    rates: np.ndarray, reserve: np.ndarray, rows: np.ndarray, parallel: float, skew: float, slack: float, vertices: np.ndarray
) -> int:
    """The vertices of ``{x in R^2: rates[k] . x + reserve[k] >= 0 for every k in rows}``, written to ``vertices``.

    ``rates`` (R, 2), ``reserve`` (R,) float64, ``rows`` (R,) bool, ``vertices`` (P (P - 1) / 2, 2) with ``P`` the
    rows kept; all C-contiguous. A row of zero rate is met everywhere or nowhere (then no vertex). Bounded when the
    rows' normals leave no angle of ``pi - skew`` or more between neighbours; then the vertices are the meeting
    points of two lines (in the order of the pairs ``i < j`` of rows) that meet every row to ``slack`` (relative)
    [-]. Returns how many were written (0: empty), or :data:`UNBOUNDED` (also when two lines are closer to parallel
    than ``skew`` but not than ``parallel``: a vertex too close to call).
    """
    total = rates.shape[0]
    s0, s1, offset, norm = np.empty(total), np.empty(total), np.empty(total), np.empty(total)
    P = 0
    for k in range(total):
        if rows[k]:
            size = math.sqrt(rates[k, 0] * rates[k, 0] + rates[k, 1] * rates[k, 1])
            if size == 0.0:
                if reserve[k] < 0.0:
                    return 0
                continue
            s0[P], s1[P], offset[P], norm[P] = rates[k, 0], rates[k, 1], reserve[k], size
            P += 1
    if P < 3:
        return UNBOUNDED
    angles = np.empty(P)
    for k in range(P):
        angles[k] = math.atan2(s1[k], s0[k])
    for k in range(1, P):  # insertion sort: a few rows
        value, at = angles[k], k
        while at > 0 and angles[at - 1] > value:
            angles[at] = angles[at - 1]
            at -= 1
        angles[at] = value
    widest = angles[0] + 2.0 * math.pi - angles[P - 1]
    for k in range(1, P):
        widest = max(widest, angles[k] - angles[k - 1])
    if widest >= math.pi - skew:
        return UNBOUNDED
    for i in range(P):
        for j in range(i + 1, P):
            sine = abs(s0[i] * s1[j] - s1[i] * s0[j]) / (norm[i] * norm[j])
            if sine < skew and sine > parallel:
                return UNBOUNDED
    count = 0
    for i in range(P):
        for j in range(i + 1, P):
            det = s0[i] * s1[j] - s1[i] * s0[j]
            if not abs(det) / (norm[i] * norm[j]) >= skew:
                continue
            x = (s1[i] * offset[j] - s1[j] * offset[i]) / det
            y = (s0[j] * offset[i] - s0[i] * offset[j]) / det
            size = math.sqrt(x * x + y * y)
            inside = True
            for k in range(P):
                if s0[k] * x + s1[k] * y + offset[k] < -(slack * (norm[k] * size + abs(offset[k]))):
                    inside = False
                    break
            if inside:
                vertices[count, 0], vertices[count, 1] = x, y
                count += 1
    return count


def _polygon_ball_numpy(
    q0: np.ndarray,
    directions: np.ndarray,
    vertices: np.ndarray,
    seed: np.ndarray,
    spread: np.ndarray,
    same: float,
    distinct: float,
    center: np.ndarray,
) -> float:
    """:func:`polygon_ball` in whole-array numpy calls (without numba or the C extension)."""
    twists = q0 + vertices @ directions
    if seed.size:
        offset = np.abs(twists - seed).max(axis=0)
        if offset.max() <= 0.5 * same and (offset + spread).max() <= 0.5 * distinct:
            return NEAR_SEED
    center[:] = 0.5 * (twists.min(axis=0) + twists.max(axis=0))
    return math.sqrt(float(((twists - center) ** 2).sum(axis=1).max()))


@njit(python=compiled_polygon_ball if HAVE_KERNELS else _polygon_ball_numpy)
def polygon_ball(
    q0: np.ndarray,
    directions: np.ndarray,
    vertices: np.ndarray,
    seed: np.ndarray,
    spread: np.ndarray,
    same: float,
    distinct: float,
    center: np.ndarray,
) -> float:
    """The twists ``q0 + vertices[v] directions`` of a polygon's vertices (their hull: the polygon's twists): when a
    ``seed`` is given (else it is empty) and every twist lies within ``same / 2`` of it per entry, and within
    ``distinct / 2`` with ``spread`` added, :data:`NEAR_SEED`; else the ball around them, its ``center`` (the middle
    of their bounding box, filled) and radius (returned, without round-off's margin).

    ``q0`` (n,), ``directions`` (2, n), ``vertices`` (V, 2) with ``V >= 1``, ``seed`` (n,) or (0,), ``spread`` and
    ``center`` (n,), all float64 and C-contiguous.
    """
    n, count = q0.size, vertices.shape[0]
    twists = np.empty((count, n))
    for v in range(count):
        for j in range(n):
            twists[v, j] = q0[j] + (vertices[v, 0] * directions[0, j] + vertices[v, 1] * directions[1, j])
    if seed.size:
        farthest, widest = 0.0, 0.0
        for j in range(n):
            offset = 0.0
            for v in range(count):
                offset = max(offset, abs(twists[v, j] - seed[j]))
            farthest = max(farthest, offset)
            widest = max(widest, offset + spread[j])
        if farthest <= 0.5 * same and widest <= 0.5 * distinct:
            return NEAR_SEED
    for j in range(n):
        low, high = twists[0, j], twists[0, j]
        for v in range(1, count):
            low, high = min(low, twists[v, j]), max(high, twists[v, j])
        center[j] = 0.5 * (low + high)
    reach = 0.0
    for v in range(count):
        square = 0.0
        for j in range(n):
            square += (twists[v, j] - center[j]) * (twists[v, j] - center[j])
        reach = max(reach, square)
    return math.sqrt(reach)
