"""Robot joint torques and mover wrenches of an audited motion: linear maps of its audited contact forces.

The values are the forces the audit judged, mapped through the scene's own
Jacobians and lever arms, so every number here derives from audited forces.
When the forces are indeterminate, their ranges, and whether a robot's torque
limits can be met, come from the solver's set of consistent forces, handed in
as a :class:`ForceFunctionals` (this package imports no solver code); they
are worked out when first read.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..model import Mover, Robot, Scales, Scene
from ..solution import Bounds, Later, MoverWrench, RobotLoad
from ..tolerances import ROUNDOFF, TORQUE_LIMIT

__all__ = ["ForceFunctionals", "LoadMap", "LoadTable"]


class ForceFunctionals(Protocol):
    """The world contact forces (m, d) consistent with one motion [force], as the solver that found it knows them."""

    def ranges(self, functionals: np.ndarray) -> list[Bounds]:
        """Min and max of each ``sum_i functionals[r, i] . f_i`` (functionals (r, m, d)); None for an unbounded side."""
        ...

    def feasible(self, functionals: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
        """Whether some consistent distribution has ``lower <= functionals . f <= upper``."""
        ...


@dataclass(frozen=True)
class _RobotMap:
    """``torques = sum_i matrix[:, i] f_i``: ``matrix[:, i]`` is ``J_i^T`` at the robot's contacts, 0 elsewhere."""

    robot: str
    joints: tuple[str, ...]
    limits: np.ndarray | None
    matrix: np.ndarray  # (n_joints, m, d)
    scale: np.ndarray  # (n_joints,) force scale x the joint's largest lever arm [torque]


@dataclass(frozen=True)
class _MoverMap:
    """``[force, moment about origin] = sum_i matrix[:, i] f_i`` over the mover's contacts."""

    mover: str
    origin: np.ndarray
    matrix: np.ndarray  # (k, m, d)
    scale: np.ndarray  # (k,) force scale, then force scale x largest lever arm


class LoadMap:
    """The linear maps from world contact forces to each robot's torques and each touched mover's wrench.

    Built once per scene (``Scene.derived``), when loads are first read.
    """

    def __init__(self, scene: Scene, scales: Scales) -> None:
        touched = {c.other for c in scene.contacts}
        self.robots = tuple(_robot_map(scene, robot, scales.force) for robot in scene.robots)
        self.movers = tuple(_mover_map(scene, mover, scales) for mover in scene.movers if mover.name in touched)
        frictionless = scene.friction.kind == "none"
        self.frictional = np.array([c.mu > 0.0 and not frictionless for c in scene.contacts], dtype=bool)
        self.force_scale = scales.force


def _robot_map(scene: Scene, robot: Robot, force: float) -> _RobotMap:
    driven = {mover.name for mover in scene.movers if mover.robot == robot.name}
    matrix = np.zeros((robot.joint_velocities.size, len(scene.contacts), scene.dimension))
    for i, contact in enumerate(scene.contacts):
        if contact.other in driven and contact.jacobian is not None:
            matrix[:, i, :] = contact.jacobian.T  # tau = J^T f: the power tau.qdot is f . (J qdot)
    lever = np.max(np.linalg.norm(matrix, axis=2), axis=1, initial=0.0)
    return _RobotMap(robot.name, robot.joint_labels(), robot.torque_limits, matrix, force * lever)


def _mover_map(scene: Scene, mover: Mover, scales: Scales) -> _MoverMap:
    d, k = scene.dimension, scene.twist_size
    assert mover.origin is not None  # filled in by the Scene
    matrix = np.zeros((k, len(scene.contacts), d))
    lever = 0.0
    for i, contact in enumerate(scene.contacts):
        if contact.other != mover.name:
            continue
        r = contact.point - mover.origin
        lever = max(lever, float(np.linalg.norm(r)))
        matrix[:d, i, :] = np.eye(d)
        matrix[d:, i, :] = _moment_rows(r)
    scale = np.r_[np.full(d, scales.force), np.full(k - d, scales.force * (lever or scales.length))]
    return _MoverMap(mover.name, np.array(mover.origin, dtype=float), matrix, scale)


def _moment_rows(r: np.ndarray) -> np.ndarray:
    """The matrix of ``f -> r x f``: (1, 2) in 2-D (the z moment), (3, 3) in 3-D."""
    if r.size == 2:
        return np.array([[-r[1], r[0]]])
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


