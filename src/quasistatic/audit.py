"""Independent audit of a motion against the laws, on the original scene data.

Nothing here reads the assembled matrices: velocities, loads and moments are
recomputed from the scene in world frame, so an assembly bug cannot hide.
Residuals are divided by the scene's scales (force, length, velocity).
"""

from __future__ import annotations

import numpy as np

from .friction import FrictionModel
from .problem import Scales, contact_frame, mover_point_velocity
from .scene import Scene
from .solution import Audit, PowerBalance

__all__ = ["relative_velocities", "power_balance", "audit_motion", "DEFAULT_TOLERANCE"]

DEFAULT_TOLERANCE = 1e-6


def _point_velocity(twist: np.ndarray, r: np.ndarray) -> np.ndarray:
    if r.size == 2:
        return twist[:2] + twist[2] * np.array([-r[1], r[0]])
    return twist[:3] + np.cross(twist[3:], r)


def _cross(r: np.ndarray, f: np.ndarray) -> np.ndarray:
    if r.size == 2:
        return np.array([r[0] * f[1] - r[1] * f[0]])
    return np.cross(r, f)


def relative_velocities(scene: Scene, twists: dict[str, np.ndarray]) -> np.ndarray:
    """World velocity of ``body`` relative to ``other`` at each contact point, (m, d)."""
    coms = {b.name: np.asarray(b.com) for b in scene.bodies}
    out = np.zeros((len(scene.contacts), scene.dimension))
    for i, c in enumerate(scene.contacts):
        p = np.asarray(c.point)
        v = _point_velocity(twists[c.body], p - coms[c.body])
        if c.other in coms:
            v = v - _point_velocity(twists[c.other], p - coms[c.other])
        else:
            v = v - mover_point_velocity(scene, c.other, p, c.jacobian)
        out[i] = v
    return out


def power_balance(scene: Scene, twists: dict[str, np.ndarray], forces: np.ndarray) -> PowerBalance:
    """Input, gravity, dissipation and residual powers of one motion [force x length/time]."""
    dim = scene.dimension
    free = {b.name for b in scene.bodies}
    u = relative_velocities(scene, twists)
    supplied = 0.0
    dissipated = 0.0
    for i, c in enumerate(scene.contacts):
        n = np.asarray(c.normal)
        if c.other not in free:
            supplied += float(forces[i] @ mover_point_velocity(scene, c.other, np.asarray(c.point), c.jacobian))
        f_t = forces[i] - (forces[i] @ n) * n
        dissipated -= float(f_t @ u[i])
    raised = 0.0
    for b in scene.bodies:
        load = np.array(b.wrench, dtype=float)
        load[:dim] += b.mass * np.asarray(scene.gravity)
        raised -= float(load @ twists[b.name])
    return PowerBalance(supplied, raised, dissipated, supplied - raised - dissipated)


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
    model = scene.friction
    assert isinstance(model, FrictionModel)
    u = relative_velocities(scene, twists)
    F, L, V = scales.force, scales.length, scales.velocity
    equilibrium = _equilibrium_residual(scene, forces, F, L)
    cone = dissipation = complementarity = 0.0
    for i, c in enumerate(scene.contacts):
        n = np.asarray(c.normal)
        frame = contact_frame(n)
        f_n = float(forces[i] @ n)
        f_t = frame[:-1] @ forces[i]
        u_n = float(u[i] @ n)
        u_t = frame[:-1] @ u[i]
        mu = c.mu if model.kind != "none" else 0.0
        cone = max(cone, -f_n / F, _outside_friction_set(f_t, mu * max(f_n, 0.0), model, scene.dimension) / F)
        complementarity = max(complementarity, -u_n / V, abs(f_n * u_n) / (F * V))
        best = mu * max(f_n, 0.0) * _support(-u_t, model, scene.dimension)
        dissipation = max(dissipation, (best + float(f_t @ u_t)) / (F * V))
    power = power_balance(scene, twists, forces)
    audit = Audit(equilibrium, cone, complementarity, dissipation, abs(power.residual) / (F * V), tolerance)
    return audit, power


def _equilibrium_residual(scene: Scene, forces: np.ndarray, F: float, L: float) -> float:
    dim = scene.dimension
    worst = 0.0
    for b in scene.bodies:
        com = np.asarray(b.com)
        total = np.array(b.wrench, dtype=float)
        total[:dim] += b.mass * np.asarray(scene.gravity)
        for i, c in enumerate(scene.contacts):
            sign = 1.0 if c.body == b.name else -1.0 if c.other == b.name else 0.0
            if sign:
                total[:dim] += sign * forces[i]
                total[dim:] += sign * _cross(np.asarray(c.point) - com, forces[i])
        worst = max(worst, float(np.max(np.abs(total[:dim]))) / F, float(np.max(np.abs(total[dim:]))) / (F * L))
    return worst


def _outside_friction_set(f_t: np.ndarray, radius: float, model: FrictionModel, dim: int) -> float:
    """How far a tangential force lies outside the friction set of the given radius."""
    if dim == 2 or model.kind != "pyramid":
        return max(0.0, float(np.linalg.norm(f_t)) - radius)
    k = model.edges
    facet_angles = (2.0 * np.arange(k) + 1.0) * np.pi / k
    facets = np.column_stack([np.cos(facet_angles), np.sin(facet_angles)])
    return max(0.0, float(np.max(facets @ f_t)) - radius * np.cos(np.pi / k))


def _support(direction: np.ndarray, model: FrictionModel, dim: int) -> float:
    """Support function of the unit friction set: max of f . direction over it."""
    if dim == 2 or model.kind != "pyramid":
        return float(np.linalg.norm(direction))
    return float(np.max(model.tangent_directions(3) @ direction))
