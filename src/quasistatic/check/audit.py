"""Independent audit of a motion against the laws, on the original scene data.

Nothing here reads the assembled matrices: velocities, loads and moments are
recomputed from the scene in world frame, so an assembly bug cannot hide.
Residuals are divided by the scene's scales (force, length, velocity).

It imports the model only (the scene and its scales): no assembly, no solver
code, so it stays an independent judge.

Speed: the audit runs after every solve, usually on a handful of contacts,
where one numpy call costs more than the arithmetic it does. So a scene's
data (points, normals, frames, moment arms, mover velocities, loads) is read
once into flat arrays (:class:`AuditGeometry`, which a caller may keep and
pass again for the same scene), and the laws are checked contact by
contact in one scalar loop per dimension, compiled by numba when it is
installed (without numba its C twin in the ``quasistatic._kernels`` extension, the same
arithmetic in the same order; where that was not built, the same loop as plain Python on
nested lists, and beyond ``LOOP_CONTACTS`` contacts its whole-array twin :func:`_laws_numpy`).
The loop also returns what a report needs per contact (relative velocity,
slip, normal velocity and force), so nothing is computed twice.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ..compiled import HAVE_AUDIT_ROWS, HAVE_KERNELS, audit_laws, audit_rows, stack_rows
from ..jit import HAVE_NUMBA, njit
from ..model import Contact, Mover, Scales, Scene
from ..solution import Audit, PowerBalance
from ..tolerances import AUDIT, MODE_SPEED

__all__ = [
    "AuditGeometry",
    "Evaluation",
    "relative_velocities",
    "power_balance",
    "audit_motion",
    "audit_motion_velocities",
    "audit_arrays",
    "DEFAULT_TOLERANCE",
]

DEFAULT_TOLERANCE = AUDIT
LOOP_CONTACTS = 24  # without numba: most contacts audited by the scalar loop (beyond: numpy; measured crossover 20-30)


@dataclass(frozen=True)
class AuditGeometry:
    """A scene's data for the audit (world frame, physical units).

    Attributes
    ----------
    dimension : 2 or 3
    names : body names in scene order
    facet_scale : 3-D pyramid only: cos(pi/K), the inradius of the unit polygon (else 1)
    arrays : ``(links, contacts, loads, facets, directions)``, contiguous arrays for the kernel:

        - links (m, 2) int: ``(body, other)`` index of each contact's bodies; ``other`` is -1 for a mover
        - contacts (m, w): one row per contact,
          ``(normal (d), tangents (d each), arm_body (d), arm_other (d), mover_velocity (d), mu)``
          where ``arm_body``/``arm_other`` run from the body's (other free body's) com to
          the point (zero for a mover), ``mover_velocity`` is the velocity of the mover's
          point (zero for a free body), the tangents are ``contact_frames``'s and ``mu`` is
          zero under ``friction: none``
        - loads (bodies, k): gravity plus applied wrench of each body
        - facets, directions (K, 2): 3-D pyramid only (else K = 0): facet normals and
          edge directions in tangent coordinates

    lists : the same as nested lists, for the kernel as plain Python (without numba); else None
    """

    dimension: int
    names: tuple[str, ...]
    facet_scale: float
    arrays: tuple[np.ndarray, ...]
    lists: tuple[Any, ...] | None

    @classmethod
    def of(cls, scene: Scene) -> AuditGeometry:
        """Read a scene's data for the audit (scenes are frozen: the result can be kept for it)."""
        return _read_geometry(scene)


_NO_EDGES = np.zeros((0, 2))  # facets and directions of anything but a 3-D pyramid


