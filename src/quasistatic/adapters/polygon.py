"""The contact points of a polytope near a halfspace, from the polytope's vertices.

A convex polytope stays out of a halfspace exactly when its vertices do, so the
contact constraints of the pair are those of its vertices within reach (the
margin plus a patch thickness of round-off), each with its own distance. Of
them only the vertices on the polytope's lower surface (on a face turned
towards the halfspace) carry a constraint the others do not imply: a vertex
above them is held up by those below it. Kept are the corners of their hull
seen along the normal, and any vertex inside that hull, which lies lower than
the hull's corners around it (a part standing on a corner whose neighbours
are within the margin touches at that corner first). Flat on its face, that is
the face's corners, what coal's contact patch gives for the pair, in a few
array operations instead of a patch computation and a line-against-shape test
per point.
"""

from __future__ import annotations

import math

import numpy as np

from .shapes import Box, Convex, FloatArray, IntArray, Mesh, Shape

__all__ = ["contact_corners", "halfspace_polygon", "plane_basis", "polytope_faces", "polytope_vertices"]


def polytope_vertices(shape: Shape) -> FloatArray | None:
    """A box's 8 corners or a convex hull's vertices (n, 3) in the shape's frame, kept with the shape; None for other shapes."""
    if isinstance(shape, Box):
        return shape.derived("vertices", _box_corners)
    if isinstance(shape, Mesh):
        return shape.convex.vertices
    if isinstance(shape, Convex):
        return shape.vertices
    return None


def polytope_faces(shape: Shape) -> tuple[FloatArray, IntArray] | None:
    """Outward unit normals (m, 3) of a box's or convex hull's faces in its frame, and each face's vertices (m, k) as
    indices into :func:`polytope_vertices`, kept with the shape; None for other shapes."""
    if isinstance(shape, Box):
        return shape.derived("faces", _box_faces)
    if isinstance(shape, Mesh):
        shape = shape.convex
    if isinstance(shape, Convex):
        return shape.derived("faces", _hull_faces)
    return None


_SIGNS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def _box_corners(box: Box) -> FloatArray:
    corners: FloatArray = _SIGNS * (box.size / 2.0)
    return corners


def _box_faces(box: Box) -> tuple[FloatArray, IntArray]:
    normals = np.vstack([np.eye(3), -np.eye(3)])
    members = np.array([np.flatnonzero(_SIGNS @ normal > 0.0) for normal in normals], dtype=np.int64)  # 4 corners each
    return normals, members


def _hull_faces(convex: Convex) -> tuple[FloatArray, IntArray]:
    a, b, c = (convex.vertices[convex.triangles[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)  # the triangles turn counter-clockwise seen from outside
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals, np.asarray(convex.triangles, dtype=np.int64)


def halfspace_polygon(
    vertices: FloatArray,
    faces: tuple[FloatArray, IntArray],
    rotation: FloatArray,
    position: FloatArray,
    normal: FloatArray,
    offset: float,
    reach: float,
    tolerance: float,
) -> tuple[FloatArray, FloatArray]:
    """Contact points (k, 3) and their gaps (k,) of a polytope, ``vertices`` (n, 3) and ``faces`` (outward normals
    (m, 3), vertex indices (m, j)) in its frame placed at ``rotation``, ``position``, and the halfspace
    ``normal . x <= offset`` (``normal`` unit, world).

    A vertex at gap ``normal . v - offset <= reach`` on a face turned towards the halfspace, or the deepest vertex,
    is within reach; its point is the midpoint of the vertex and its foot on the plane. Of those, kept are the
    corners of their hull seen along the normal and the points inside it: no point within ``tolerance`` [length] of
    another (the lower one stays), or of the segment between two hull corners unless it lies lower than them.
    In plain floats past the products over all vertices and faces: a contact has a few points, where each numpy
    call costs more than their arithmetic.
    """
    r, p, n = rotation.tolist(), position.tolist(), normal.tolist()
    up = [r[0][j] * n[0] + r[1][j] * n[1] + r[2][j] * n[2] for j in range(3)]  # the normal in the polytope's frame
    base = p[0] * n[0] + p[1] * n[1] + p[2] * n[2] - offset
    heights = vertices @ np.array(up)
    lower = np.zeros(len(vertices), dtype=bool)
    face_normals, members = faces
    lower[members[face_normals @ np.array(up) < 0.0]] = True  # on a face turned towards the halfspace
    lower[int(np.argmin(heights))] = True  # always: a needle's tip has faces all but parallel to the normal
    gaps = [height + base for height in heights.tolist()]
    near = [k for k in np.flatnonzero(lower).tolist() if gaps[k] <= reach]
    points = []
    for k in near:
        x, y, z = vertices[k].tolist()
        half = gaps[k] / 2.0
        points.append((r[0][0] * x + r[0][1] * y + r[0][2] * z + p[0] - half * n[0],
                       r[1][0] * x + r[1][1] * y + r[1][2] * z + p[1] - half * n[1],
                       r[2][0] * x + r[2][1] * y + r[2][2] * z + p[2] - half * n[2]))  # fmt: skip
    gaps = [gaps[k] for k in near]
    if len(points) > 1:
        (ux, uy, uz), (vx, vy, vz) = plane_basis(n)
        flat = [(x * ux + y * uy + z * uz, x * vx + y * vy + z * vz) for x, y, z in points]
        corners = contact_corners(flat, gaps, tolerance)
        points, gaps = [points[k] for k in corners], [gaps[k] for k in corners]
    return np.array(points, dtype=float).reshape(-1, 3), np.array(gaps, dtype=float)


def plane_basis(normal: list[float]) -> tuple[list[float], list[float]]:
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


def contact_corners(flat: list[tuple[float, float]], gaps: list[float], tolerance: float) -> list[int]:
    """Indices of the points that carry a constraint: the corners of the 2-D hull of ``flat`` (Andrew's monotone
    chain, counter-clockwise), then the points inside it (each on the lower surface, so lower than the corners
    around it). In plain floats: a patch has a few points, where each numpy call costs more than the arithmetic.

    Points within ``tolerance`` of each other are one (the lowest gap stays); a point within ``tolerance``
    of the segment between its hull neighbours is on an edge, not a corner, unless it lies lower than that
    segment by more than ``tolerance`` (a part standing on an edge bent down in its middle).
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
    hull = lower[:-1] + upper[:-1]
    inside = [k for k in kept if k not in hull and not _on_hull_edge(k, hull, flat, gaps, tolerance)]
    return hull + sorted(inside)


def _on_hull_edge(k: int, hull: list[int], flat: list[tuple[float, float]], gaps: list[float], tolerance: float) -> bool:
    """Whether point ``k`` lies within ``tolerance`` of an edge of the hull, and no lower than the edge there."""
    x, y = flat[k]
    for a, b in zip(hull, hull[1:] + hull[:1], strict=True):
        (ax, ay), (bx, by) = flat[a], flat[b]
        ux, uy = bx - ax, by - ay
        t = min(max(((x - ax) * ux + (y - ay) * uy) / max(ux * ux + uy * uy, 1e-300), 0.0), 1.0)
        if (x - ax - t * ux) ** 2 + (y - ay - t * uy) ** 2 <= tolerance * tolerance:
            return gaps[k] >= (1.0 - t) * gaps[a] + t * gaps[b] - tolerance
    return False


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
