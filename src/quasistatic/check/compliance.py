"""The audit of a compliant step: equilibrium, the cones and the compatibility of every spring, from the scene itself.

Independent of the program that found the step (:mod:`quasistatic.solvers.compliance`):
it reads the springs from the scene's contacts and robots, moves the bodies and movers
by the reported displacement and the movers' advance, and checks that each spring's
deflection is what that motion leaves at its contact.
"""

from __future__ import annotations

import numpy as np

from ..model import Scales, Scene
from ..model.kinematics import contact_frames
from ..solution import CompliantStep, StepAudit
from ..tolerances import AUDIT, ROUNDOFF, SMALLEST_LENGTH
from .audit import relative_velocities

__all__ = ["audited_step"]

STUCK, LIMIT, OPEN = "stuck", "at friction limit", "open"


def audited_step(
    scene: Scene, scales: Scales, displacements: dict[str, np.ndarray], forces: np.ndarray, message: str, tolerance: float = AUDIT
) -> CompliantStep:
    """The compliant step of world ``forces`` (m, d) and body ``displacements`` [length, rad], audited.

    ``valid`` needs the audit to pass and no loaded contact at its friction limit.
    """
    assert scene.closing_time is not None  # only a scene with a closing time has a step
    h = scene.closing_time
    frames = contact_frames(np.array([c.normal for c in scene.contacts], dtype=float).reshape(-1, scene.dimension))
    local = np.einsum("mst,mt->ms", frames, forces)  # contact-frame forces: tangent(s), normal
    # Body minus other at each point over the step: the displacement as a twist over h, minus each mover's advance.
    moved = h * np.einsum("mst,mt->ms", frames, relative_velocities(scene, {n: d / h for n, d in displacements.items()}))
    deflection = _deflections(scene, frames, forces, local)
    states = _states(scene, local, scales.force * tolerance)
    span = max(float(np.abs(moved).max(initial=0.0)), float(np.abs(deflection).max(initial=0.0)), SMALLEST_LENGTH)
    audit = StepAudit(
        _equilibrium(scene, forces, scales),
        _cone(scene, local) / scales.force,
        _compatibility(moved, deflection, local, states, _frictional(scene)) / span,
        tolerance,
    )
    valid = audit.passed and LIMIT not in states
    # Round-off of the scene's own scales is reported as 0 (as a motion's): a 1e-18 m shift next to 2 mm is not data.
    d = scene.dimension
    units = np.r_[np.full(d, span), np.full(scene.twist_size - d, span / scales.length)] * ROUNDOFF
    shown = {name: np.where(np.abs(value) <= units, 0.0, value) + 0.0 for name, value in displacements.items()}
    forces = np.where(np.abs(forces) <= ROUNDOFF * scales.force, 0.0, forces) + 0.0
    normal_forces = tuple(0.0 if abs(f) <= ROUNDOFF * scales.force else float(f) + 0.0 for f in local[:, -1])
    return CompliantStep(h, shown, forces, normal_forces, states, audit, valid, message)


def _deflections(scene: Scene, frames: np.ndarray, forces: np.ndarray, local: np.ndarray) -> np.ndarray:
    """Each contact's spring deflection (compression positive), contact frame: its own springs, then its robot's joints."""
    d = scene.dimension
    out = np.zeros_like(local)
    for i, contact in enumerate(scene.contacts):
        if contact.stiffness is not None:
            springs = np.full(d, contact.stiffness.tangential)
            springs[-1] = contact.stiffness.normal
            out[i] = local[i] / springs
    driver = {m.name: m.robot for m in scene.movers}
    for robot in scene.robots:
        if robot.joint_stiffness is None:
            continue
        jacobians = {i: c.jacobian for i, c in enumerate(scene.contacts) if driver.get(c.other) == robot.name and c.jacobian is not None}
        torques = np.zeros(robot.joint_velocities.size)
        for i, jacobian in jacobians.items():
            torques += jacobian.T @ forces[i]
        yielded = torques / robot.joint_stiffness  # the joints give way to the load the link carries
        for i, jacobian in jacobians.items():
            out[i] += frames[i] @ (jacobian @ yielded)
    return out


def _states(scene: Scene, local: np.ndarray, zero: float) -> tuple[str, ...]:
    states = []
    for contact, force in zip(scene.contacts, local, strict=True):
        mu = contact.mu if scene.friction.kind != "none" else 0.0
        if force[-1] <= zero:
            states.append(OPEN)
        elif mu > 0 and float(np.linalg.norm(force[:-1])) >= mu * force[-1] - zero:
            states.append(LIMIT)
        else:
            states.append(STUCK)
    return tuple(states)


def _equilibrium(scene: Scene, forces: np.ndarray, scales: Scales) -> float:
    d, worst = scene.dimension, 0.0
    for body in scene.bodies:
        wrench = np.array(scene.load(body), dtype=float)
        for contact, force in zip(scene.contacts, forces, strict=True):
            sign = 1.0 if contact.body == body.name else -1.0 if contact.other == body.name else 0.0
            if sign:
                arm = contact.point - body.com
                wrench[:d] += sign * force
                wrench[d:] += sign * (np.cross(arm, force) if d == 3 else arm[0] * force[1] - arm[1] * force[0])
        moment = float(np.abs(wrench[d:]).max()) / (scales.force * scales.length)
        worst = max(worst, float(np.abs(wrench[:d]).max()) / scales.force, moment)
    return worst


def _cone(scene: Scene, local: np.ndarray) -> float:
    worst = 0.0
    for contact, force in zip(scene.contacts, local, strict=True):
        mu = contact.mu if scene.friction.kind != "none" else 0.0
        worst = max(worst, -float(force[-1]), float(np.linalg.norm(force[:-1])) - mu * float(force[-1]))
    return worst


def _frictional(scene: Scene) -> np.ndarray:
    return np.array([c.mu > 0 and scene.friction.kind != "none" for c in scene.contacts], dtype=bool)


def _compatibility(moved: np.ndarray, deflection: np.ndarray, local: np.ndarray, states: tuple[str, ...], frictional: np.ndarray) -> float:
    """Largest misfit [length]: a stuck spring deflects exactly what the motion leaves (moved = -deflection); an open
    contact's gap does not close; a frictionless one fits along its normal; at the friction limit the normal fits
    and the slip opposes the friction."""
    worst = 0.0
    for i, state in enumerate(states):
        misfit = moved[i] + deflection[i]
        if state == OPEN:
            worst = max(worst, -float(moved[i, -1]))
        elif not frictional[i]:
            worst = max(worst, abs(float(misfit[-1])))
        elif state == STUCK or not local[i, :-1].any():
            worst = max(worst, float(np.abs(misfit).max()))
        else:
            friction = local[i, :-1] / np.linalg.norm(local[i, :-1])
            slip = misfit[:-1]
            opposite = slip + max(0.0, -float(slip @ friction)) * friction  # what is left of the slip once it opposes
            worst = max(worst, abs(float(misfit[-1])), float(np.abs(opposite).max()))
    return worst