def _read_geometry(scene: Scene) -> AuditGeometry:
    """Contact by contact (:func:`_contact_rows`): for the few contacts of a typical scene that is several times
    cheaper than numpy calls (it runs once per scene, e.g. once per item of a batch or step of a simulation)."""
    dim = scene.dimension
    model = scene.friction
    names = tuple(b.name for b in scene.bodies)
    index = {name: i for i, name in enumerate(names)}
    links = [(index[c.body], index.get(c.other, -1)) for c in scene.contacts]
    rows = _contact_rows(scene, links, model.kind != "none")
    m = len(links)
    loads = []
    gravity = np.asarray(scene.gravity, dtype=float)
    for b in scene.bodies:
        load = np.array(b.wrench, dtype=float)
        load[:dim] += b.mass * gravity
        loads.append(load)
    facets = directions = _NO_EDGES
    facet_scale = 1.0
    if dim == 3 and model.kind == "pyramid":
        k = model.edges
        facet_angles = (2.0 * np.arange(k) + 1.0) * np.pi / k
        facets = np.column_stack([np.cos(facet_angles), np.sin(facet_angles)])
        directions = np.array(model.tangent_directions(3), dtype=float).reshape(k, 2)
        facet_scale = math.cos(math.pi / k)
    arrays = (
        np.array(links, dtype=np.int64).reshape(m, 2),
        rows,
        np.array(loads, dtype=float),
        np.ascontiguousarray(facets, dtype=float),
        np.ascontiguousarray(directions, dtype=float),
    )
    for array in arrays:
        array.setflags(write=False)
    lists = None if HAVE_NUMBA or HAVE_KERNELS else tuple(array.tolist() for array in arrays)
    return AuditGeometry(dim, names, facet_scale, arrays, lists)


def _contact_rows_python(scene: Scene, links: list[tuple[int, int]], frictional: bool) -> np.ndarray:
    """Each contact's row of :attr:`AuditGeometry.arrays` ``contacts`` (m, w), in Python floats (the C kernel's twin)."""
    dim = scene.dimension
    coms = [_floats(b.com) for b in scene.bodies]
    movers = {mover.name: mover for mover in scene.movers}
    zero = [0.0] * dim
    rows = []
    for c, (body, other) in zip(scene.contacts, links, strict=True):
        point, normal = _floats(c.point), _floats(c.normal)
        arm_body = [x - y for x, y in zip(point, coms[body], strict=True)]
        if other >= 0:
            arm_other, velocity = [x - y for x, y in zip(point, coms[other], strict=True)], zero
        else:
            arm_other, velocity = zero, _mover_velocity(scene, movers[c.other], point, c)
        rows.append([*normal, *_tangents(normal), *arm_body, *arm_other, *velocity, float(c.mu) if frictional else 0.0])
    return np.array(rows, dtype=float).reshape(len(rows), 1 + dim * (dim + 3))


def _contact_rows_compiled(scene: Scene, links: list[tuple[int, int]], frictional: bool) -> np.ndarray:
    """:func:`_contact_rows_python` in the extension's C (the same numbers): the scene's vectors gathered, a robot
    link's point velocity worked out here (:func:`_mover_velocity`), the rest in one call (a fresh scene's audit
    arrays in ~5x less time)."""
    dim, contacts = scene.dimension, scene.contacts
    movers = {mover.name: mover for mover in scene.movers}
    no_twist, no_point = np.zeros(scene.twist_size), np.zeros(dim)
    twists, origins, driven, joints = [], [], [], []
    for c, (_, other) in zip(contacts, links, strict=True):
        mover = movers[c.other] if other < 0 else None
        twist, origin, velocity, through = no_twist, no_point, no_point, False
        if mover is not None and mover.robot is not None:
            velocity, through = np.array(_mover_velocity(scene, mover, _floats(c.point), c)), True
        elif mover is not None:  # a Scene fills a rigid mover's twist and origin
            twist, origin = cast(np.ndarray, mover.twist), cast(np.ndarray, mover.origin)
        twists.append(twist)
        origins.append(origin)
        driven.append(velocity)
        joints.append(through)
    return audit_rows(
        stack_rows([c.normal for c in contacts], dim),
        stack_rows([c.point for c in contacts], dim),
        stack_rows([b.com for b in scene.bodies], dim),
        np.array(links, dtype=np.int64).reshape(len(links), 2),
        stack_rows(twists, scene.twist_size),
        stack_rows(origins, dim),
        stack_rows(driven, dim),
        np.array(joints, dtype=bool),
        np.array([float(c.mu) if frictional else 0.0 for c in contacts]),
    )


_contact_rows = _contact_rows_compiled if HAVE_AUDIT_ROWS else _contact_rows_python


def _floats(vector: object) -> list[float]:
    """A validated scene vector (a float array) as a list of floats."""
    if isinstance(vector, np.ndarray) and vector.dtype == np.float64:
        return vector.tolist()  # type: ignore[no-any-return]
    return np.asarray(vector, dtype=float).tolist()  # type: ignore[no-any-return]


