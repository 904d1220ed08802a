"""An audited :class:`~quasistatic.solution.Motion` from physical twists and world forces.

The audit runs at once; each contact's mode and result (:class:`ContactResult`)
are made from the audit's own arrays when first read, so a mode is always
what the audit measured, never what a solver claimed. Values below
``ROUNDOFF`` of the scene's own scale (a 1e-17 twist entry next to 0.01 m/s
motions) are reported as 0: they are round-off, not physics, and changing
them moves no residual by more than that.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..compiled import HAVE_KERNELS, drop_roundoff
from ..jit import njit
from ..model import Scales, Scene
from ..solution import Audit, ContactResult, Later, Mode, Motion, PowerBalance, UnprovenExtreme
from ..tolerances import AUDIT, MODE_SPEED, ROUNDOFF
from .audit import AuditGeometry, audit_arrays
from .loads import ForceFunctionals, LoadTable

__all__ = ["audited_motion", "ContactTable", "MotionGeometry"]

Range = tuple[float, float | None]


class MotionGeometry:
    """What :func:`audited_motion` reads of a scene: the audit's arrays, contact pairs, the mode threshold.

    Build it once per scene (:meth:`of`) and pass it to every motion of that scene.
    """

    def __init__(self, scene: Scene, scales: Scales) -> None:
        self.scene = scene
        self.audit = AuditGeometry.of(scene)
        self.names = tuple(b.name for b in scene.bodies)
        self.pairs = tuple((c.body, c.other) for c in scene.contacts)
        self.threshold = MODE_SPEED * scales.velocity
        self.twist_roundoff = ROUNDOFF * scales.twist_units(scene.dimension)
        # Per column of a contact's (normal velocity, slip speed, normal force).
        d = scene.dimension
        # Per column of a contact's force (d), slip (d) and (normal velocity, slip speed, normal force).
        force, speed = np.array([ROUNDOFF * scales.force] * d), np.array([ROUNDOFF * scales.velocity] * d)  # (np.full costs 2x)
        self.roundoff = (force, speed, ROUNDOFF * np.array([scales.velocity, scales.velocity, scales.force]))
        self.power_roundoff = ROUNDOFF * scales.power


def audited_motion(
    geometry: MotionGeometry,
    scales: Scales,
    twists: np.ndarray,
    forces: np.ndarray,
    *,
    ranges: list[Range] | Callable[[], list[Range]] | None = None,
    extreme_twists: tuple[dict[str, np.ndarray], ...] = (),
    continuum: bool = False,
    unbounded: bool = False,
    free_directions: tuple[str, ...] = (),
    force_set: ForceFunctionals | Later[ForceFunctionals | None] | None = None,
    indeterminate: Later[bool] | None = None,
    tolerance: float = AUDIT,
    extreme_audits: tuple[Audit, ...] = (),
    unproven_extremes: tuple[UnprovenExtreme, ...] = (),
) -> Motion:
    """Audit one motion on the original scene data and name each contact's mode.

    Parameters
    ----------
    twists : (bodies, k)
        Physical body twists in scene order [length/time, rad/time].
    forces : (m, d)
        World contact forces on each contact's ``body`` [force].
    ranges : list of (lo, hi), a function returning one, or None
        Physical normal-force ranges, when the forces are indeterminate [force]; a
        function is called when the contacts' results are first read.
    force_set : ForceFunctionals, optional
        With indeterminate forces: every world force distribution consistent with the motion,
        for the ranges of robot torques and mover wrenches (:mod:`.loads`); a Later of it (None
        when the forces turn out unique) when that is decided only when read.
    indeterminate : Later of bool, optional
        Whether the forces are indeterminate, decided when first read; ``ranges`` is then read only
        when it is. None: they are indeterminate exactly when ``ranges`` is given.
    """
    audit, power, evaluation = audit_arrays(geometry.audit, twists, forces, scales, tolerance)
    table = ContactTable(
        geometry.pairs, forces, evaluation.slips, evaluation.normal, geometry.threshold, ranges, geometry.roundoff, indeterminate
    )
    named = dict(zip(geometry.names, _drop_roundoff(np.array(twists, dtype=float), geometry.twist_roundoff), strict=True))
    loads = LoadTable(geometry.scene, scales, forces, force_set)
    power = _clean_power(power, geometry.power_roundoff)
    return Motion(
        named,
        table,
        power,
        audit,
        continuum,
        extreme_twists,
        unbounded,
        free_directions,
        loads,
        extreme_audits=extreme_audits,
        unproven_extremes=unproven_extremes,
    )


def _drop_roundoff_numpy(values: np.ndarray, roundoff: np.ndarray) -> np.ndarray:
    """:func:`_drop_roundoff` in one numpy call (what runs without numba), in place."""
    values[np.abs(values) <= roundoff] = 0.0
    return values


@njit(python=drop_roundoff if HAVE_KERNELS else _drop_roundoff_numpy)  # without numba: the loop in C where it was built
def _drop_roundoff(values: np.ndarray, roundoff: np.ndarray) -> np.ndarray:
    """``values`` (rows, c) with entries within ``roundoff[j]`` of zero set to 0, in place (one compiled loop: small arrays)."""
    for i in range(values.shape[0]):
        for j in range(values.shape[1]):
            if abs(values[i, j]) <= roundoff[j]:
                values[i, j] = 0.0
    return values


def _clean_power(power: PowerBalance, roundoff: float) -> PowerBalance:
    """Round-off powers shown as 0; the residual is a measurement and stays as it is."""
    supplied = 0.0 if abs(power.input) <= roundoff else power.input
    raised = 0.0 if abs(power.gravity) <= roundoff else power.gravity
    dissipated = 0.0 if abs(power.dissipation) <= roundoff else power.dissipation
    return PowerBalance(supplied, raised, dissipated, power.residual)


class ContactTable:
    """One motion's per-contact results as arrays (physical units, world frame); a
    :class:`~quasistatic.solution.ContactSource` that makes :class:`ContactResult` objects on demand.

    Attributes
    ----------
    pairs : ``(body, other)`` of each contact
    forces, slips : (m, d) contact force on ``body`` and tangential relative velocity
    normal : (m, 3) normal velocity, slip speed and normal force of each contact
    threshold : speed below which a contact is not moving [length/time]
    ranges : physical normal-force ranges, a function that works them out (called once, when first
        needed), or None when the forces are unique
    roundoff : per-column magnitudes below which forces, slips and the normal columns are reported as 0
    indeterminate : whether the forces are indeterminate, decided when first read (``ranges`` is read only
        when they are); None: exactly when ``ranges`` is not None

    The arrays are kept as the audit measured them; round-off is dropped when results are made.
    """

    __slots__ = ("pairs", "forces", "slips", "normal", "threshold", "ranges", "roundoff", "indeterminate")

    def __init__(
        self,
        pairs: tuple[tuple[str, str], ...],
        forces: np.ndarray,
        slips: np.ndarray,
        normal: np.ndarray,
        threshold: float,
        ranges: list[Range] | Callable[[], list[Range]] | None,
        roundoff: tuple[np.ndarray, np.ndarray, np.ndarray],
        indeterminate: Later[bool] | None = None,
    ) -> None:
        self.pairs, self.forces, self.slips, self.normal = pairs, forces, slips, normal
        self.threshold, self.ranges, self.roundoff = threshold, ranges, roundoff
        self.indeterminate = indeterminate

    def __getstate__(self) -> tuple[object, ...]:
        # Floats in lists: pickling a few small arrays costs more than the numbers in them.
        # Ranges still to be worked out are worked out here: the function holds the solver's data.
        arrays = (self.forces, self.slips, self.normal)
        return (
            self.pairs,
            self.threshold,
            self.range_list(),
            tuple(r.tolist() for r in self.roundoff),
            *((a.shape, a.ravel().tolist()) for a in arrays),
        )

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        self.pairs, self.threshold, self.ranges = state[:3]
        self.indeterminate = None  # decided when pickled: the ranges say it
        force, speed, normal = (np.array(r, dtype=float) for r in state[3])
        self.roundoff = (force, speed, normal)
        self.forces, self.slips, self.normal = (np.array(values, dtype=float).reshape(shape) for shape, values in state[4:])

    def forces_indeterminate(self) -> bool:
        if self.indeterminate is not None:
            return self.indeterminate.value()
        return self.ranges is not None

    def range_list(self) -> list[Range] | None:
        """The normal-force ranges, worked out now if they were deferred; None when the forces are unique."""
        if not self.forces_indeterminate():
            return None
        if callable(self.ranges):
            self.ranges = self.ranges()
        return self.ranges

    def modes(self) -> tuple[Mode, ...]:
        threshold = self.threshold
        return tuple(_mode(u_n, speed, threshold) for u_n, speed, _ in self.normal.tolist())

    def forces_and_slips(self) -> tuple[np.ndarray, np.ndarray]:
        force_roundoff, speed_roundoff, _ = self.roundoff
        return _drop_roundoff(self.forces.copy(), force_roundoff), _drop_roundoff(self.slips.copy(), speed_roundoff)

    def results(self) -> tuple[ContactResult, ...]:
        known = self.range_list()
        ranges: list[Range | None] = list(known) if known is not None else [None] * len(self.pairs)
        force_roundoff, speed_roundoff, normal_roundoff = self.roundoff
        forces = _drop_roundoff(self.forces.copy(), force_roundoff)
        slips = _drop_roundoff(self.slips.copy(), speed_roundoff)
        normal = _drop_roundoff(self.normal.copy(), normal_roundoff)
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
                self.pairs, normal.tolist(), forces, slips, ranges, strict=True
            )
        )


def _mode(u_n: float, speed: float, threshold: float) -> Mode:
    if u_n > threshold:
        return "separating"
    if speed > threshold:
        return "sliding"
    return "rolling"
