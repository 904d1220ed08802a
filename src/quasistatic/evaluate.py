"""From a backend's raw numbers (scene-relative) to an audited Motion (physical units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .audit import DEFAULT_TOLERANCE, audit_motion, relative_velocities
from .problem import Problem
from .solution import ContactResult, Mode, Motion

__all__ = ["RawMotion", "to_motion", "MODE_TOLERANCE"]

MODE_TOLERANCE = 1e-6  # relative speed (per velocity scale) below which a contact is not moving


@dataclass(frozen=True)
class RawMotion:
    """A backend's answer in scene-relative units.

    Attributes
    ----------
    q : (k n,)
        Stacked body twists.
    c : (m, d)
        Contact forces in contact frames (tangent(s), normal), on ``body``.
    extremes : tuple of (k n,) arrays
        For a continuum of motions: its extreme twists.
    unbounded : bool
        For a continuum: it extends to infinity.
    """

    q: np.ndarray
    c: np.ndarray
    extremes: tuple[np.ndarray, ...] = ()
    unbounded: bool = False

    @property
    def continuum(self) -> bool:
        return bool(self.extremes) or self.unbounded


def physical_twists(problem: Problem, q: np.ndarray) -> dict[str, np.ndarray]:
    """Scene-relative stacked twists to named physical twists."""
    k = problem.scene.twist_size
    units = problem.scales.twist_units(problem.dimension)
    return {b.name: q[i * k : (i + 1) * k] * units for i, b in enumerate(problem.scene.bodies)}


def to_motion(
    problem: Problem,
    raw: RawMotion,
    ranges: list[tuple[float, float | None]] | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
) -> Motion:
    """Audit a raw motion on the original data and name each contact's mode."""
    scene, scales = problem.scene, problem.scales
    twists = physical_twists(problem, raw.q)
    forces = np.einsum("mij,mi->mj", problem.frames, raw.c) * scales.force
    u = relative_velocities(scene, twists)
    audit, power = audit_motion(scene, twists, forces, scales, tolerance)
    contacts = []
    for i, contact in enumerate(scene.contacts):
        n = np.asarray(contact.normal)
        u_n = float(u[i] @ n)
        slip = u[i] - u_n * n
        range_i = None
        if ranges is not None:
            lo, hi = ranges[i]
            range_i = (lo * scales.force, None if hi is None else hi * scales.force)
        contacts.append(
            ContactResult(
                body=contact.body,
                other=contact.other,
                mode=_mode(u_n, slip, scales.velocity),
                force=forces[i],
                normal_force=float(forces[i] @ n),
                slip=slip,
                normal_velocity=u_n,
                normal_force_range=range_i,
            )
        )
    extremes = tuple(physical_twists(problem, e) for e in raw.extremes)
    return Motion(twists, tuple(contacts), power, audit, raw.continuum, extremes, raw.unbounded)


def _mode(u_n: float, slip: np.ndarray, velocity_scale: float) -> Mode:
    if u_n > MODE_TOLERANCE * velocity_scale:
        return "separating"
    if float(np.linalg.norm(slip)) > MODE_TOLERANCE * velocity_scale:
        return "sliding"
    return "rolling"
