"""From a backend's raw numbers (scene-relative) to an audited Motion (physical units)."""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar, cast

import numpy as np

from .audit import DEFAULT_TOLERANCE, audit_arrays, dropper
from .jit import HAVE_NUMBA, njit
from .problem import Problem
from .solution import ContactResult, Mode, Motion, _lazy_motion

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
    layout = derived(problem, "layout", _Layout)
    return dict(zip(layout.names, np.reshape(q, (-1, layout.units.size)) * layout.units, strict=True))


T = TypeVar("T")
_DERIVED: dict[int, tuple[weakref.ref[Problem], dict[str, Any]]] = {}


def derived(problem: Problem, name: str, build: Callable[[Problem], T]) -> T:
    """``build(problem)``, computed once per Problem object (problems are frozen) and kept with it.

    For the data a solve derives from a problem every time (index arrays,
    contiguous copies, unit vectors, names): solving the same problem again,
    as benchmarks, batches and simulations do, skips that work.
    """
    key = id(problem)
    entry = _DERIVED.get(key)
    if entry is None or entry[0]() is not problem:
        entry = (weakref.ref(problem, dropper(_DERIVED, key)), {})
        _DERIVED[key] = entry
    values = entry[1]
    if name not in values:
        values[name] = build(problem)
    return cast(T, values[name])


class _Layout:
    """What :func:`to_motion` needs of a problem besides the motion: names, units, frames."""

    def __init__(self, problem: Problem) -> None:
        scene, scales = problem.scene, problem.scales
        k, d = scene.twist_size, scene.dimension
        self.names = tuple(b.name for b in scene.bodies)
        self.pairs = tuple((c.body, c.other) for c in scene.contacts)
        self.units = np.array([scales.velocity] * d + [scales.velocity / scales.length] * (k - d))
        self.frames = np.ascontiguousarray(problem.frames, dtype=float)
        self.threshold = MODE_TOLERANCE * scales.velocity


@njit
def _to_world_kernel(q: np.ndarray, c: np.ndarray, frames: np.ndarray, units: np.ndarray, force: float) -> tuple[np.ndarray, np.ndarray]:
    """Physical twists (bodies, k) and world contact forces (m, d) of a scene-relative ``q`` and ``c``."""
    k = units.shape[0]
    bodies = q.shape[0] // k
    T = np.empty((bodies, k))
    for a in range(bodies):
        for j in range(k):
            T[a, j] = q[a * k + j] * units[j]
    m, d = c.shape
    forces = np.zeros((m, d))
    for i in range(m):
        for j in range(d):
            total = 0.0
            for s in range(d):
                total += c[i, s] * frames[i, s, j]
            forces[i, j] = total * force
    return T, forces


def _to_world(layout: _Layout, q: np.ndarray, c: np.ndarray, force: float) -> tuple[np.ndarray, np.ndarray]:
    if HAVE_NUMBA:
        q, c = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(c, dtype=float)
        return _to_world_kernel(q, c, layout.frames, layout.units, force)
    T = np.reshape(q, (-1, layout.units.size)) * layout.units
    return T, np.matmul(c[:, None, :], layout.frames)[:, 0, :] * force


def to_motion(
    problem: Problem,
    raw: RawMotion,
    ranges: list[tuple[float, float | None]] | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
) -> Motion:
    """Audit a raw motion on the original data and name each contact's mode.

    The audit runs now; the per-contact results (:class:`ContactResult`) are
    made from the audit's arrays when the motion's ``contacts`` are first read.
    """
    scales = problem.scales
    layout = derived(problem, "layout", _Layout)
    T, forces = _to_world(layout, raw.q, raw.c, scales.force)
    audit, power, evaluation = audit_arrays(problem.scene, T, forces, scales, tolerance)
    if ranges is not None:
        F = scales.force
        ranges = [(lo * F, None if hi is None else hi * F) for lo, hi in ranges]
    table = _ContactTable(layout.pairs, forces, evaluation.slips, evaluation.normal, layout.threshold, ranges)
    extremes = tuple(physical_twists(problem, e) for e in raw.extremes)
    twists = dict(zip(layout.names, T, strict=True))
    return _lazy_motion(twists, table, power, audit, raw.continuum, extremes, raw.unbounded)


class _ContactTable:
    """One motion's per-contact results as arrays (physical units, world frame), turned into
    :class:`ContactResult` objects on demand.

    Attributes
    ----------
    pairs : ``(body, other)`` of each contact
    forces, slips : (m, d) contact force on ``body`` and tangential relative velocity
    normal : (m, 3) normal velocity, slip speed and normal force of each contact
    threshold : speed below which a contact is not moving [length/time]
    ranges : physical normal-force ranges, or None
    """

    __slots__ = ("pairs", "forces", "slips", "normal", "threshold", "ranges")

    def __init__(
        self,
        pairs: tuple[tuple[str, str], ...],
        forces: np.ndarray,
        slips: np.ndarray,
        normal: np.ndarray,
        threshold: float,
        ranges: list[tuple[float, float | None]] | None,
    ) -> None:
        self.pairs, self.forces, self.slips, self.normal = pairs, forces, slips, normal
        self.threshold, self.ranges = threshold, ranges

    def __getstate__(self) -> tuple[object, ...]:
        # Floats in lists: pickling a few small arrays costs more than the numbers in them.
        arrays = (self.forces, self.slips, self.normal)
        return (self.pairs, self.threshold, self.ranges, *((a.shape, a.ravel().tolist()) for a in arrays))

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        self.pairs, self.threshold, self.ranges = state[:3]
        self.forces, self.slips, self.normal = (np.array(values, dtype=float).reshape(shape) for shape, values in state[3:])

    def modes(self) -> tuple[Mode, ...]:
        threshold = self.threshold
        return tuple(_mode(u_n, speed, threshold) for u_n, speed, _ in self.normal.tolist())

    def results(self) -> tuple[ContactResult, ...]:
        ranges: list[tuple[float, float | None] | None] = list(self.ranges) if self.ranges else [None] * len(self.pairs)
        return tuple(
            ContactResult(
                body=body,
                other=other,
                mode=_mode(u_n, speed, self.threshold),
                force=force,
                normal_force=f_n,
                slip=slip,
                normal_velocity=u_n,
                normal_force_range=range_i,
            )
            for (body, other), (u_n, speed, f_n), force, slip, range_i in zip(
                self.pairs, self.normal.tolist(), self.forces, self.slips, ranges, strict=True
            )
        )


def _mode(u_n: float, speed: float, threshold: float) -> Mode:
    if u_n > threshold:
        return "separating"
    if speed > threshold:
        return "sliding"
    return "rolling"