def _tangents(n: list[float]) -> list[float]:
    """The tangent rows of :func:`~quasistatic.model.kinematics.contact_frames` (recomputed) for the unit normal ``n``, flattened."""
    if len(n) == 2:
        return [n[1], -n[0]]
    x, y, z = n
    a = [abs(x), abs(y), abs(z)]
    axis = a.index(min(a))  # the first smallest, as np.argmin
    # t1 = n x e_axis, normalised; t2 = n x t1
    t = [(0.0, z, -y), (-z, 0.0, x), (y, -x, 0.0)][axis]
    norm = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    t0, t1, t2 = t[0] / norm, t[1] / norm, t[2] / norm
    return [t0, t1, t2, y * t2 - z * t1, z * t0 - x * t2, x * t1 - y * t0]


def _mover_velocity(scene: Scene, mover: Mover, point: list[float], contact: Contact) -> list[float]:
    """World velocity of the mover's material point at ``point`` (recomputed here, not taken from assembly)."""
    if mover.robot is not None:
        joints = _floats(scene.robot(mover.robot).joint_velocities)
        rows = np.asarray(contact.jacobian, dtype=float).tolist()
        return [sum(a * w for a, w in zip(row, joints, strict=True)) for row in rows]
    twist = _floats(mover.twist)
    r = [x - y for x, y in zip(point, _floats(mover.origin), strict=True)]
    if len(point) == 2:
        return [twist[0] - twist[2] * r[1], twist[1] + twist[2] * r[0]]
    wx, wy, wz = twist[3:]
    return [twist[0] + wy * r[2] - wz * r[1], twist[1] + wz * r[0] - wx * r[2], twist[2] + wx * r[1] - wy * r[0]]


# Columns of ``Evaluation.sums``: what one pass over the contacts finds (physical units, not yet scaled).
_LINEAR, _ANGULAR = 0, 1  # largest unbalanced force and moment on any body
_CONE = 2  # largest -f_n or excursion outside the friction set [force], >= 0
_PENETRATION = 3  # largest -u_n [velocity], >= 0
_NORMAL_POWER = 4  # largest |f_n u_n| [power]
_SHORTFALL = 5  # largest shortfall from maximum dissipation [power], >= 0
_SUPPLIED = 6  # power the movers put in
_DISSIPATED = 7  # power lost to friction
_RAISED = 8  # power against gravity and applied wrenches
_CHECK = 9  # sum of every velocity, force and net wrench: not finite when any of them is not
_MISALIGN = 10  # exact 3-D cones: largest distance of a sliding contact's friction from -mu f_n slip/|slip| [force]


@dataclass(frozen=True)
class Evaluation:
    """One pass over a motion's contacts (physical units, world frame).

    Attributes
    ----------
    sums : (10,) the quantities indexed by ``_LINEAR`` ... ``_CHECK``
    velocities : (m, d) relative velocity of ``body`` with respect to ``other`` at each contact
    slips : (m, d) its tangential part ``u - u_n n``
    normal : (m, 3) per contact: normal velocity ``u_n``, slip speed ``|slip|``, normal force ``f_n``
    """

    sums: np.ndarray
    velocities: np.ndarray
    slips: np.ndarray
    normal: np.ndarray


def _evaluate(geometry: AuditGeometry, T: np.ndarray, forces: np.ndarray, slide_speed: float = np.inf) -> Evaluation:
    """Run the law kernel on twists ``T`` (bodies, k) and world forces ``forces`` (m, d), physical units."""
    T = np.ascontiguousarray(T, dtype=float)
    forces = np.ascontiguousarray(forces, dtype=float)
    arrays = geometry.arrays
    kernel = _array_kernel(geometry.dimension, len(arrays[0]))
    if kernel is not None:
        return Evaluation(*kernel(arrays[0], arrays[1], arrays[2], T, forces, arrays[3], arrays[4], geometry.facet_scale, slide_speed))
    # Plain Python, few contacts: the kernel's loop on nested lists beats the ~60 calls of its whole-array twin.
    kernel = _laws_2d if geometry.dimension == 2 else _laws_3d
    lists = geometry.lists
    assert lists is not None
    sums, u, slips, normal = kernel(
        lists[0], lists[1], lists[2], T.tolist(), forces.tolist(), lists[3], lists[4], geometry.facet_scale, slide_speed
    )
    return Evaluation(np.asarray(sums), np.asarray(u), np.asarray(slips), np.asarray(normal))


