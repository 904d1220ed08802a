"""Independent audit of a motion against the laws, on the original scene data.

Nothing here reads the assembled matrices: velocities, loads and moments are
recomputed from the scene in world frame, so an assembly bug cannot hide.
Residuals are divided by the scene's scales (force, length, velocity).

Speed: the audit runs after every solve, usually on a handful of contacts,
where one numpy call costs more than the arithmetic it does. So each scene's
data (points, normals, frames, moment arms, mover velocities, loads) is read
once per scene object into plain floats, and the laws are checked contact by
contact in scalar Python, one loop per dimension.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from .friction import FrictionModel
from .problem import Scales, contact_frame, mover_point_velocity
from .scene import Scene
from .solution import Audit, PowerBalance

__all__ = ["relative_velocities", "power_balance", "audit_motion", "audit_motion_velocities", "DEFAULT_TOLERANCE"]

DEFAULT_TOLERANCE = 1e-6


@dataclass(frozen=True)
class _Geometry:
    """A scene's data for the audit, as floats (world frame, physical units).

    Attributes
    ----------
    names : body names in scene order; ``loads`` their gravity plus applied wrench
    links : ``(body, other)`` index of each contact's bodies; ``other`` is -1 for a mover
    contacts : one flat tuple of floats per contact:
        ``(normal (d), tangents (d each), arm_body (d), arm_other (d), mover_velocity (d), mu)``
        where ``arm_body``/``arm_other`` run from the body's (other free body's) com to
        the point (zero for a mover), ``mover_velocity`` is the velocity of the mover's
        point (zero for a free body), the tangents are ``contact_frame``'s and ``mu`` is
        zero under ``friction: none``.
    facets, directions, facet_scale : 3-D pyramid only: facet normals, edge
        directions (tangent coordinates) and cos(pi/K), the inradius of the unit polygon.
    """

    dimension: int
    names: tuple[str, ...]
    loads: tuple[tuple[float, ...], ...]
    links: tuple[tuple[int, int], ...]
    contacts: tuple[tuple[float, ...], ...]
    facets: tuple[tuple[float, float], ...] | None
    directions: tuple[tuple[float, float], ...] | None
    facet_scale: float


_GEOMETRY: dict[int, tuple[weakref.ref[Scene], _Geometry]] = {}


def _geometry(scene: Scene) -> _Geometry:
    """The scene's data as floats, read once per scene object (scenes are frozen)."""
    key = id(scene)
    entry = _GEOMETRY.get(key)
    if entry is not None and entry[0]() is scene:
        return entry[1]
    geometry = _read_geometry(scene)
    _GEOMETRY[key] = (weakref.ref(scene), geometry)
    weakref.finalize(scene, _GEOMETRY.pop, key, None)
    return geometry


def _floats(array: object) -> list[float]:
    return [float(x) for x in np.asarray(array, dtype=float).ravel()]


def _read_geometry(scene: Scene) -> _Geometry:
    dim = scene.dimension
    model = scene.friction
    assert isinstance(model, FrictionModel)
    names = tuple(b.name for b in scene.bodies)
    index = {name: i for i, name in enumerate(names)}
    coms = {b.name: np.asarray(b.com, dtype=float) for b in scene.bodies}
    zero = [0.0] * dim
    links = []
    contacts = []
    for c in scene.contacts:
        point = np.asarray(c.point, dtype=float)
        normal = np.asarray(c.normal, dtype=float)
        tangents = contact_frame(normal)[:-1]
        free_other = c.other in index
        links.append((index[c.body], index[c.other] if free_other else -1))
        contacts.append(
            (
                *_floats(normal),
                *_floats(tangents),
                *_floats(point - coms[c.body]),
                *(_floats(point - coms[c.other]) if free_other else zero),
                *(zero if free_other else _floats(mover_point_velocity(scene, c.other, point, c.jacobian))),
                float(c.mu) if model.kind != "none" else 0.0,
            )
        )
    loads = []
    for b in scene.bodies:
        load = np.array(b.wrench, dtype=float)
        load[:dim] += b.mass * np.asarray(scene.gravity)
        loads.append(tuple(_floats(load)))
    facets = directions = None
    facet_scale = 1.0
    if dim == 3 and model.kind == "pyramid":
        k = model.edges
        facet_angles = (2.0 * np.arange(k) + 1.0) * np.pi / k
        facets = tuple((math.cos(a), math.sin(a)) for a in facet_angles)
        directions = tuple((float(x), float(y)) for x, y in model.tangent_directions(3))
        facet_scale = math.cos(math.pi / k)
    return _Geometry(dim, names, tuple(loads), tuple(links), tuple(contacts), facets, directions, facet_scale)


