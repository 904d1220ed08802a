"""Planar shapes on the page: disks as circles, boxes and polygons as their outlines, halfplanes as a shaded strip.

Shared by :mod:`.figures` (a Solution on a :class:`~quasistatic.adapters.PlanarWorld`) and
:mod:`.animation` (a planar run, frame by frame). The plane is the page: x right, y up.
A halfplane is unbounded: it is drawn as its boundary line and a shaded strip on its
solid side, ``reach`` either way of the point of the line nearest ``centre``; the axes
clip it to the view. matplotlib is imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ..adapters import Disk, HalfPlane, PlanarShape, Polygon, Pose
from .geometry import FloatArray
from .style import BODY_FILL, EDGE_COLOUR, MOVER_FILL

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["GROUND_FILL", "PlanarPart", "draw_planar_parts", "halfplane_strip", "placed_vertices", "planar_extent"]

GROUND_FILL = "#F4F4F4"  # a halfplane (table, wall): lighter than any part, drawn under everything
_HATCH = "#B8B8B8"  # the strip's hatching: a halfplane is solid on that side
_STRIP_DEPTH = 0.08  # the halfplane's shaded strip is this share of the reach deep


class PlanarPart(Protocol):
    """A planar body or mover as drawn: its shape and pose (:class:`~quasistatic.adapters.PlanarBody`, ``PlanarMover``)."""

    @property
    def name(self) -> str: ...

    @property
    def shape(self) -> PlanarShape | None: ...

    @property
    def pose(self) -> Pose: ...


def placed_vertices(polygon: Polygon, pose: Pose) -> FloatArray:
    """A polygon's vertices (counter-clockwise) in the plane, at ``pose``."""
    out: FloatArray = np.asarray(polygon.vertices) @ pose.rotation[:2, :2].T + pose.position[:2]
    return out


def planar_extent(shape: PlanarShape, pose: Pose) -> FloatArray | None:
    """Points of the plane whose bounding box holds a bounded shape at ``pose`` (None for a halfplane)."""
    if isinstance(shape, Disk):
        return pose.position[:2] + shape.radius * np.array([[-1.0, -1.0], [1.0, 1.0]])
    if isinstance(shape, Polygon):
        return placed_vertices(shape, pose)
    return None


def halfplane_strip(halfplane: HalfPlane, pose: Pose, centre: FloatArray, reach: float) -> FloatArray:
    """Corners (4, 2) of the strip drawn for a halfplane: ``2 reach`` along its line, ``_STRIP_DEPTH reach`` into its solid side."""
    rotation = pose.rotation[:2, :2]
    normal = rotation @ halfplane.normal  # outward, in the plane
    on_line = pose.position[:2] + halfplane.offset * normal  # a point of the boundary line
    foot = centre[:2] - float(normal @ (centre[:2] - on_line)) * normal
    along = np.array([-normal[1], normal[0]]) * reach
    depth = -normal * _STRIP_DEPTH * reach
    return np.array([foot - along, foot + along, foot + along + depth, foot - along + depth])


def draw_planar_parts(
    ax: Axes, bodies: Iterable[PlanarPart], movers: Iterable[PlanarPart], centre: FloatArray, reach: float
) -> list[FloatArray]:
    """Add one patch per shaped part (movers darker than bodies; halfplanes under everything, with their boundary line).

    Returns the bounded shapes' extents, for the view's limits (a halfplane has none).
    """
    from matplotlib.patches import Circle, Patch
    from matplotlib.patches import Polygon as PolygonPatch

    extents: list[FloatArray] = []
    parts = [(m, MOVER_FILL) for m in movers] + [(b, BODY_FILL) for b in bodies]
    for part, fill in parts:
        shape, pose = part.shape, part.pose
        if isinstance(shape, HalfPlane):
            strip = halfplane_strip(shape, pose, centre, reach)
            ax.add_patch(
                PolygonPatch(
                    strip, closed=True, facecolor=GROUND_FILL, edgecolor=_HATCH, linewidth=0.0, hatch="//", zorder=0, gid=part.name
                )
            )
            ax.plot(strip[:2, 0], strip[:2, 1], color=EDGE_COLOUR, linewidth=1.0, zorder=0.2)
            continue
        patch: Patch
        if isinstance(shape, Disk):
            patch = Circle(tuple(pose.position[:2]), shape.radius, facecolor=fill, edgecolor=EDGE_COLOUR, linewidth=0.8, zorder=1)
        elif isinstance(shape, Polygon):
            vertices = placed_vertices(shape, pose)
            patch = PolygonPatch(vertices, closed=True, facecolor=fill, edgecolor=EDGE_COLOUR, linewidth=0.8, zorder=1)
        else:
            continue  # a part without a shape: drawn through its contacts by the caller
        patch.set_gid(part.name)  # found by name (tests, SVG ids); legends use their own handles
        ax.add_patch(patch)
        extent = planar_extent(shape, pose)
        extents += [] if extent is None else [extent]
    return extents
