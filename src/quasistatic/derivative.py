"""The exact derivative of a solved motion with respect to the commanded inputs, and its types.

The inputs are the robots' joint velocities and the rigid movers' twists
(:class:`~quasistatic.laws.inputs.InputVector`). Within the motion's contact modes
the laws are smooth equations (:mod:`quasistatic.laws.fixed_modes`); their
implicit-function derivative (:mod:`quasistatic.laws.sensitivity`) gives every
body twist's and contact force's rate per unit of each input, and the mode
boundaries give how far each input can move before a contact changes mode.
Where no derivative exists (not ``solved``, forces indeterminate, a motion on a
mode boundary) the answer is a :class:`NoSensitivity` that says why.

This module never solves: :func:`quasistatic.sensitivity` does when given no
answer, and :func:`quasistatic.solve` gives every Solution a
:class:`SolvedScene` (the scene it was solved from), through which
``solution.sensitivity()`` reaches :func:`differentiate` without an import
cycle (``solution.py`` is a leaf).
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .adapters import UrdfRobot
from .laws import Problem, assemble
from .laws.geometry_derivative import GeometryDerivative, geometry_derivative, geometry_parameters
from .laws.inputs import InputVector
from .laws.modes import ModeMasks
from .laws.pyramid_modes import PyramidModes, pyramid_boundaries, pyramid_derivative
from .laws.sensitivity import Boundary, FixedModeDerivative, Singular, ball_radius, boundaries, crossing, fixed_mode_derivative
from .model import FloatArray, Scene
from .solution import Mode, Solution
from .tolerances import MODE_BOUNDARY, ROUNDOFF, SAME_TWIST

__all__ = [
    "differentiate",
    "SolvedScene",
    "Sensitivity",
    "GeometrySensitivity",
    "NoSensitivity",
    "NoSensitivityReason",
    "ModeChange",
    "InputMargin",
]

_CHANGES = {
    "separating": "the separating contact closes (normal speed reaches 0)",
    "normal_force": "the normal force reaches 0 (the contact may separate)",
    "cone": "the rolling contact's force reaches its friction cone (it may slide)",
    "slip": "the sliding contact's slip reaches 0 (it may stick)",
    "edge": "the sliding contact's slip turns to a pyramid face's normal (its friction may leave its edge)",
    "face": "the sliding contact's friction reaches a pyramid edge (its slip may leave the face's normal)",
}


class NoSensitivityReason(enum.Enum):
    """Why a motion has no derivative with respect to the inputs."""

    NOT_SOLVED = "not_solved"
    """The answer is not ``solved`` (ambiguous, jammed, unstable or failed): there is no one motion to differentiate."""
    FORCES_INDETERMINATE = "forces_indeterminate"
    """The motion's forces are not unique, so their derivative is not defined."""
    CONTINUUM = "continuum"
    """The twist is not isolated within its modes (a continuum of motions)."""
    MODE_BOUNDARY = "mode_boundary"
    """A contact is on the boundary between two modes: the one-sided derivatives differ."""
    NO_ROOT = "no_root"
    """Newton's method on the fixed-mode laws did not return to the reported motion."""


@dataclass(frozen=True)
class NoSensitivity:
    """No derivative, and why: ``reason``, a sentence, and the contact concerned when there is one."""

    reason: NoSensitivityReason
    message: str
    contact: int | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"available": False, "reason": self.reason.value, "message": self.message, "contact": self.contact}


@dataclass(frozen=True)
class ModeChange:
    """The first mode change met: at ``contact`` (scene order), ``what`` (separating, normal_force, cone, slip)."""

    contact: int
    what: str

    @property
    def description(self) -> str:
        return f"contacts[{self.contact}]: {_CHANGES[self.what]}"