@dataclass(frozen=True)
class _Sums:
    """What one pass over the contacts finds (physical units; residuals not yet scaled)."""

    totals: list[list[float]]  # net wrench on each body
    velocities: list[tuple[float, ...]]  # world relative velocity at each contact
    cone: float  # largest -f_n or excursion outside the friction set [force], >= 0
    penetration: float  # largest -u_n [velocity], >= 0
    normal_power: float  # largest |f_n u_n| [power]
    shortfall: float  # largest shortfall from maximum dissipation [power], >= 0
    supplied: float  # power the movers put in
    dissipated: float  # power lost to friction


def _pass(geometry: _Geometry, twists: dict[str, np.ndarray], forces: np.ndarray) -> tuple[_Sums, list[list[float]]]:
    """Velocities, net wrenches and the per-contact laws, in one loop over the contacts."""
    T = [np.asarray(twists[name], dtype=float).tolist() for name in geometry.names]
    f = np.asarray(forces, dtype=float).tolist()
    totals = [list(load) for load in geometry.loads]
    if geometry.dimension == 2:
        return _pass_2d(geometry, T, f, totals), T
    return _pass_3d(geometry, T, f, totals), T


def _pass_2d(geometry: _Geometry, T: list[list[float]], f: list[list[float]], totals: list[list[float]]) -> _Sums:
    velocities: list[tuple[float, ...]] = []
    cone = penetration = normal_power = shortfall = supplied = dissipated = 0.0
    for (b, o), (nx, ny, tx, ty, rbx, rby, rox, roy, mvx, mvy, mu), (fx, fy) in zip(geometry.links, geometry.contacts, f, strict=True):
        vx, vy, w = T[b]
        ux, uy = vx - w * rby, vy + w * rbx
        total = totals[b]
        total[0] += fx
        total[1] += fy
        total[2] += rbx * fy - rby * fx
        if o >= 0:
            vx, vy, w = T[o]
            ux, uy = ux - (vx - w * roy), uy - (vy + w * rox)
            total = totals[o]
            total[0] -= fx
            total[1] -= fy
            total[2] -= rox * fy - roy * fx
        else:
            ux, uy = ux - mvx, uy - mvy
            supplied += fx * mvx + fy * mvy
        velocities.append((ux, uy))
        f_n, f_t = fx * nx + fy * ny, fx * tx + fy * ty
        u_n, u_t = ux * nx + uy * ny, ux * tx + uy * ty
        radius = mu * max(f_n, 0.0)
        cone = max(cone, -f_n, abs(f_t) - radius)
        penetration = max(penetration, -u_n)
        normal_power = max(normal_power, abs(f_n * u_n))
        shortfall = max(shortfall, radius * abs(u_t) + f_t * u_t)
        dissipated -= fx * ux + fy * uy - f_n * u_n  # tangential force . slip
    return _Sums(totals, velocities, cone, penetration, normal_power, shortfall, supplied, dissipated)


