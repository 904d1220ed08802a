"""Plane geometry for pictures: views (projections onto the page), convex outlines and the shapes' outlines.

Pure numpy: everything here is drawn later by :mod:`quasistatic.viz.figures`.
A 3-D scene is drawn by projecting it orthographically onto the page, not with
matplotlib's 3-D axes, so that arrows keep their true lengths along the page
and 2-D and 3-D pictures share one drawing code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..adapters import Box, Capsule, Convex, Cylinder, Halfspace, Mesh, Pose, Shape, Sphere
from .choices import VIEWS

__all__ = ["VIEWS", "Projection", "convex_hull", "shape_outline", "plane_patch"]

FloatArray = npt.NDArray[np.float64]

_CIRCLE_POINTS = 48


@dataclass(frozen=True)
class Projection:
    """An orthographic view: page coordinates of world points and vectors.

    Attributes
    ----------
    name : str
        ``plane`` for a 2-D scene, else one of :data:`VIEWS`.
    matrix : array (2, 3)
        Rows: the page's right and up directions in the world (orthonormal).
    """

    name: str
    matrix: FloatArray

    @classmethod
    def of(cls, dimension: int, view: str) -> Projection:
        if dimension == 2:
            return cls("plane", np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]))
        if view not in VIEWS:
            raise ValueError(f"view {view!r} is not one of {', '.join(VIEWS)}")
        return cls(view, np.vstack(VIEWS[view]))

    def __call__(self, vectors: npt.ArrayLike) -> FloatArray:
        """Page coordinates of points or vectors, (d,) or (n, d) with d = 2 or 3 (a 2-D one lies in z = 0)."""
        array = np.atleast_2d(np.asarray(vectors, dtype=float))
        if array.shape[1] == 2:
            array = np.hstack([array, np.zeros((len(array), 1))])
        out: FloatArray = array @ self.matrix.T
        return out


def lifted(vector: npt.ArrayLike) -> FloatArray:
    """A 2-D vector as a 3-D one in the plane z = 0 (3-D vectors unchanged)."""
    array = np.asarray(vector, dtype=float)
    return np.append(array, 0.0) if array.shape == (2,) else array


def convex_hull(points: npt.ArrayLike) -> FloatArray:
    """Vertices of the convex hull of page points (n, 2), counter-clockwise (Andrew's monotone chain)."""
    unique = np.unique(np.round(np.asarray(points, dtype=float), 12), axis=0)
    if len(unique) < 3:
        return unique
    ordered = sorted(map(tuple, unique))
    lower = _chain(ordered)
    upper = _chain(ordered[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _chain(points: list[tuple[float, ...]]) -> list[tuple[float, ...]]:
    chain: list[tuple[float, ...]] = []
    for p in points:
        while len(chain) >= 2 and _cross(chain[-2], chain[-1], p) <= 0.0:
            chain.pop()
        chain.append(p)
    return chain


def _cross(o: tuple[float, ...], a: tuple[float, ...], b: tuple[float, ...]) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def shape_outline(shape: Shape, pose: Pose, projection: Projection) -> FloatArray | None:
    """The page outline (convex, counter-clockwise) of a bounded shape, or None for a halfspace."""
    if isinstance(shape, Sphere):
        return projection(pose.position) + shape.radius * _circle()
    if isinstance(shape, Capsule):
        ends = projection(pose.apply([[0.0, 0.0, -shape.length / 2], [0.0, 0.0, shape.length / 2]]))
        return convex_hull(np.vstack([end + shape.radius * _circle() for end in ends]))
    local = _local_points(shape)
    return None if local is None else convex_hull(projection(pose.apply(local)))


def _local_points(shape: Shape) -> FloatArray | None:
    """Points whose hull is the shape, in its own frame (None for a halfspace)."""
    if isinstance(shape, Box):
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        out: FloatArray = corners * shape.size / 2
        return out
    if isinstance(shape, Cylinder):
        angles = np.linspace(0.0, 2 * math.pi, _CIRCLE_POINTS, endpoint=False)
        rim = np.column_stack([shape.radius * np.cos(angles), shape.radius * np.sin(angles), np.zeros_like(angles)])
        return np.vstack([rim + [0.0, 0.0, -shape.length / 2], rim + [0.0, 0.0, shape.length / 2]])
    if isinstance(shape, Convex):
        return np.asarray(shape.vertices, dtype=float)
    if isinstance(shape, Mesh):
        return np.asarray(shape.convex.vertices, dtype=float)
    return None


def _circle() -> FloatArray:
    angles = np.linspace(0.0, 2 * math.pi, _CIRCLE_POINTS, endpoint=False)
    return np.column_stack([np.cos(angles), np.sin(angles)])


def plane_patch(halfspace: Halfspace, pose: Pose, centre: FloatArray, half_width: float, projection: Projection) -> FloatArray:
    """Page corners of a square of the halfspace's boundary plane around ``centre`` (world), e.g. a floor."""
    local_centre = pose.inverse().apply(centre)
    normal = halfspace.normal
    foot = local_centre - (normal @ local_centre - halfspace.offset) * normal
    u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    corners = [foot + half_width * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return projection(pose.apply(np.array(corners)))