@dataclass(frozen=True)
class InputMargin:
    """How far one input may decrease (``below``) or increase (``above``) alone before a contact changes mode.

    In the input's own unit; ``inf`` when no mode changes in that direction. ``below_change``/``above_change``
    name the first change (None with ``inf``).
    """

    input: str
    below: float
    above: float
    below_change: ModeChange | None
    above_change: ModeChange | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "input": self.input,
            "below": _finite(self.below),
            "above": _finite(self.above),
            "below_change": None if self.below_change is None else self.below_change.description,
            "above_change": None if self.above_change is None else self.above_change.description,
        }


@dataclass(frozen=True)
class GeometrySensitivity:
    """The derivative of one solved motion with respect to the contact geometry, in physical units and world frame.

    Attributes
    ----------
    parameters : tuple of str
        The G parameters, contact by contact: ``contacts[i].point.x`` (and ``.y``, ``.z``) [length], then
        ``contacts[i].normal.turn_x`` (``_y``, ``_z``; ``normal.turn`` in 2-D) [rad]: the normal turned about
        that world axis (a turn about the normal itself changes nothing); then, for each URDF robot given,
        ``robots.NAME.q.JOINT`` [rad or length]: the joint position, with the contact points and normals held
        (the link's Jacobian at each contact point turns with the configuration, so its point velocity does).
    twists : dict name -> array (k, G)
        d(body twist)/d(parameter).
    forces : array (m, d, G)
        d(world contact force on the body)/d(parameter).

    A contact whose other side is a robot keeps its given Jacobian as its point moves (it is data of the
    scene); a rigid mover's point velocity follows the point. Valid while the modes hold (no margins are given
    for the geometry).
    """

    parameters: tuple[str, ...]
    twists: dict[str, FloatArray]
    forces: FloatArray

    def to_dict(self) -> dict[str, Any]:
        return {
            "parameters": list(self.parameters),
            "twists": {name: d.tolist() for name, d in self.twists.items()},
            "forces": self.forces.tolist(),
        }


@dataclass(frozen=True)
class Sensitivity:
    """The derivative of one solved motion with respect to the inputs, in physical units and world frame.

    Attributes
    ----------
    inputs : tuple of str
        The P inputs, e.g. ``hand.joint[0]``, ``pusher.v_x`` (robots' joints, then rigid movers' twists).
    twists : dict name -> array (k, P)
        d(body twist)/d(input): [length/time or rad/time per input unit].
    forces : array (m, d, P)
        d(world contact force on the body)/d(input) [force per input unit].
    modes : tuple of str
        The contact modes the derivative holds in.
    margins : tuple of InputMargin
        Per input: how far it may move alone, either way, before a contact changes mode.
    ball : float
        Radius of the Euclidean ball in the inputs (mixed units, as given) within which no contact changes
        mode; ``ball_change`` names the nearest change.
    margins_exact : bool
        True in 2-D, with 3-D pyramids, and on 3-D exact cones without sliding frictional contacts: the laws are
        affine in the inputs and the margins are exact. Otherwise they are first-order estimates.
    ball_exact : bool
        True when every mode-deciding quantity is linear in the inputs (2-D, 3-D pyramids, or no frictional 3-D
        contact closed).
    certified : bool
        The differentiated motion was proven the only one (a certified ``solved``).
    geometry : GeometrySensitivity or None
        With ``geometry=True``: the derivative with respect to the contact points and normals.
    """

    inputs: tuple[str, ...]
    twists: dict[str, FloatArray]
    forces: FloatArray
    modes: tuple[Mode, ...]
    margins: tuple[InputMargin, ...]
    ball: float
    ball_change: ModeChange | None
    margins_exact: bool
    ball_exact: bool
    certified: bool
    geometry: GeometrySensitivity | None = None

    @property
    def twist_jacobian(self) -> FloatArray:
        """Every body's twist stacked in scene order, per input: (k n, P)."""
        return np.concatenate(list(self.twists.values()), axis=0)

    def to_dict(self) -> dict[str, Any]:
        return {
            "available": True,
            "inputs": list(self.inputs),
            "twists": {name: d.tolist() for name, d in self.twists.items()},
            "forces": self.forces.tolist(),
            "modes": list(self.modes),
            "margins": [m.to_dict() for m in self.margins],
            "ball": _finite(self.ball),
            "ball_change": None if self.ball_change is None else self.ball_change.description,
            "margins_exact": self.margins_exact,
            "ball_exact": self.ball_exact,
            "certified": self.certified,
            "geometry": None if self.geometry is None else self.geometry.to_dict(),
        }