def _pass_3d(geometry: _Geometry, T: list[list[float]], f: list[list[float]], totals: list[list[float]]) -> _Sums:
    facets, directions, facet_scale = geometry.facets, geometry.directions, geometry.facet_scale
    velocities: list[tuple[float, ...]] = []
    cone = penetration = normal_power = shortfall = supplied = dissipated = 0.0
    for (b, o), contact, (fx, fy, fz) in zip(geometry.links, geometry.contacts, f, strict=True):
        nx, ny, nz, ax, ay, az, bx, by, bz, rx, ry, rz, sx, sy, sz, mx, my, mz, mu = contact
        v0, v1, v2, w0, w1, w2 = T[b]
        ux, uy, uz = v0 + w1 * rz - w2 * ry, v1 + w2 * rx - w0 * rz, v2 + w0 * ry - w1 * rx
        total = totals[b]
        total[0] += fx
        total[1] += fy
        total[2] += fz
        total[3] += ry * fz - rz * fy
        total[4] += rz * fx - rx * fz
        total[5] += rx * fy - ry * fx
        if o >= 0:
            v0, v1, v2, w0, w1, w2 = T[o]
            ux -= v0 + w1 * sz - w2 * sy
            uy -= v1 + w2 * sx - w0 * sz
            uz -= v2 + w0 * sy - w1 * sx
            total = totals[o]
            total[0] -= fx
            total[1] -= fy
            total[2] -= fz
            total[3] -= sy * fz - sz * fy
            total[4] -= sz * fx - sx * fz
            total[5] -= sx * fy - sy * fx
        else:
            ux, uy, uz = ux - mx, uy - my, uz - mz
            supplied += fx * mx + fy * my + fz * mz
        velocities.append((ux, uy, uz))
        f_n = fx * nx + fy * ny + fz * nz
        f_1, f_2 = fx * ax + fy * ay + fz * az, fx * bx + fy * by + fz * bz
        u_n = ux * nx + uy * ny + uz * nz
        u_1, u_2 = ux * ax + uy * ay + uz * az, ux * bx + uy * by + uz * bz
        radius = mu * max(f_n, 0.0)
        if facets is None or directions is None:
            outside = math.sqrt(f_1 * f_1 + f_2 * f_2) - radius
            support = math.sqrt(u_1 * u_1 + u_2 * u_2)
        else:
            outside = max([p * f_1 + q * f_2 for p, q in facets]) - radius * facet_scale
            support = max([-(p * u_1 + q * u_2) for p, q in directions])
        cone = max(cone, -f_n, outside)
        penetration = max(penetration, -u_n)
        normal_power = max(normal_power, abs(f_n * u_n))
        shortfall = max(shortfall, radius * support + f_1 * u_1 + f_2 * u_2)
        dissipated -= fx * ux + fy * uy + fz * uz - f_n * u_n  # tangential force . slip
    return _Sums(totals, velocities, cone, penetration, normal_power, shortfall, supplied, dissipated)


def _balance(geometry: _Geometry, sums: _Sums, T: list[list[float]]) -> PowerBalance:
    raised = 0.0
    for load, twist in zip(geometry.loads, T, strict=True):
        for a, b in zip(load, twist, strict=True):
            raised -= a * b
    return PowerBalance(sums.supplied, raised, sums.dissipated, sums.supplied - raised - sums.dissipated)


def relative_velocities(scene: Scene, twists: dict[str, np.ndarray]) -> np.ndarray:
    """World velocity of ``body`` relative to ``other`` at each contact point, (m, d)."""
    geometry = _geometry(scene)
    sums, _ = _pass(geometry, twists, np.zeros((len(scene.contacts), scene.dimension)))
    return np.array(sums.velocities, dtype=float).reshape(len(scene.contacts), scene.dimension)


def power_balance(scene: Scene, twists: dict[str, np.ndarray], forces: np.ndarray) -> PowerBalance:
    """Input, gravity, dissipation and residual powers of one motion [force x length/time]."""
    geometry = _geometry(scene)
    sums, T = _pass(geometry, twists, forces)
    return _balance(geometry, sums, T)


def audit_motion(
    scene: Scene,
    twists: dict[str, np.ndarray],
    forces: np.ndarray,
    scales: Scales,
    tolerance: float = DEFAULT_TOLERANCE,
) -> tuple[Audit, PowerBalance]:
    """Residuals of equilibrium, cone, complementarity, maximum dissipation and power.

    Parameters
    ----------
    forces : (m, d)
        World-frame contact force on each contact's ``body`` [force].
    """
    audit, power, _ = audit_motion_velocities(scene, twists, forces, scales, tolerance)
    return audit, power


def audit_motion_velocities(
    scene: Scene,
    twists: dict[str, np.ndarray],
    forces: np.ndarray,
    scales: Scales,
    tolerance: float = DEFAULT_TOLERANCE,
) -> tuple[Audit, PowerBalance, list[tuple[float, ...]]]:
    """:func:`audit_motion`, plus the relative contact velocities it measured (m tuples of d) [length/time]."""
    geometry = _geometry(scene)
    sums, T = _pass(geometry, twists, forces)
    F, L, V = scales.force, scales.length, scales.velocity
    dim = geometry.dimension
    linear = angular = 0.0
    for total in sums.totals:
        for j, x in enumerate(total):
            if j < dim:
                linear = max(linear, abs(x))
            else:
                angular = max(angular, abs(x))
    equilibrium = max(linear / F, angular / (F * L))
    power = _balance(geometry, sums, T)
    audit = Audit(
        equilibrium,
        max(0.0, sums.cone / F),
        max(sums.penetration / V, sums.normal_power / (F * V)),
        sums.shortfall / (F * V),
        abs(power.residual) / (F * V),
        tolerance,
    )
    return audit, power, sums.velocities
