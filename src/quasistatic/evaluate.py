"""From a backend's raw numbers (scene-relative) to an audited Motion (physical units)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .audit import DEFAULT_TOLERANCE, audit_motion_velocities
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
    scene, scales = problem.scene, problem.scales
    k, d = scene.twist_size, scene.dimension
    V = scales.velocity
    units = np.array([V] * d + [V / scales.length] * (k - d))
    twists = np.reshape(q, (-1, k)) * units
    return {b.name: twists[i] for i, b in enumerate(scene.bodies)}


def to_motion(
    problem: Problem,
    raw: RawMotion,
    ranges: list[tuple[float, float | None]] | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
) -> Motion:
    """Audit a raw motion on the original data and name each contact's mode."""
    scene, scales = problem.scene, problem.scales
    twists = physical_twists(problem, raw.q)
    forces = np.matmul(raw.c[:, None, :], problem.frames)[:, 0, :] * scales.force
    audit, power, u = audit_motion_velocities(scene, twists, forces, scales, tolerance)
    threshold = MODE_TOLERANCE * scales.velocity
    # Contact by contact in scalar Python: for a few contacts that is cheaper than numpy calls.
    contacts = []
    for i, (contact, u_i, f_i) in enumerate(zip(scene.contacts, u, forces.tolist(), strict=True)):
        n = contact.normal.tolist()  # type: ignore[attr-defined]
        u_n = _dot(u_i, n)
        slip = [u_i[0] - u_n * n[0], u_i[1] - u_n * n[1]]
        if len(n) == 3:
            slip.append(u_i[2] - u_n * n[2])
        range_i = None
        if ranges is not None:
            lo, hi = ranges[i]
            range_i = (lo * scales.force, None if hi is None else hi * scales.force)
        contacts.append(
            ContactResult(
                body=contact.body,
                other=contact.other,
                mode=_mode(u_n, math.sqrt(_dot(slip, slip)), threshold),
                force=forces[i],
                normal_force=_dot(f_i, n),
                slip=np.array(slip),
                normal_velocity=u_n,
                normal_force_range=range_i,
            )
        )
    extremes = tuple(physical_twists(problem, e) for e in raw.extremes)
    return Motion(twists, tuple(contacts), power, audit, raw.continuum, extremes, raw.unbounded)


def _dot(a: list[float] | tuple[float, ...], b: list[float]) -> float:
    if len(a) == 2:
        return a[0] * b[0] + a[1] * b[1]
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _mode(u_n: float, speed: float, threshold: float) -> Mode:
    if u_n > threshold:
        return "separating"
    if speed > threshold:
        return "sliding"
    return "rolling"