def differentiate(
    scene: Scene,
    solution: Solution,
    *,
    inputs: Collection[str] | None = None,
    geometry: bool = False,
    robots: Sequence[UrdfRobot] = (),
) -> Sensitivity | NoSensitivity:
    """The derivative of ``solution``, an answer of ``scene``, with respect to the scene's inputs.

    Parameters
    ----------
    scene : Scene
        The scene ``solution`` answers.
    solution : Solution
        Only a ``solved`` motion has a derivative.
    inputs : collection of str, optional
        Names of the robots and rigid movers whose inputs to differentiate by (all of them when omitted).
    geometry : bool
        Also differentiate with respect to each contact's point and normal (``Sensitivity.geometry``); exact
        cones and 2-D only (a ValueError on 3-D pyramids, whose edges turn with the contact frame).
    robots : sequence of UrdfRobot
        With ``geometry``: also differentiate with respect to these robots' joint positions (each must be the
        scene's robot of that name, at the configuration its contact Jacobians came from).

    Returns
    -------
    Sensitivity, or NoSensitivity with the reason there is none.
    """
    selection = InputVector.of(scene, _checked_owners(scene, inputs))
    if robots and not geometry:
        raise ValueError("robots: joint-position derivatives come with the geometry's; pass geometry=True")
    if geometry and scene.dimension == 3 and scene.friction.kind == "pyramid":
        raise ValueError("geometry: derivatives through the geometry are given for exact cones and in 2-D, not on 3-D pyramids")
    refused = _refusal(solution)
    if refused is not None:
        return refused
    assert solution.motion is not None  # solved
    problem = assemble(scene)
    masks = ModeMasks.of(problem, solution.modes)
    q, c = _relative_motion(problem, solution)
    found = _derivative(problem, masks, q, c, _input_map(problem, selection))
    if isinstance(found, Singular):
        return _singular(found)
    derivative, limits = found
    if float(np.max(np.abs(derivative.q - q), initial=0.0)) > SAME_TWIST:
        return NoSensitivity(NoSensitivityReason.NO_ROOT, "the fixed-mode laws' motion is not the reported one (no root nearby)")
    on_boundary = next((b for b in limits if b.value < MODE_BOUNDARY), None)
    if on_boundary is not None:
        change = ModeChange(on_boundary.contact, on_boundary.what)
        return NoSensitivity(NoSensitivityReason.MODE_BOUNDARY, f"on a mode boundary: {change.description}", on_boundary.contact)
    result = _physical(problem, selection, derivative, limits, masks, solution)
    if not geometry:
        return result
    names, rates = _joint_position_rates(scene, robots)
    through = geometry_derivative(problem, masks, q, c, rates)
    if isinstance(through, Singular):
        return _singular(through)
    return dataclasses.replace(result, geometry=_physical_geometry(problem, through, names))


def _joint_position_rates(scene: Scene, robots: Sequence[UrdfRobot]) -> tuple[tuple[str, ...], FloatArray]:
    """Names ``robots.NAME.q.JOINT`` and, per contact, its mover point's world velocity rate per unit of each, (m, d, R)."""
    names: list[str] = []
    columns: list[FloatArray] = []
    movers = {mover.name: mover for mover in scene.movers}
    for robot in robots:
        given = next((r for r in scene.robots if r.name == robot.name), None)
        if given is None:
            raise ValueError(f"robots: {robot.name!r} is not a robot of the scene")
        rates = np.zeros((len(scene.contacts), scene.dimension, len(robot.joint_names)))
        for i, contact in enumerate(scene.contacts):
            mover = movers.get(contact.other)
            if mover is None or mover.robot != robot.name:
                continue
            link = contact.other.removeprefix(f"{robot.name}/")
            _check_configuration(robot, link, contact.point, contact.jacobian, f"contacts[{i}]")
            rates[i] = np.einsum("ajk,k->aj", robot.point_jacobian_rates(link, contact.point), given.joint_velocities)
        names += [f"robots.{robot.name}.q.{joint}" for joint in robot.joint_names]
        columns.append(rates)
    if not columns:
        return (), np.zeros((len(scene.contacts), scene.dimension, 0))
    return tuple(names), np.concatenate(columns, axis=2)


