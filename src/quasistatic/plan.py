"""``plan(scene, twist, modes)``: the inverse problem. Which inputs make the bodies move as wanted, with given modes?

The free inputs (robot joint velocities, movers' twists) of least norm, or of
least user-given quadratic cost, such that the wanted twist with the wanted
contact modes satisfies the laws (:mod:`quasistatic.solvers.planning`). The
result is audited on the scene with those inputs filled in, exactly as a
forward answer is; with ``certify=True`` the forward certified solve of that
scene then says whether the planned motion is the only one the laws allow,
and lists the others when it is not.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from .check import DEFAULT_TOLERANCE, MotionGeometry, audited_motion
from .laws import assemble
from .laws.inputs import InputVector
from .model import FloatArray, Scene
from .solution import Mode, Motion, Solution
from .solve import solve
from .solvers.planning import PlanModes, plan_inputs
from .tolerances import PLAN_SPEED, ROUNDOFF, SAME_TWIST

__all__ = ["plan", "PlanResult", "QuadraticCost"]

PlanStatus = Literal["planned", "infeasible", "failed"]
_MODE_NAMES = ("rolling", "sliding", "separating")


@dataclass(frozen=True)
class QuadraticCost:
    """``p.H p / 2 + linear.p`` over the free inputs ``p``, in the order of ``PlanResult.input_names``.

    ``hessian`` (P, P) symmetric positive semi-definite; ``linear`` (P,) or None for zero.
    """

    hessian: npt.ArrayLike
    linear: npt.ArrayLike | None = None


@dataclass(frozen=True)
class PlanResult:
    """The planned inputs and the motion they give.

    Attributes
    ----------
    status : {"planned", "infeasible", "failed"}
        ``planned``: the inputs make the wanted motion satisfy the laws, audited. ``infeasible``: no inputs
        do (within the planner's method: see ``message``). ``failed``: the planner's answer failed its audit.
    message : str
    input_names : tuple of str
        The free inputs, e.g. ``hand.joint[0]``, ``pusher.v_x``.
    inputs : array (P,)
        Their planned values [input units]; zeros unless ``planned``.
    scene : Scene or None
        The scene with the planned inputs filled in.
    motion : Motion or None
        The wanted motion with the planned forces, audited on ``scene``.
    cost : float or None
    unique : bool or None
        With ``certify=True``: whether the forward certified solve proves the planned motion the only one
        the laws allow. None when not asked (the plan is then unproven as the only motion).
    forward : Solution or None
        The forward solve of ``scene`` (``certify=True``).
    other_motions : tuple of Motion
        Motions the forward solve found besides the planned one.
    """

    status: PlanStatus
    message: str
    input_names: tuple[str, ...]
    inputs: FloatArray
    scene: Scene | None = None
    motion: Motion | None = None
    cost: float | None = None
    unique: bool | None = None
    forward: Solution | None = field(default=None, repr=False)
    other_motions: tuple[Motion, ...] = ()

    @property
    def ok(self) -> bool:
        return self.status == "planned"

    def to_dict(self) -> dict[str, Any]:
        return {
            "status": self.status,
            "message": self.message,
            "inputs": {name: float(v) + 0.0 for name, v in zip(self.input_names, self.inputs, strict=True)},
            "cost": self.cost,
            "certified": self.unique is not None,
            "unique": self.unique,
            "motion": None if self.motion is None else self.motion.to_dict(),
            "forward_status": None if self.forward is None else self.forward.status,
            "other_motions": [m.to_dict() for m in self.other_motions],
        }


def plan(
    scene: Scene,
    twist: Mapping[str, npt.ArrayLike] | npt.ArrayLike,
    modes: Sequence[Mode],
    *,
    free: Collection[str] | None = None,
    cost: QuadraticCost | None = None,
    certify: bool = False,
    min_speed: float | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
) -> PlanResult:
    """Inputs that make the free bodies move with ``twist`` and the contacts in ``modes``.

    Parameters
    ----------
    scene : Scene
        The scene; its values of the free inputs are ignored, the others are kept.
    twist : mapping body name -> array (3,) in 2-D or (6,) in 3-D, or one array for a one-body scene
        The wanted twist of every free body (linear velocity of the com, then angular) [length/time, rad/time].
    modes : sequence of {"rolling", "sliding", "separating"}
        The wanted mode of each contact, in scene order. A sliding contact slips whichever way is cheaper.
    free : collection of str, optional
        Robots and movers whose inputs the planner chooses (every robot when omitted; a mover must be named).
    cost : QuadraticCost, optional
        The default is the squared Euclidean norm of the free inputs, halved.
    certify : bool
        Also solve the planned scene forward (certified) and say whether the planned motion is the only one.
    min_speed : float, optional
        Smallest slip speed of a sliding contact and normal speed of a separating one [length/time]; by default
        :data:`~quasistatic.tolerances.PLAN_SPEED` of the wanted motion's speed at the scene's length scale.
    tolerance : float
        Audit threshold on every scene-relative residual [-].
    """
    wanted_modes = _checked_modes(scene, modes)
    selection = InputVector.of(scene, _checked_free(scene, free))
    base = selection.apply(scene, np.zeros(selection.size))
    problem = assemble(base)
    units = problem.scales.twist_units(scene.dimension)
    T = _checked_twists(scene, twist)
    hessian, linear = _checked_cost(cost, selection.size)
    B = np.einsum("mst,mtP->msP", problem.frames, selection.point_velocity_map(base)) / problem.scales.velocity
    delta = _smallest_speed(scene, T, wanted_modes, min_speed, problem.scales.length) / problem.scales.velocity
    planned = plan_inputs(problem, (T / units).ravel(), PlanModes.of(wanted_modes), B, hessian, linear, delta)
    if planned.status != "planned":
        return PlanResult("infeasible", planned.message, selection.names, np.zeros(selection.size))
    planned_scene = selection.apply(scene, planned.p)
    forces = np.einsum("ms,msd->md", planned.c, problem.frames) * problem.scales.force
    scales = assemble(planned_scene).scales
    motion = audited_motion(MotionGeometry(planned_scene, scales), scales, T, forces, tolerance=tolerance)
    message = "planned and audited; unproven as the only motion (certify=True solves it forward)"
    result = PlanResult("planned", message, selection.names, planned.p, planned_scene, motion, planned.cost)
    failure = _failure(motion, wanted_modes)
    if failure is not None:
        return PlanResult("failed", failure, selection.names, planned.p, planned_scene, motion, planned.cost)
    return _certified(result, T) if certify else result


def _failure(motion: Motion, modes: tuple[Mode, ...]) -> str | None:
    if not motion.audit.passed:
        return f"failed: the planned motion violates the laws ({', '.join(motion.audit.failures())}); it is not a plan"
    wrong = [i for i, (got, want) in enumerate(zip(motion.modes, modes, strict=True)) if got != want]
    if wrong:
        return f"failed: contacts {wrong} are {[motion.modes[i] for i in wrong]} in the audited motion, not as wanted"
    return None


def _certified(result: PlanResult, T: FloatArray) -> PlanResult:
    """The forward certified solve of the planned scene: is the planned motion the only one?"""
    assert result.scene is not None
    forward = solve(result.scene)
    found = forward.solutions or ((forward.motion,) if forward.motion is not None and forward.status == "solved" else ())
    scale = max(float(np.max(np.abs(T), initial=0.0)), 1e-300)
    others = tuple(m for m in found if float(np.max(np.abs(np.array(list(m.twists.values())) - T))) > SAME_TWIST * scale)
    unique = forward.status == "solved" and forward.certified and not others
    if unique:
        message = "planned; the forward certified solve proves it the only motion"
    else:
        message = f"planned; not the only motion: the forward solve says {forward.status} ({len(others)} other motions listed)"
    return PlanResult(
        result.status, message, result.input_names, result.inputs, result.scene, result.motion, result.cost, unique, forward, others
    )


def _checked_modes(scene: Scene, modes: Sequence[Mode]) -> tuple[Mode, ...]:
    if isinstance(modes, str):
        raise ValueError(f"modes: expected one mode per contact, got the text {modes!r}")
    checked = tuple(modes)
    if len(checked) != len(scene.contacts):
        raise ValueError(f"modes: expected {len(scene.contacts)} entries (one per contact), got {len(checked)}")
    for i, mode in enumerate(checked):
        if mode not in _MODE_NAMES:
            raise ValueError(f"modes[{i}]: {mode!r} is not one of rolling, sliding, separating")
    return checked


def _checked_free(scene: Scene, free: Collection[str] | None) -> Collection[str]:
    known = {r.name for r in scene.robots} | {m.name for m in scene.movers if m.robot is None}
    if free is None:
        if not scene.robots:
            raise ValueError("free: the scene has no robot; name the movers whose twists the planner may choose")
        return {r.name for r in scene.robots}
    names = (free,) if isinstance(free, str) else tuple(free)
    for name in names:
        if name not in known:
            raise ValueError(f"free: {name!r} is not a robot or a mover with a twist (known: {', '.join(sorted(known)) or 'none'})")
    if not names:
        raise ValueError("free: no inputs to choose; name at least one robot or mover")
    return names


def _checked_twists(scene: Scene, twist: Mapping[str, npt.ArrayLike] | npt.ArrayLike) -> FloatArray:
    """The wanted twists (bodies, k), one per free body, finite."""
    k = scene.twist_size
    if not isinstance(twist, Mapping):
        if len(scene.bodies) != 1:
            raise ValueError("twist: the scene has several bodies; give a mapping from body name to twist")
        twist = {scene.bodies[0].name: twist}
    names = [b.name for b in scene.bodies]
    unknown = [name for name in twist if name not in names]
    if unknown:
        raise ValueError(f"twist: {unknown[0]!r} is not a free body (bodies: {', '.join(names)})")
    rows = []
    for name in names:
        if name not in twist:
            raise ValueError(f"twist: no twist given for body {name!r}; every free body needs one")
        try:
            value = np.array(twist[name], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"twist.{name}: {twist[name]!r} is not a list of {k} numbers") from None
        if value.shape != (k,) or not np.all(np.isfinite(value)):
            raise ValueError(f"twist.{name}: {np.asarray(twist[name]).tolist()!r} is not a list of {k} finite numbers")
        rows.append(value)
    return np.array(rows)


def _checked_cost(cost: QuadraticCost | None, size: int) -> tuple[FloatArray, FloatArray]:
    if cost is None:
        return np.eye(size), np.zeros(size)
    hessian = np.array(cost.hessian, dtype=float)
    linear = np.zeros(size) if cost.linear is None else np.array(cost.linear, dtype=float)
    if hessian.shape != (size, size) or not np.all(np.isfinite(hessian)) or not np.allclose(hessian, hessian.T):
        raise ValueError(f"cost.hessian: expected a symmetric finite {size} x {size} matrix, got shape {hessian.shape}")
    if np.linalg.eigvalsh(hessian).min() < -ROUNDOFF * max(1.0, float(np.abs(hessian).max())):
        raise ValueError("cost.hessian: must be positive semi-definite (the plan is a convex QP)")
    if linear.shape != (size,) or not np.all(np.isfinite(linear)):
        raise ValueError(f"cost.linear: expected {size} finite numbers, got shape {linear.shape}")
    return hessian, linear


def _smallest_speed(scene: Scene, T: FloatArray, modes: tuple[Mode, ...], min_speed: float | None, length: float) -> float:
    """The smallest slip or separation speed to plan for [length/time]."""
    d = scene.dimension
    if min_speed is not None:
        if not (np.isfinite(min_speed) and min_speed > 0):
            raise ValueError(f"min_speed: {min_speed!r} must be a positive number")
        return float(min_speed)
    speed = float(np.max(np.linalg.norm(T[:, :d], axis=1) + np.linalg.norm(T[:, d:], axis=1) * length, initial=0.0))
    if speed == 0.0 and any(mode != "rolling" for mode in modes):
        raise ValueError("min_speed: the wanted twist is zero; give the smallest slip and separation speed to plan for")
    return PLAN_SPEED * speed