class LoadTable:
    """A :class:`~quasistatic.solution.LoadSource` over one audited motion's world forces (m, d).

    ``force_set`` is None when the forces are unique (or not known to be otherwise): the
    values are then the only ones, with no ranges. Pickled, it keeps its maps instead of
    the scene, and its force set, so a batch worker ships the LPs' data, not their
    results: ranges are worked out only where they are read.
    """

    __slots__ = ("scene", "scales", "forces", "force_set", "load_map")

    def __init__(
        self, scene: Scene, scales: Scales, forces: np.ndarray, force_set: ForceFunctionals | Later[ForceFunctionals | None] | None
    ) -> None:
        self.scene, self.scales, self.forces, self.force_set = scene, scales, forces, force_set
        self.load_map: LoadMap | None = None

    def __getstate__(self) -> tuple[Any, ...]:
        return (self._map(), self.forces, self._set())

    def _set(self) -> ForceFunctionals | None:
        """The force set; one decided only when read (None: the forces turned out unique) is decided now."""
        if isinstance(self.force_set, Later):
            self.force_set = self.force_set.value()
        return self.force_set

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        self.load_map, self.forces, self.force_set = state

    def _map(self) -> LoadMap:
        if self.load_map is None:
            scales = self.scales
            self.load_map = self.scene.derived("load_map", lambda scene: LoadMap(scene, scales))
        return self.load_map

    def robot_loads(self) -> tuple[RobotLoad, ...]:
        return tuple(self._robot(robot) for robot in self._map().robots)

    def mover_wrenches(self) -> tuple[MoverWrench, ...]:
        return tuple(self._mover(mover) for mover in self._map().movers)

    def force_ranges(self) -> tuple[tuple[Bounds, ...] | None, ...] | None:
        """Each frictional contact's world force components' ranges over the consistent forces (None for a
        frictionless contact: its force lies along its normal, whose range the contact gives); None when unique.

        Two LPs per component, when first read: what friction leaves free (a pull shared by two supports)
        shows here and not in the normal forces' ranges.
        """
        force_set = self._set()
        if force_set is None:
            return None
        m, d = self.forces.shape
        load_map = self._map()
        frictional = np.flatnonzero(load_map.frictional).tolist()
        functionals = np.zeros((len(frictional) * d, m, d))
        for row, (i, axis) in enumerate((i, axis) for i in frictional for axis in range(d)):
            functionals[row, i, axis] = 1.0
        scale = np.full(functionals.shape[0], load_map.force_scale)
        bounds = _clean_bounds(force_set.ranges(functionals), scale) if frictional else ()
        per_contact: list[tuple[Bounds, ...] | None] = [None] * m
        for k, i in enumerate(frictional):
            per_contact[i] = bounds[k * d : (k + 1) * d]
        return tuple(per_contact)

    def _robot(self, robot: _RobotMap) -> RobotLoad:
        torques = _clean(np.einsum("jid,id->j", robot.matrix, self.forces), robot.scale)
        force_set = self._set()
        ranges = None if force_set is None else _clean_bounds(force_set.ranges(robot.matrix), robot.scale)
        exceeded = () if robot.limits is None else self._exceeded(robot, robot.limits, torques, ranges)
        return RobotLoad(robot.robot, robot.joints, torques, ranges, robot.limits, exceeded)

    def _mover(self, mover: _MoverMap) -> MoverWrench:
        values = _clean(np.einsum("kid,id->k", mover.matrix, self.forces), mover.scale)
        force_set = self._set()
        ranges = None if force_set is None else _clean_bounds(force_set.ranges(mover.matrix), mover.scale)
        d = self.forces.shape[1]
        return MoverWrench(mover.mover, mover.origin, values[:d], values[d:], ranges)

    def _exceeded(self, robot: _RobotMap, limits: np.ndarray, torques: np.ndarray, ranges: tuple[Bounds, ...] | None) -> tuple[str, ...]:
        """The joints whose limits no consistent force distribution meets (see :attr:`RobotLoad.limits_exceeded`)."""
        allowed = limits + TORQUE_LIMIT * robot.scale
        force_set = self._set()
        if ranges is None or force_set is None:
            over = np.abs(torques) > allowed
        else:
            over = np.array([_outside(bounds, limit) for bounds, limit in zip(ranges, allowed.tolist(), strict=True)], dtype=bool)
            if not over.any() and not force_set.feasible(robot.matrix, -allowed, allowed):
                over[_conflict(force_set, robot.matrix, allowed)] = True
        return tuple(name for name, exceeded in zip(robot.joints, over.tolist(), strict=True) if exceeded)


def _outside(bounds: Bounds, limit: float) -> bool:
    """True when every value in ``bounds`` lies beyond ``[-limit, limit]``."""
    lo, hi = bounds
    return (lo is not None and lo > limit) or (hi is not None and hi < -limit)


def _conflict(force_set: ForceFunctionals, matrix: np.ndarray, allowed: np.ndarray) -> list[int]:
    """Joints whose limits cannot all be met together, none of them needed for that (a deletion filter).

    Each limit is dropped in turn and kept dropped while the rest still cannot be met:
    what remains is an irreducible conflicting set (one LP per joint).
    """
    kept = list(range(allowed.size))
    for joint in range(allowed.size):
        trial = [j for j in kept if j != joint]
        if not force_set.feasible(matrix[trial], -allowed[trial], allowed[trial]):
            kept = trial
    return kept


def _clean_bounds(ranges: list[Bounds], scale: np.ndarray) -> tuple[Bounds, ...]:
    """:func:`_clean` for the ends of ranges (an unbounded end, None, stays)."""
    return tuple((_clean_end(lo, s), _clean_end(hi, s)) for (lo, hi), s in zip(ranges, scale.tolist(), strict=True))


def _clean_end(end: float | None, scale: float) -> float | None:
    return None if end is None else (0.0 if abs(end) <= ROUNDOFF * scale else end)


def _clean(values: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Entries within :data:`ROUNDOFF` of their own scale reported as 0 (round-off, not load)."""
    values[np.abs(values) <= ROUNDOFF * scale] = 0.0
    return values + 0.0