def _check_configuration(robot: UrdfRobot, link: str, point: FloatArray, jacobian: FloatArray | None, field: str) -> None:
    """The robot must be where the scene's contact Jacobian was taken, or its rates would be another pose's."""
    now = robot.point_jacobian(link, point)
    if jacobian is None or not np.allclose(now, jacobian, rtol=0.0, atol=ROUNDOFF * max(1.0, float(np.abs(now).max()))):
        raise ValueError(f"robots: {robot.name!r} is not at the configuration {field}'s Jacobian came from")


def _physical_geometry(problem: Problem, through: GeometryDerivative, joints: tuple[str, ...]) -> GeometrySensitivity:
    units = problem.scales.twist_units(problem.dimension)
    k = units.size
    twists = {b.name: through.dq[a * k : (a + 1) * k] * units[:, None] for a, b in enumerate(problem.scene.bodies)}
    world = np.einsum("msdG,ms->mdG", through.dframes, through.c) + np.einsum("msd,msG->mdG", problem.frames, through.dc)
    names = geometry_parameters(problem.dimension, problem.n_contacts) + joints
    return GeometrySensitivity(names, twists, world * problem.scales.force)


def _derivative(
    problem: Problem, masks: ModeMasks, q: FloatArray, c: FloatArray, B: FloatArray
) -> tuple[FixedModeDerivative, list[Boundary]] | Singular:
    """The derivative and the mode boundaries: linear laws for 3-D pyramids, the exact fixed-mode laws otherwise."""
    if problem.dimension == 3 and problem.friction.kind == "pyramid":
        modes = PyramidModes.of(problem, masks, c)
        linear = pyramid_derivative(problem, modes, B)
        return linear if isinstance(linear, Singular) else (linear, pyramid_boundaries(linear, modes, problem.mu))
    exact = fixed_mode_derivative(problem, masks, q, c, B)
    return exact if isinstance(exact, Singular) else (exact, boundaries(exact, masks, problem.mu))


@dataclass(frozen=True)
class SolvedScene:
    """What a Solution keeps of its solve to differentiate itself: the Scene it was solved from.

    Not part of the Solution's JSON, nor of its pickle (``solve_many`` attaches its own scene again).
    """

    scene: Scene
    robots: tuple[UrdfRobot, ...] = ()  # a World's URDF robots, for derivatives in their joint positions

    def sensitivity(self, solution: Solution, inputs: Collection[str] | None = None, geometry: bool = False) -> Sensitivity | NoSensitivity:
        return differentiate(self.scene, solution, inputs=inputs, geometry=geometry, robots=self.robots)


def _checked_owners(scene: Scene, owners: Collection[str] | None) -> Collection[str] | None:
    if owners is None:
        return None
    if isinstance(owners, str):
        owners = (owners,)
    known = {r.name for r in scene.robots} | {m.name for m in scene.movers if m.robot is None}
    for name in owners:
        if name not in known:
            raise ValueError(f"inputs: {name!r} is not a robot or a mover with a twist (known: {', '.join(sorted(known)) or 'none'})")
    return owners


def _refusal(solution: Solution) -> NoSensitivity | None:
    if solution.status != "solved" or solution.motion is None:
        return NoSensitivity(NoSensitivityReason.NOT_SOLVED, f"the answer is {solution.status}: there is no one motion to differentiate")
    if solution.forces_indeterminate:
        return NoSensitivity(
            NoSensitivityReason.FORCES_INDETERMINATE, "the contact forces are indeterminate: their derivative is not defined"
        )
    if solution.motion.continuum:
        return NoSensitivity(NoSensitivityReason.CONTINUUM, "the motion is a continuum: it is not isolated")
    return None