def _array_kernel(dimension: int, contacts: int) -> Callable[..., tuple[np.ndarray, ...]] | None:
    """The laws' kernel on arrays: numba's loops, else their C twin (the ``_kernels`` extension, the same arithmetic),
    else past ``LOOP_CONTACTS`` contacts the numpy twin; None: the loop as plain Python on nested lists."""
    if HAVE_NUMBA:
        return _laws_2d if dimension == 2 else _laws_3d
    if HAVE_KERNELS:
        return audit_laws
    return _laws_numpy if contacts > LOOP_CONTACTS else None


@np.errstate(all="ignore")  # values that are not finite fail by the check sum, as in the loop: no warning
def _laws_numpy(
    links: np.ndarray,
    contacts: np.ndarray,
    loads: np.ndarray,
    T: np.ndarray,
    f: np.ndarray,
    facets: np.ndarray,
    directions: np.ndarray,
    facet_scale: float,
    slide_speed: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_laws_2d` and :func:`_laws_3d` in whole-array numpy calls (without numba, on many contacts).

    The same quantities to round-off (sums taken in another order); ``T``'s width (3 or 6) gives the dimension.
    """
    d = 2 if T.shape[1] == 3 else 3
    m, n_bodies = links.shape[0], loads.shape[0]
    body, other = links[:, 0], links[:, 1]
    arms = contacts[:, d * d : d * d + 2 * d].reshape(m, 2, d)  # to the point from the body's and the other's com
    mover, mu = contacts[:, d * d + 2 * d : d * d + 3 * d], contacts[:, -1]
    # incidences (bodies, m): 1 where a contact has the body as its ``body`` (``other``); a mover is no row
    on_body = (body == np.arange(n_bodies)[:, None]).astype(float)
    on_other = (other == np.arange(n_bodies)[:, None]).astype(float)
    u = _point_velocities(T[body], arms[:, 0], d) - _point_velocities(on_other.T @ T, arms[:, 1], d) - mover
    # frame rows (normal, tangents) against forces and velocities: (m, d, 2)
    local = contacts[:, : d * d].reshape(m, d, d) @ np.stack((f, u), axis=2)
    f_n, u_n, f_t, u_t = local[:, 0, 0], local[:, 0, 1], local[:, 1:, 0], local[:, 1:, 1]
    radius = mu * np.maximum(f_n, 0.0)
    sums = np.zeros(11)
    if len(facets) > 0:  # 3-D pyramid: the largest facet excursion, and the support function of the slip
        outside = (f_t @ facets.T).max(axis=1) - radius * facet_scale
        support = (-(u_t @ directions.T)).max(axis=1)
    else:
        outside = np.sqrt((f_t * f_t).sum(axis=1)) - radius
        support = np.sqrt((u_t * u_t).sum(axis=1))
        sliding = support > slide_speed
        if d == 3 and sliding.any():  # sliding: the friction must be -mu f_n slip/|slip| exactly
            e = f_t[sliding] + (radius[sliding] / support[sliding])[:, None] * u_t[sliding]
            sums[_MISALIGN] = np.sqrt((e * e).sum(axis=1)).max()
    sums[_CONE] = max(0.0, float(np.concatenate((-f_n, outside)).max(initial=0.0)))
    sums[_PENETRATION] = (-u_n).max(initial=0.0)
    sums[_NORMAL_POWER] = np.abs(f_n * u_n).max(initial=0.0)
    sums[_SHORTFALL] = (radius * support + (f_t * u_t).sum(axis=1)).max(initial=0.0)
    sums[_SUPPLIED] = (f * mover).sum()
    sums[_DISSIPATED] = -((f * u).sum() - (f_n * u_n).sum())  # tangential force . slip
    slips = u - u_n[:, None] * contacts[:, :d]
    normal = np.column_stack((u_n, np.sqrt((slips * slips).sum(axis=1)), f_n))
    totals = loads + on_body @ np.hstack((f, _moments(arms[:, 0], f, d))) - on_other @ np.hstack((f, _moments(arms[:, 1], f, d)))
    raised = -float((loads * T).sum())
    sums[_LINEAR] = np.abs(totals[:, :d]).max(initial=0.0)
    sums[_ANGULAR] = np.abs(totals[:, d:]).max(initial=0.0)
    sums[_RAISED] = raised
    sums[_CHECK] = f.sum() + u.sum() + totals.sum() + raised
    return sums, u, slips, normal


# Cross products by columns, (a x b)_i = a_{i+1} b_{i+2} - a_{i+2} b_{i+1}, written out rather than model.kinematics.cross
# so that v + w x r is summed left to right as the loop kernel sums it (the same rounding).
_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])


def _point_velocities(T: np.ndarray, arms: np.ndarray, d: int) -> np.ndarray:
    """Velocities (m, d) of the points at ``arms`` from their bodies' coms, for twists ``T`` (m, 3 or 6)."""
    if d == 2:
        return T[:, :2] + T[:, 2:3] * arms[:, ::-1] * np.array([-1.0, 1.0])
    w = T[:, 3:]
    return T[:, :3] + w[:, _NEXT] * arms[:, _AFTER] - w[:, _AFTER] * arms[:, _NEXT]


def _moments(arms: np.ndarray, f: np.ndarray, d: int) -> np.ndarray:
    """Moments (m, 1 or 3) of forces ``f`` (m, d) applied at ``arms`` from the coms."""
    if d == 2:
        return arms[:, :1] * f[:, 1:] - arms[:, 1:] * f[:, :1]
    return arms[:, _NEXT] * f[:, _AFTER] - arms[:, _AFTER] * f[:, _NEXT]


@njit
def _allocate(m: int, d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    return np.zeros(11), np.empty((m, d)), np.empty((m, d)), np.empty((m, 3))


@njit
def _laws_2d(
    links: np.ndarray,
    contacts: np.ndarray,
    loads: np.ndarray,
    T: np.ndarray,
    f: np.ndarray,
    facets: np.ndarray,
    directions: np.ndarray,
    facet_scale: float,
    slide_speed: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Velocities, net wrenches and the per-contact laws of a planar motion, in one loop over the contacts.

    ``links`` (m, 2), ``contacts`` (m, 11), ``loads`` (bodies, 3) as in :class:`AuditGeometry`;
    ``T`` (bodies, 3) twists, ``f`` (m, 2) world forces on each contact's body.
    Indexed as ``x[i][j]`` so that it also runs on nested lists (without numba).
    """
    m = len(links)
    nb = len(loads)
    sums, u, slips, normal = _allocate(m, 2)
    totals = np.zeros((nb, 3))
    for a in range(nb):
        for j in range(3):
            totals[a][j] = loads[a][j]
    cone = penetration = normal_power = shortfall = supplied = dissipated = check = 0.0
    for i in range(m):
        b, o = links[i][0], links[i][1]
        c = contacts[i]
        nx, ny, tx, ty, rbx, rby, rox, roy, mvx, mvy, mu = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10]
        fx, fy = f[i][0], f[i][1]
        t = T[b]
        vx, vy, w = t[0], t[1], t[2]
        ux, uy = vx - w * rby, vy + w * rbx
        total = totals[b]
        total[0] += fx
        total[1] += fy
        total[2] += rbx * fy - rby * fx
        if o >= 0:
            t = T[o]
            vx, vy, w = t[0], t[1], t[2]
            ux, uy = ux - (vx - w * roy), uy - (vy + w * rox)
            total = totals[o]
            total[0] -= fx
            total[1] -= fy
            total[2] -= rox * fy - roy * fx
        else:
            ux, uy = ux - mvx, uy - mvy
            supplied += fx * mvx + fy * mvy
        f_n, f_t = fx * nx + fy * ny, fx * tx + fy * ty
        u_n, u_t = ux * nx + uy * ny, ux * tx + uy * ty
        radius = mu * max(f_n, 0.0)
        cone = max(cone, -f_n, abs(f_t) - radius)
        penetration = max(penetration, -u_n)
        normal_power = max(normal_power, abs(f_n * u_n))
        shortfall = max(shortfall, radius * abs(u_t) + f_t * u_t)
        dissipated -= fx * ux + fy * uy - f_n * u_n  # tangential force . slip
        check += fx + fy + ux + uy
        sx, sy = ux - u_n * nx, uy - u_n * ny
        u[i][0], u[i][1] = ux, uy
        slips[i][0], slips[i][1] = sx, sy
        normal[i][0], normal[i][1], normal[i][2] = u_n, np.sqrt(sx * sx + sy * sy), f_n
    _finish(sums, totals, loads, T, 2, check)
    sums[_CONE], sums[_PENETRATION], sums[_NORMAL_POWER], sums[_SHORTFALL] = cone, penetration, normal_power, shortfall
    sums[_SUPPLIED], sums[_DISSIPATED] = supplied, dissipated
    return sums, u, slips, normal


@njit
def _laws_3d(
    links: np.ndarray,
    contacts: np.ndarray,
    loads: np.ndarray,
    T: np.ndarray,
    f: np.ndarray,
    facets: np.ndarray,
    directions: np.ndarray,
    facet_scale: float,
    slide_speed: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_laws_2d` in space: ``contacts`` (m, 19), ``T`` (bodies, 6), ``f`` (m, 3).

    ``facets`` and ``directions`` (K, 2) are the pyramid's (empty for exact cones).
    """
    m = len(links)
    nb = len(loads)
    pyramid = len(facets) > 0
    misalign = 0.0
    sums, u, slips, normal = _allocate(m, 3)
    totals = np.zeros((nb, 6))
    for a in range(nb):
        for j in range(6):
            totals[a][j] = loads[a][j]
    cone = penetration = normal_power = shortfall = supplied = dissipated = check = 0.0
    for i in range(m):
        b, o = links[i][0], links[i][1]
        c = contacts[i]
        nx, ny, nz, ax, ay, az, bx, by, bz = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8]
        rx, ry, rz, sx, sy, sz, mx, my, mz, mu = c[9], c[10], c[11], c[12], c[13], c[14], c[15], c[16], c[17], c[18]
        fx, fy, fz = f[i][0], f[i][1], f[i][2]
        t = T[b]
        v0, v1, v2, w0, w1, w2 = t[0], t[1], t[2], t[3], t[4], t[5]
        ux, uy, uz = v0 + w1 * rz - w2 * ry, v1 + w2 * rx - w0 * rz, v2 + w0 * ry - w1 * rx
        total = totals[b]
        total[0] += fx
        total[1] += fy
        total[2] += fz
        total[3] += ry * fz - rz * fy
        total[4] += rz * fx - rx * fz
        total[5] += rx * fy - ry * fx
        if o >= 0:
            t = T[o]
            v0, v1, v2, w0, w1, w2 = t[0], t[1], t[2], t[3], t[4], t[5]
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
        f_n = fx * nx + fy * ny + fz * nz
        f_1, f_2 = fx * ax + fy * ay + fz * az, fx * bx + fy * by + fz * bz
        u_n = ux * nx + uy * ny + uz * nz
        u_1, u_2 = ux * ax + uy * ay + uz * az, ux * bx + uy * by + uz * bz
        radius = mu * max(f_n, 0.0)
        if pyramid:
            outside = -np.inf
            support = -np.inf
            for k in range(len(facets)):
                outside = max(outside, facets[k][0] * f_1 + facets[k][1] * f_2)
                support = max(support, -(directions[k][0] * u_1 + directions[k][1] * u_2))
            outside -= radius * facet_scale
        else:
            outside = np.sqrt(f_1 * f_1 + f_2 * f_2) - radius
            support = np.sqrt(u_1 * u_1 + u_2 * u_2)
            if support > slide_speed:  # sliding: the friction must be -mu f_n slip/|slip| exactly (linear in its error)
                e_1, e_2 = f_1 + radius * u_1 / support, f_2 + radius * u_2 / support
                misalign = max(misalign, np.sqrt(e_1 * e_1 + e_2 * e_2))
        cone = max(cone, -f_n, outside)
        penetration = max(penetration, -u_n)
        normal_power = max(normal_power, abs(f_n * u_n))
        shortfall = max(shortfall, radius * support + f_1 * u_1 + f_2 * u_2)
        dissipated -= fx * ux + fy * uy + fz * uz - f_n * u_n  # tangential force . slip
        check += fx + fy + fz + ux + uy + uz
        px, py, pz = ux - u_n * nx, uy - u_n * ny, uz - u_n * nz
        u[i][0], u[i][1], u[i][2] = ux, uy, uz
        slips[i][0], slips[i][1], slips[i][2] = px, py, pz
        normal[i][0], normal[i][1], normal[i][2] = u_n, np.sqrt(px * px + py * py + pz * pz), f_n
    _finish(sums, totals, loads, T, 3, check)
    sums[_CONE], sums[_PENETRATION], sums[_NORMAL_POWER], sums[_SHORTFALL] = cone, penetration, normal_power, shortfall
    sums[_MISALIGN] = misalign
    sums[_SUPPLIED], sums[_DISSIPATED] = supplied, dissipated
    return sums, u, slips, normal


@njit
def _finish(sums: np.ndarray, totals: np.ndarray, loads: np.ndarray, T: np.ndarray, dim: int, check: float) -> None:
    """Largest unbalanced force and moment, the power against the loads and the finiteness check, into ``sums``."""
    linear = angular = raised = 0.0
    for a in range(len(loads)):
        for j in range(len(totals[a])):
            check += totals[a][j]
            x = abs(totals[a][j])
            if j < dim:
                linear = max(linear, x)
            else:
                angular = max(angular, x)
            raised -= loads[a][j] * T[a][j]
    sums[_LINEAR], sums[_ANGULAR], sums[_RAISED], sums[_CHECK] = linear, angular, raised, check + raised


def _twist_array(geometry: AuditGeometry, twists: dict[str, np.ndarray]) -> np.ndarray:
    return np.array([np.asarray(twists[name], dtype=float) for name in geometry.names], dtype=float)


def _balance(sums: np.ndarray) -> PowerBalance:
    supplied, raised, dissipated = float(sums[_SUPPLIED]), float(sums[_RAISED]), float(sums[_DISSIPATED])
    return PowerBalance(supplied, raised, dissipated, supplied - raised - dissipated)


def relative_velocities(scene: Scene, twists: dict[str, np.ndarray]) -> np.ndarray:
    """World velocity of ``body`` relative to ``other`` at each contact point, (m, d)."""
    geometry = AuditGeometry.of(scene)
    return _evaluate(geometry, _twist_array(geometry, twists), np.zeros((len(scene.contacts), scene.dimension))).velocities


def power_balance(scene: Scene, twists: dict[str, np.ndarray], forces: np.ndarray) -> PowerBalance:
    """Input, gravity, dissipation and residual powers of one motion [force x length/time]."""
    geometry = AuditGeometry.of(scene)
    return _balance(_evaluate(geometry, _twist_array(geometry, twists), forces).sums)


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
    geometry = AuditGeometry.of(scene)
    sliding = MODE_SPEED * scales.velocity
    audit, power, evaluation = _audit(_evaluate(geometry, _twist_array(geometry, twists), forces, sliding), scales, tolerance)
    return audit, power, [tuple(u) for u in evaluation.velocities.tolist()]


def audit_arrays(
    geometry: AuditGeometry, twists: np.ndarray, forces: np.ndarray, scales: Scales, tolerance: float = DEFAULT_TOLERANCE
) -> tuple[Audit, PowerBalance, Evaluation]:
    """:func:`audit_motion` on twists as an array (bodies in scene order, k), plus the per-contact evaluation.

    The evaluation carries each contact's relative velocity, slip, normal
    velocity and normal force [physical units], for the report.
    """
    return _audit(_evaluate(geometry, twists, forces, MODE_SPEED * scales.velocity), scales, tolerance)


def _audit(evaluation: Evaluation, scales: Scales, tolerance: float) -> tuple[Audit, PowerBalance, Evaluation]:
    F, L, V = scales.force, scales.length, scales.velocity
    sums = evaluation.sums.tolist()
    power = _balance(evaluation.sums)
    equilibrium = max(sums[_LINEAR] / F, sums[_ANGULAR] / (F * L))
    if not math.isfinite(sums[_CHECK]):  # a NaN can hide from max(); no non-finite motion passes
        equilibrium = math.inf
    audit = Audit(
        equilibrium,
        max(0.0, sums[_CONE] / F),
        max(sums[_PENETRATION] / V, sums[_NORMAL_POWER] / (F * V)),
        max(sums[_SHORTFALL] / (F * V), sums[_MISALIGN] / F),
        abs(power.residual) / (F * V),
        tolerance,
    )
    return audit, power, evaluation
