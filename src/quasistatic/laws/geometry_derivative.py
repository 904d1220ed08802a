"""Derivatives of a fixed-mode motion with respect to the contact geometry: each contact's point and normal.

The fixed-mode laws ``F(x; J, b) = 0`` (:mod:`.fixed_modes`) depend on the
geometry through ``J`` (each contact frame's rows ``f`` and the arms ``r`` from
the coms: a row is ``[f, r x f]``) and ``b`` (the mover's point velocity in the
contact frame). For a change ``dJ, db`` of the data at the polished motion ``x``
the laws change by (analytically, at fixed ``x``)

    equilibrium   sum_i dJ_i^T c_i + J_t,i^T dc_t,i   (dc_t: a sliding contact's friction turning with its slip)
    closed        dJ_n q - db_n
    rolling       dJ_t q - db_t

and the implicit function theorem gives ``dx = -F_x^{-1} dF``. The parameters,
per contact, in physical units: its point's world coordinates [length], and a
turn of its normal about each world axis (about the plane's normal in 2-D)
[rad]. A turned normal turns its frame as :func:`~quasistatic.model.kinematics.contact_frames`
builds it (``t1 = n x e / |n x e|``, ``t2 = n x t1``). A robot-driven contact's
Jacobian is data of the scene and is kept as given; a rigid mover's point
velocity ``v + w x (p - origin)`` follows its point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import FloatArray
from ..model.kinematics import cross
from .assemble import Problem
from .fixed_modes import ROLLING, SEPARATING, SLIDING, FixedModeLaws
from .modes import ModeMasks
from .sensitivity import Singular, force_derivative, polish

__all__ = ["GeometryDerivative", "geometry_parameters", "geometry_derivative"]


@dataclass(frozen=True)
class GeometryDerivative:
    """Derivatives per physical unit of each geometry parameter (G of them), in scene-relative units.

    ``dq`` (k n, G); ``c`` (m, d) contact-frame forces and ``dc`` (m, d, G) their rates in the (turning) frames;
    ``dframes`` (m, d, d, G) the frames' rates, so that a world force's rate is ``dframes^T c + frames^T dc``.
    """

    dq: FloatArray
    c: FloatArray
    dc: FloatArray
    dframes: FloatArray


@dataclass(frozen=True)
class _Change:
    """What one parameter changes: contact ``contact``'s frame rows ``dframe`` (d, d) and arm ``darm`` (d,), scene-relative."""

    contact: int
    dframe: FloatArray
    darm: FloatArray


def geometry_parameters(dimension: int, m: int) -> tuple[str, ...]:
    """Names of the parameters, contact by contact: ``contacts[i].point.x`` ..., then ``contacts[i].normal.turn_x`` ...
    (``normal.turn`` in 2-D: counterclockwise)."""
    axes = "xyz"[:dimension]
    turns = ("turn",) if dimension == 2 else ("turn_x", "turn_y", "turn_z")
    return tuple(
        name for i in range(m) for name in [f"contacts[{i}].point.{a}" for a in axes] + [f"contacts[{i}].normal.{t}" for t in turns]
    )


def geometry_derivative(
    problem: Problem, masks: ModeMasks, q: FloatArray, c: FloatArray, velocity_rates: FloatArray | None = None
) -> GeometryDerivative | Singular:
    """The derivative of the motion ``(q, c)`` with modes ``masks`` per unit of each of :func:`geometry_parameters`,
    then of R more parameters that only move the movers' points: ``velocity_rates`` (m, d, R), the world velocity
    of each contact's mover point per unit of each [length/time per parameter unit] (a robot's joint positions)."""
    laws = FixedModeLaws(problem, masks)
    x = polish(laws, laws.start(q, c, nonnegative=False))
    if isinstance(x, Singular):
        return x
    changes = [change for i in range(problem.n_contacts) for change in _changes(problem, i)]
    q, forces = laws.motion(x)
    u = problem.velocities(q)
    (m, d, n), R = problem.J.shape, 0 if velocity_rates is None else velocity_rates.shape[2]
    G = len(changes) + R
    dJ, db = np.zeros((m, d, n, G)), np.zeros((m, d, G))
    for g, change in enumerate(changes):
        dJ[change.contact, :, :, g], db[change.contact, :, g] = _data_change(problem, change)
    if velocity_rates is not None:
        db[:, :, len(changes) :] = np.einsum("mst,mtR->msR", problem.frames, velocity_rates) / problem.scales.velocity
    dF = np.stack([_residual_change(laws, q, forces, u, dJ[..., g], db[..., g]) for g in range(G)], axis=1)
    dx = -np.linalg.solve(laws.jacobian(x), dF).astype(float)
    dq = dx[:n]
    du = np.einsum("mdnG,n->mdG", dJ, q) + np.einsum("mdn,nG->mdG", problem.J, dq) - db
    dc = force_derivative(laws, laws.column.astype(float), dx, forces, u, du)
    dframes = np.zeros((m, d, d, G))
    for g, change in enumerate(changes):
        dframes[change.contact, :, :, g] = change.dframe
    return GeometryDerivative(dq, forces, dc, dframes)


