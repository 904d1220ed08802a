"""A solver's motion in scene-relative units, and its conversion to physical units and world frame."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..compiled import HAVE_KERNELS
from ..compiled import to_world as compiled_to_world
from ..jit import HAVE_NUMBA, njit
from ..model import FloatArray
from .assemble import Problem

__all__ = ["RawMotion", "ForceSet", "DeferredForces", "WorldForceSet", "WorldLayout", "to_world", "physical_twists", "free_directions"]

Bounds = tuple[float | None, float | None]


class ForceSet(Protocol):
    """Every force distribution consistent with one motion, as a solver knows it (scene-relative, contact frames).

    ``functionals`` (r, m, d) weigh each contact's contact-frame force ``c`` (tangent(s), then normal).
    """

    def ranges(self, functionals: FloatArray) -> list[Bounds]:
        """Min and max of each ``sum_i functionals[r, i] . c_i`` over the set (None for an unbounded side)."""
        ...

    def feasible(self, functionals: FloatArray, lower: FloatArray, upper: FloatArray) -> bool:
        """Whether some distribution in the set has ``lower <= functionals . c <= upper``."""
        ...


class DeferredForces(Protocol):
    """What a solver knows of one motion's forces, worked out only when asked (scene-relative, contact frames).

    :meth:`indeterminate` decides whether the contact forces are indeterminate (once); :meth:`normal_ranges`
    and :meth:`force_set` are read only when they are.
    """

    def indeterminate(self) -> bool: ...

    def normal_ranges(self) -> tuple[tuple[float, float | None], ...]: ...

    def force_set(self) -> ForceSet: ...


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
    free_axes : tuple of int
        For an unbounded continuum: ``+(j + 1)`` where twist entry ``j`` grows without bound, ``-(j + 1)`` where it falls.
    force_ranges : tuple of (lo, hi) or None
        When the motion is determined but its forces are not: each contact's normal-force
        range over every force distribution consistent with it (``hi`` None when unbounded).
    lazy_ranges : callable or None
        Instead of ``force_ranges``: a function that works them out when first
        read (they cost two LPs per loaded contact, most of a frictionless
        solve); its presence alone says the forces are indeterminate.
    force_set : ForceSet or None
        With indeterminate forces: the set of consistent forces itself, for the ranges
        of robot torques and mover wrenches (LPs run only when those are read).
    extremes_share_forces : bool
        The forces ``c`` hold at every extreme too (one contact-mode pattern's motions are its twists times
        its forces), so each extreme is audited with them, as the motion itself is.
    extreme_forces : tuple of (m, d) arrays
        Otherwise: forces the backend found at each extreme (contact frames), in the order of ``extremes``; each
        extreme is audited with its own. An extreme without forces (this empty) cannot be audited: not listed.
    deferred : DeferredForces or None
        Instead of ``force_ranges``, ``lazy_ranges`` and ``force_set``: whether the forces are indeterminate, and their ranges and set,
        all worked out when first read (deciding it costs more than the rest of a small 2-D solve).
    """

    q: FloatArray
    c: FloatArray
    extremes: tuple[FloatArray, ...] = ()
    unbounded: bool = False
    free_axes: tuple[int, ...] = ()
    force_ranges: tuple[tuple[float, float | None], ...] | None = None
    lazy_ranges: Callable[[], tuple[tuple[float, float | None], ...]] | None = field(default=None, repr=False, compare=False)
    force_set: ForceSet | None = field(default=None, repr=False, compare=False)
    extremes_share_forces: bool = False
    extreme_forces: tuple[FloatArray, ...] = ()
    deferred: DeferredForces | None = field(default=None, repr=False, compare=False)

    @property
    def continuum(self) -> bool:
        return bool(self.extremes) or self.unbounded

    @property
    def forces_indeterminate(self) -> bool:
        """Whether the forces are indeterminate (with ``deferred``, decided now)."""
        if self.deferred is not None:
            return self.deferred.indeterminate()
        return self.force_ranges is not None or self.lazy_ranges is not None


class WorldLayout:
    """What the conversion to physical units needs of a problem: body names, twist units, contact frames.

    Built once per problem (:meth:`Problem.derived`).
    """

    def __init__(self, problem: Problem) -> None:
        scene, scales = problem.scene, problem.scales
        self.names = tuple(b.name for b in scene.bodies)
        self.units = scales.twist_units(scene.dimension)
        self.frames = np.ascontiguousarray(problem.frames, dtype=float)


class WorldForceSet:
    """A :class:`ForceSet` read in physical units and world frame: functionals (r, m, d) on world forces [force].

    A world force is ``f_i = F R_i^T c_i`` (``R_i`` the contact frame's rows, ``F`` the force
    scale), so ``w_i . f_i = (F R_i w_i) . c_i``: the functionals are turned into contact
    frames and scaled, and the values come out physical.
    """

    def __init__(self, problem: Problem, raw: ForceSet) -> None:
        self.frames = _layout(problem).frames
        self.force = problem.scales.force
        self.raw = raw

    def _relative(self, functionals: FloatArray) -> FloatArray:
        return np.einsum("isj,rij->ris", self.frames, np.asarray(functionals, dtype=float)) * self.force

    def ranges(self, functionals: FloatArray) -> list[Bounds]:
        return self.raw.ranges(self._relative(functionals))

    def feasible(self, functionals: FloatArray, lower: FloatArray, upper: FloatArray) -> bool:
        return self.raw.feasible(self._relative(functionals), lower, upper)


def _layout(problem: Problem) -> WorldLayout:
    return problem.derived("world_layout", WorldLayout)


def physical_twists(problem: Problem, q: FloatArray) -> dict[str, FloatArray]:
    """Scene-relative stacked twists to named physical twists."""
    layout = _layout(problem)
    return dict(zip(layout.names, np.reshape(q, (-1, layout.units.size)) * layout.units, strict=True))


def to_world(problem: Problem, q: FloatArray, c: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Physical twists (bodies, k) and world contact forces (m, d) of a scene-relative ``q`` and ``c``."""
    layout = _layout(problem)
    force = problem.scales.force
    if HAVE_NUMBA:
        q, c = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(c, dtype=float)
        return _to_world_kernel(q, c, layout.frames, layout.units, force)
    if HAVE_KERNELS:  # the kernel's loops in C: without numba, a few numpy calls cost more than the arithmetic
        return compiled_to_world(q, c, layout.frames, layout.units, force)
    T = np.reshape(q, (-1, layout.units.size)) * layout.units
    return T, np.matmul(c[:, None, :], layout.frames)[:, 0, :] * force


@njit
def _to_world_kernel(q: FloatArray, c: FloatArray, frames: FloatArray, units: FloatArray, force: float) -> tuple[FloatArray, FloatArray]:
    """:func:`to_world` as one compiled loop (a few numpy calls cost more than the arithmetic on small scenes)."""
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


def free_directions(problem: Problem, free_axes: tuple[int, ...]) -> tuple[str, ...]:
    """Names of the signed twist directions of an unbounded continuum, e.g. ``"box v_x +"``, ``"box omega_z -"``."""
    if not free_axes:
        return ()
    components = ("v_x", "v_y", "omega_z") if problem.dimension == 2 else ("v_x", "v_y", "v_z", "omega_x", "omega_y", "omega_z")
    names = _layout(problem).names
    k = len(components)
    return tuple(f"{names[(abs(a) - 1) // k]} {components[(abs(a) - 1) % k]} {'+' if a > 0 else '-'}" for a in free_axes)
