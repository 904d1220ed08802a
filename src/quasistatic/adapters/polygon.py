"""The contact polygon of a polytope near a halfspace, from the polytope's vertices.

A convex polytope's points nearest a plane include its vertices, and the part
of it within a distance ``h`` of the plane projects onto the plane as the
convex hull of the projections of its vertices within ``h`` and of the points
where its edges cross the height ``h``. Those crossing points lie at the
margin itself, and detection keeps only points within the margin (plus a
patch thickness of round-off): what remains are the vertices within reach,
each with its own distance, and of them the corners of their hull. This is
what coal's contact patch gives for the pair, measured point by point
(:mod:`.detect`), in a few array operations instead of a patch computation
and a line-against-shape test per point.
"""

from __future__ import annotations

import math

import numpy as np

from .shapes import Box, Convex, FloatArray, Mesh, Shape

__all__ = ["polytope_vertices", "halfspace_polygon"]


def polytope_vertices(shape: Shape) -> FloatArray | None:
    """A box's 8 corners or a convex hull's vertices (n, 3) in the shape's frame, kept with the shape; None for other shapes."""
    if isinstance(shape, Box):
        return shape.derived("vertices", _box_corners)
    if isinstance(shape, Mesh):
        return shape.convex.vertices
    if isinstance(shape, Convex):
        return shape.vertices
    return None


def _box_corners(box: Box) -> FloatArray:
    signs = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    corners: FloatArray = signs * (box.size / 2.0)
    return corners


def halfspace_polygon(
    vertices: FloatArray, rotation: FloatArray, position: FloatArray, normal: FloatArray, offset: float, reach: float, tolerance: float
) -> tuple[FloatArray, FloatArray]:
    """Contact points (k, 3) and their gaps (k,) of a polytope, ``vertices`` (n, 3) in its frame placed at ``rotation``,
    ``position``, and the halfspace ``normal . x <= offset`` (``normal`` unit, world).

    A vertex at gap ``normal . v - offset <= reach`` is within reach; its point is the midpoint of the vertex
    and its foot on the plane. Of those, the corners of their hull seen along the normal are kept: no point
    within ``tolerance`` [length] of another (the lower one stays) or of the segment between its neighbours.
    In plain floats past the one product over all vertices: a contact has a few points, where each numpy call
    costs more than their arithmetic.
    """
    r, p, n = rotation.tolist(), position.tolist(), normal.tolist()
    up = [r[0][j] * n[0] + r[1][j] * n[1] + r[2][j] * n[2] for j in range(3)]  # the normal in the polytope's frame
    base = p[0] * n[0] + p[1] * n[1] + p[2] * n[2] - offset
    gaps = [height + base for height in (vertices @ np.array(up)).tolist()]
    near = [k for k, gap in enumerate(gaps) if gap <= reach]
    points = []
    for k in near:
        x, y, z = vertices[k].tolist()
        half = gaps[k] / 2.0
        points.append((r[0][0] * x + r[0][1] * y + r[0][2] * z + p[0] - half * n[0],
                       r[1][0] * x + r[1][1] * y + r[1][2] * z + p[1] - half * n[1],
                       r[2][0] * x + r[2][1] * y + r[2][2] * z + p[2] - half * n[2]))  # fmt: skip
    gaps = [gaps[k] for k in near]
    if len(points) > 1:
        (ux, uy, uz), (vx, vy, vz) = _plane_basis(n)
        flat = [(x * ux + y * uy + z * uz, x * vx + y * vy + z * vz) for x, y, z in points]
        corners = _hull_corners(flat, gaps, tolerance)
        points, gaps = [points[k] for k in corners], [gaps[k] for k in corners]
    return np.array(points, dtype=float).reshape(-1, 3), np.array(gaps, dtype=float)


def _plane_basis(normal: list[float]) -> tuple[list[float], list[float]]:
    """Two orthonormal directions across the unit ``normal``, in plain floats."""
    x, y, z = normal
    if abs(x) <= abs(y) and abs(x) <= abs(z):  # across the normal's smallest entry's axis: far from parallel
        first = (0.0, z, -y)  # normal x e_x
    elif abs(y) <= abs(z):
        first = (-z, 0.0, x)  # normal x e_y
    else:
        first = (y, -x, 0.0)  # normal x e_z
    scale = 1.0 / math.sqrt(first[0] ** 2 + first[1] ** 2 + first[2] ** 2)
    a, b, c = first[0] * scale, first[1] * scale, first[2] * scale
    return [a, b, c], [y * c - z * b, z * a - x * c, x * b - y * a]


def _hull_corners(flat: list[tuple[float, float]], gaps: list[float], tolerance: float) -> list[int]:
    """Indices of the corners of the 2-D hull of ``flat``, counter-clockwise (Andrew's monotone chain, in plain floats:
    a patch has a few points, where each numpy call costs more than the arithmetic).

    Points within ``tolerance`` of each other are one (the lowest gap stays); a point within ``tolerance``
    of the segment between its hull neighbours is on an edge, not a corner.
    """
    limit = tolerance * tolerance
    kept: list[int] = []
    for k in sorted(range(len(flat)), key=gaps.__getitem__):  # the lowest of coinciding points first
        x, y = flat[k]
        for m in kept:
            if (x - flat[m][0]) ** 2 + (y - flat[m][1]) ** 2 <= limit:
                break
        else:
            kept.append(k)
    if len(kept) <= 2:
        return sorted(kept)
    order = sorted(kept, key=flat.__getitem__)
    lower = _chain(flat, order, limit)
    upper = _chain(flat, order[::-1], limit)
    return lower[:-1] + upper[:-1]


def _chain(flat: list[tuple[float, float]], order: list[int], limit: float) -> list[int]:
    """One half of the monotone chain: points that turn left, a point dropped while it is not a corner."""
    chain: list[int] = []
    for k in order:
        while len(chain) >= 2 and not _corner(flat[chain[-2]], flat[chain[-1]], flat[k], limit):
            chain.pop()
        chain.append(k)
    return chain


def _corner(a: tuple[float, float], b: tuple[float, float], c: tuple[float, float], limit: float) -> bool:
    """Whether ``b`` turns left from ``a`` to ``c`` by more than ``sqrt(limit)`` (its distance from the line ``ac``)."""
    ux, uy, vx, vy = c[0] - a[0], c[1] - a[1], b[0] - a[0], b[1] - a[1]
    cross = ux * vy - uy * vx  # (c - a) x (b - a): negative when a, b, c turn left
    length = ux * ux + uy * uy
    return cross < 0.0 and cross * cross > limit * length