def _singular(singular: Singular) -> NoSensitivity:
    if singular.why == "forces_indeterminate":
        return NoSensitivity(NoSensitivityReason.FORCES_INDETERMINATE, "the fixed-mode laws leave the forces free: no derivative of forces")
    if singular.why == "continuum":
        return NoSensitivity(NoSensitivityReason.CONTINUUM, "the fixed-mode laws leave the twist free: the motion is not isolated")
    return NoSensitivity(NoSensitivityReason.NO_ROOT, "the reported motion does not satisfy the fixed-mode laws to their tolerance")


def _relative_motion(problem: Problem, solution: Solution) -> tuple[FloatArray, FloatArray]:
    """The solution's twist and contact-frame forces in scene-relative units."""
    assert solution.motion is not None
    units = problem.scales.twist_units(problem.dimension)
    q = np.concatenate([solution.twists[b.name] / units for b in problem.scene.bodies])
    forces = np.array([c.force for c in solution.contacts], dtype=float).reshape(problem.n_contacts, problem.dimension)
    return q, np.einsum("mst,mt->ms", problem.frames, forces) / problem.scales.force


def _input_map(problem: Problem, selection: InputVector) -> FloatArray:
    """d b / d p: the movers' scene-relative point velocities in contact frames per physical input unit, (m, d, P)."""
    W = selection.point_velocity_map(problem.scene)
    return np.einsum("mst,mtP->msP", problem.frames, W) / problem.scales.velocity


def _physical(
    problem: Problem,
    selection: InputVector,
    derivative: FixedModeDerivative,
    limits: list[Boundary],
    masks: ModeMasks,
    solution: Solution,
) -> Sensitivity:
    scene, scales = problem.scene, problem.scales
    units = scales.twist_units(problem.dimension)
    k = units.size
    twists = {b.name: derivative.dq[a * k : (a + 1) * k] * units[:, None] for a, b in enumerate(scene.bodies)}
    forces = np.einsum("msd,msP->mdP", problem.frames, derivative.dc) * scales.force
    margins = tuple(_margin(name, j, selection.size, limits, derivative.affine) for j, name in enumerate(selection.names))
    radii = [ball_radius(b) for b in limits]
    nearest = int(np.argmin(radii)) if radii else -1
    ball = radii[nearest] if radii else float("inf")
    polyhedral = problem.friction.is_polyhedral(problem.dimension)
    linear = polyhedral or not bool(np.any(masks.closed & (problem.mu > 0)))
    return Sensitivity(
        inputs=selection.names,
        twists=twists,
        forces=forces,
        modes=solution.modes,
        margins=margins,
        ball=ball,
        ball_change=ModeChange(limits[nearest].contact, limits[nearest].what) if np.isfinite(ball) else None,
        margins_exact=derivative.affine,
        ball_exact=linear,
        certified=solution.certified,
    )


def _margin(name: str, j: int, size: int, limits: list[Boundary], affine: bool) -> InputMargin:
    ends: list[tuple[float, ModeChange | None]] = []
    for sign in (-1.0, 1.0):
        direction = np.zeros(size)
        direction[j] = sign
        distances = [crossing(b, direction, affine) for b in limits]
        first = int(np.argmin(distances)) if distances else -1
        if first < 0 or not np.isfinite(distances[first]):
            ends.append((float("inf"), None))
        else:
            ends.append((distances[first], ModeChange(limits[first].contact, limits[first].what)))
    (below, below_change), (above, above_change) = ends
    return InputMargin(name, below, above, below_change, above_change)


def _finite(value: float) -> float | None:
    """JSON has no infinity: an unbounded margin is null."""
    return float(value) if np.isfinite(value) else None