def _changes(problem: Problem, i: int) -> list[_Change]:
    """Contact ``i``'s parameters: its point along each world axis, then its normal turned about each axis."""
    d = problem.dimension
    frame = problem.frames[i]
    L = problem.scales.length
    none = np.zeros((d, d))
    points = [_Change(i, none, np.eye(d)[a] / L) for a in range(d)]
    if d == 2:
        n = frame[1]
        dn = np.array([-n[1], n[0]])
        return [*points, _Change(i, np.array([[dn[1], -dn[0]], dn]), np.zeros(2))]
    return points + [_Change(i, _turned_frame(frame, cross(np.eye(3)[a], frame[2])), np.zeros(3)) for a in range(3)]


def _turned_frame(frame: FloatArray, dn: FloatArray) -> FloatArray:
    """Rates of :func:`contact_frames`'s rows for the normal's rate ``dn`` (its helper axis ``e`` fixed)."""
    n = frame[2]
    e = np.zeros(3)
    e[np.argmin(np.abs(n))] = 1.0
    a = cross(n, e)
    t1 = a / np.linalg.norm(a)
    da = cross(dn, e)
    dt1 = (da - t1 * (t1 @ da)) / np.linalg.norm(a)
    return np.array([dt1, cross(dn, t1) + cross(n, dt1), dn])


def _data_change(problem: Problem, change: _Change) -> tuple[FloatArray, FloatArray]:
    """(dJ_i (d, k n), db_i (d,)) of one parameter, scene-relative per physical unit."""
    scene, i = problem.scene, change.contact
    contact = scene.contacts[i]
    d, k = problem.dimension, scene.twist_size
    frame, dframe = problem.frames[i], change.dframe
    index = {body.name: a for a, body in enumerate(scene.bodies)}
    dJ = np.zeros((d, problem.J.shape[2]))
    for name, sign in ((contact.body, 1.0), (contact.other, -1.0)):
        if name not in index:
            continue
        com = (np.asarray(scene.bodies[index[name]].com, dtype=float) - problem.scales.origin) / problem.scales.length
        arm = (np.asarray(contact.point, dtype=float) - problem.scales.origin) / problem.scales.length - com
        block = _rows(dframe, arm) + _arm_rows(frame, change.darm)
        dJ[:, index[name] * k : (index[name] + 1) * k] += sign * block
    return dJ, dframe @ (frame.T @ problem.b[i]) + frame @ _mover_rate(problem, i, change.darm)


def _rows(frame: FloatArray, arm: FloatArray) -> FloatArray:
    """``[f, r x f]`` for each row ``f`` of ``frame`` (``r_x f_y - r_y f_x`` in 2-D)."""
    if frame.shape[0] == 2:
        return np.column_stack([frame, arm[0] * frame[:, 1] - arm[1] * frame[:, 0]])
    return np.column_stack([frame, cross(arm[None, :], frame)])


def _arm_rows(frame: FloatArray, darm: FloatArray) -> FloatArray:
    """The rows' rate for an arm rate ``darm``: ``[0, dr x f]``."""
    rows = _rows(frame, darm)
    rows[:, : frame.shape[0]] = 0.0
    return rows


def _mover_rate(problem: Problem, i: int, darm: FloatArray) -> FloatArray:
    """Rate of a rigid mover's world point velocity (scene-relative) as the contact point moves by ``darm`` (scene-relative)."""
    scene = problem.scene
    movers = {mover.name: mover for mover in scene.movers}
    mover = movers.get(scene.contacts[i].other)
    if mover is None or mover.robot is not None or not np.any(darm):
        return np.zeros(problem.dimension)  # a free body's motion is unknown; a robot's contact Jacobian is data
    assert mover.twist is not None  # filled in by the Scene
    d, spin = problem.dimension, np.asarray(mover.twist, dtype=float)[problem.dimension :]
    rate = spin[0] * np.array([-darm[1], darm[0]]) if d == 2 else cross(spin, darm)
    return rate * problem.scales.length / problem.scales.velocity


def _residual_change(laws: FixedModeLaws, q: FloatArray, forces: FloatArray, u: FloatArray, dJ: FloatArray, db: FloatArray) -> FloatArray:
    """The fixed-mode residual's change at fixed unknowns for a change ``dJ`` (m, d, n), ``db`` (m, d) of the data."""
    n, t = laws.n, laws.t
    dF = np.zeros(laws.size)
    dv = np.einsum("mdn,n->md", dJ, q) - db  # the contact velocities' change at fixed twist
    for i in np.flatnonzero(laws.kind != SEPARATING):
        col = int(laws.column[i])
        dF[:n] += dJ[i].T @ forces[i]
        dF[col] = dv[i, t]
        if laws.kind[i] == ROLLING:
            dF[col + 1 : col + 1 + t] = dv[i, :t]
        elif laws.kind[i] == SLIDING and laws.mu[i] > 0 and t == 2:
            speed = float(np.linalg.norm(u[i, :t]))
            e = u[i, :t] / speed
            turn = -laws.mu[i] * forces[i, t] * (np.eye(t) - np.outer(e, e)) / speed @ dv[i, :t]
            dF[:n] += laws.J[i, :t].T @ turn
    return dF
