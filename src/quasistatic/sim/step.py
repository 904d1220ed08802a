"""One quasi-static time step: find the contacts, solve, move.

:func:`evaluate` answers the forward problem at a state (contacts found again, the same
audited :func:`quasistatic.solve` as a single answer); :func:`advance` moves the state along
that answer for a time ``h``; :func:`step` is the two together, a pure function over frozen
values that a planner can call in its own loop. :func:`quasistatic.sim.simulate` adds events
and the choice of step length.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Literal, cast

import numpy as np
import numpy.typing as npt

from ..adapters import AnyWorld, Detection
from ..errors import SceneError, SolverError
from ..model import Contact, Scene
from ..solution import LaterField, Mode, Motion, Solution, Status
from ..solve import Reuse, solve
from ..tolerances import SIM_APPROACH, SIM_LOOKAHEAD, SIM_PENETRATION, SIM_POWER_TIE
from .rigid import advance_pose, point_velocity
from .state import Inputs, State

__all__ = ["AmbiguityPolicy", "StepOptions", "SimModel", "ContactRecord", "Evaluation", "StepResult", "evaluate", "advance", "step"]

FloatArray = npt.NDArray[np.float64]
AmbiguityPolicy = Literal["stop", "min_power"]
MOVING: frozenset[Status] = frozenset({"solved", "ambiguous"})


@dataclass(frozen=True)
class StepOptions:
    """How each step is solved.

    ``ambiguous``: ``stop`` ends the run at an ambiguous answer; ``min_power`` goes on with the motion of
    least input power among those listed (the paper's choice), and records that a choice was made.
    ``method``, ``certify``, ``time_limit``: passed to :func:`quasistatic.solve`.
    ``reuse``: a step whose scene-relative laws equal the previous solve's bit for bit (a body that only
    translates) takes that certified answer again (:class:`quasistatic.solve.Reuse`), audited anew;
    the run is the same step for step with it off.
    """

    dt: float = 0.01
    ambiguous: AmbiguityPolicy = "stop"
    method: str = "auto"
    certify: bool = True
    time_limit: float = 60.0
    reuse: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise SceneError("dt", self.dt, "must be a positive number of seconds")
        if self.ambiguous not in ("stop", "min_power"):
            raise SceneError("ambiguous", self.ambiguous, "must be 'stop' or 'min_power'")


@dataclass(frozen=True)
class SimModel:
    """What does not change over a run: the World (shapes, masses, parsed robots, friction) and the step options."""

    world: AnyWorld
    options: StepOptions = field(default_factory=StepOptions)

    @cached_property
    def margin(self) -> float:
        """Gaps up to this count as contacts [length] (the World's own margin)."""
        return self.world.contact_margin

    @cached_property
    def detecting(self) -> AnyWorld:
        """The World searching the look-ahead band too: built once, so every step reuses its detection layout."""
        band = self.margin + SIM_LOOKAHEAD * self.world.size
        return replace(self.world, detection=replace(self.world.detection, margin=band))

    @cached_property
    def reuse(self) -> Reuse | None:
        """The run's memory of its last certified answer (None when ``options.reuse`` is off)."""
        return Reuse() if self.options.reuse else None

    def placed(self, state: State) -> AnyWorld:
        """The look-ahead World at ``state``'s poses and joint positions, with the scene's own velocities: the step that
        ended on ``state`` (looking for drifted contacts) and the next step, which starts on that very State and sets
        its inputs on it, place it once. Kept for the last State asked, as :meth:`found_at` keeps its contacts."""
        kept = self.__dict__.get("_placed")
        if kept is not None and kept[0] is state:
            return cast(AnyWorld, kept[1])
        world = state.applied(self.detecting)
        self.__dict__["_placed"] = (state, world)
        return world

    def found_at(self, state: State, world: AnyWorld) -> Detection:
        """``world.detect()``, ``world`` being the look-ahead World placed at ``state``; the contacts found at the
        state a step ended on (:func:`advance` looks for drifted contacts there) serve the next step, which
        starts on that very State. Detection reads poses and joint positions only, never the inputs."""
        kept = self.__dict__.get("_found")
        if kept is not None and kept[0] is state:
            return cast(Detection, kept[1])
        found = world.detect()
        self.__dict__["_found"] = (state, found)  # a one-entry cache, as cached_property keeps its values
        return found

    def __post_init__(self) -> None:
        if self.world.contacts or self.world.explicit_robots:
            raise SceneError(
                "contacts",
                len(self.world.contacts),
                "a simulation finds its contacts again at every step: give shapes, not listed contacts",
            )


@dataclass(frozen=True)
class ContactRecord:
    """One contact at one instant: where, its normal (into ``body``), gap, force on ``body``, mode, and slip.

    ``slip``: the velocity of ``body``'s material point relative to ``other``'s, in the tangent plane
    (zero unless sliding; zero where there is no motion) [length/time].
    """

    body: str
    other: str
    point: FloatArray
    normal: FloatArray
    gap: float
    force: FloatArray
    mode: Mode | None  # None where the answer has no motion (jammed, unstable, failed)
    slip: FloatArray = field(default_factory=lambda: np.zeros(3))


@dataclass(frozen=True)
class Evaluation:
    """The forward problem answered at one state: the contacts, the Solution and the motion taken from it."""

    state: State  # after any penetration was corrected
    inputs: Inputs
    world: AnyWorld  # at this state, detecting over the look-ahead band
    margin: float  # the contact margin [length]
    detection: Detection
    near: tuple[tuple[Contact, float], ...]  # surfaces within the look-ahead band, not yet touching, and their gaps
    solution: Solution
    motion: Motion | None  # None: the run cannot go on (jammed, unstable, failed, or ambiguous under "stop")
    choice: str  # how the motion was chosen among several, or ""
    penetration: float  # the largest depth found before correction [length]
    model: SimModel = field(repr=False, compare=False)

    @property
    def status(self) -> Status:
        return self.solution.status

    @property
    def certified(self) -> bool:
        return self.solution.certified

    def twist(self, body: str) -> FloatArray:
        """The body's twist [v of its centre of mass, w] ([vx, vy, w] in the plane); zero for a body the motion does not move."""
        if self.motion is None or body not in self.motion.twists:
            return np.zeros(_twist_size(self.world))
        return np.asarray(self.motion.twists[body], dtype=float)

    def contact_records(self) -> tuple[ContactRecord, ...]:
        """Each contact with its force and mode in the motion taken (no forces when there is none)."""
        contacts = self.detection.contacts
        if self.motion is None:
            return tuple(
                ContactRecord(c.body, c.other, c.point, c.normal, g, np.zeros(len(c.normal)), None)
                for c, g in zip(contacts, self.detection.gaps, strict=True)
            )
        forces, slips = self.motion.forces_and_slips()  # no force ranges: a run records the forces taken
        return tuple(
            ContactRecord(c.body, c.other, c.point, c.normal, g, force, mode, slip)
            for c, g, force, mode, slip in zip(contacts, self.detection.gaps, forces, self.motion.modes, slips, strict=True)
        )


@dataclass(frozen=True)
class StepResult:
    """What happened at one state of a run, and the step taken from it (``dt`` is 0 for the last state).

    ``message`` is the step's Solution's own message, worked out when first read (its claim about the forces
    costs more than the rest of a small step's bookkeeping): saving, printing, comparing or pickling reads it.
    """

    time: float
    dt: float
    status: Status
    certified: bool
    message: LaterField[str] = LaterField(required=True)  # no default: reading it from the class raises AttributeError
    twists: Mapping[str, FloatArray]  # type: ignore[misc]  # mypy takes any descriptor for a default; the message has none
    contacts: tuple[ContactRecord, ...]  # type: ignore[misc]
    choice: str = ""
    penetration: float = 0.0
    events: tuple[Event, ...] = ()

    @classmethod
    def of(cls, evaluation: Evaluation, dt: float, events: tuple[Event, ...] = ()) -> StepResult:
        twists = {b.name: evaluation.twist(b.name) for b in evaluation.world.bodies}
        solution = evaluation.solution
        return cls(
            evaluation.state.time,
            dt,
            solution.status,
            solution.certified,
            solution.kept_message(),
            twists,
            evaluation.contact_records(),
            evaluation.choice,
            evaluation.penetration,
            events,
        )


@dataclass(frozen=True)
class Event:
    """Something that changed during a run, located in time within ``window``.

    ``kind``: ``contact made``, ``contact broken``, ``mode change``, or the status that ended or
    continued the run (``jammed``, ``unstable``, ``ambiguous``, ``failed``); ``pair`` the two
    names involved (empty for a whole-scene status), ``detail`` one sentence.
    """

    time: float
    kind: str
    pair: tuple[str, str]
    detail: str
    window: tuple[float, float]


# --------------------------------------------------------------------------- evaluate


def evaluate(model: SimModel, state: State, inputs: Inputs) -> Evaluation:
    """Contacts found at ``state`` (penetration corrected first), the certified answer, and the motion to follow."""
    inputs.check(model.world)
    world = inputs.applied(model.placed(state))
    margin = model.margin
    found = model.found_at(state, world)
    state, world, found, penetration = _corrected(model, state, inputs, world, found)
    touching = [i for i, g in enumerate(found.gaps) if g <= margin]
    near = tuple((found.contacts[i], found.gaps[i]) for i, g in enumerate(found.gaps) if g > margin)
    detection = Detection(
        tuple(found.contacts[i] for i in touching), tuple(found.gaps[i] for i in touching), margin, _isolated(world, found, touching)
    )
    solution = _solved(model, world.scene(detection))
    motion, choice = _chosen(solution, model.options.ambiguous)
    return Evaluation(state, inputs, world, margin, detection, near, solution, motion, choice, penetration, model)


def _solved(model: SimModel, scene: Scene) -> Solution:
    """The certified answer; a solver that crashes underneath (HiGHS, SCIP) ends the run ``failed``, its steps kept."""
    options = model.options
    try:
        return solve(scene, options.method, certify=options.certify, time_limit=options.time_limit, reuse=model.reuse)
    except SolverError as error:
        return Solution("failed", f"the solver failed: {error}", options.method, str(scene.friction))


def _isolated(world: AnyWorld, found: Detection, touching: list[int]) -> Mapping[str, tuple[str, float]]:
    """Bodies with no contact: the nearest surface the wider search saw, else what detection said."""
    touched = {found.contacts[i].body for i in touching} | {found.contacts[i].other for i in touching}
    isolated = dict(found.isolated)
    for contact, gap in zip(found.contacts, found.gaps, strict=True):
        if contact.body not in touched and (contact.body not in isolated or gap < isolated[contact.body][1]):
            isolated[contact.body] = (contact.other, gap)
    return {name: isolated[name] for name in isolated if name not in touched and any(b.name == name for b in world.bodies)}


def _chosen(solution: Solution, policy: AmbiguityPolicy) -> tuple[Motion | None, str]:
    if solution.status == "solved":
        return solution.motion, ""
    if solution.status != "ambiguous" or policy == "stop" or not solution.solutions:
        return None, ""
    motions = solution.solutions
    best = min(range(len(motions)), key=lambda i: motions[i].power.input)
    complete = "" if solution.search_complete else " (the list is not proven complete)"
    # Ties are judged on the powers' own scale (every power of every listed motion): a zero-power tie is exact.
    scale = max(max(abs(m.power.input), abs(m.power.gravity), abs(m.power.dissipation)) for m in motions)
    least = motions[best].power.input
    tied = [i for i, m in enumerate(motions) if i != best and m.power.input - least <= SIM_POWER_TIE * scale]
    tie = f"; motions {', '.join(str(i + 1) for i in tied)} tie with it, and the first listed was taken" if tied else ""
    return motions[best], f"ambiguous: took motion {best + 1} of {len(motions)}, the least input power{tie}{complete}"


# --------------------------------------------------------------------------- penetration


def _corrected(
    model: SimModel, state: State, inputs: Inputs, world: AnyWorld, found: Detection
) -> tuple[State, AnyWorld, Detection, float]:
    """Move the free bodies out of any penetration deeper than the tolerance, by the least motion (twice at most)."""
    depth = max((-g for g in found.gaps), default=0.0)
    first_depth = max(depth, 0.0)
    for _ in range(2):
        deep = [(c, g) for c, g in zip(found.contacts, found.gaps, strict=True) if g < -SIM_PENETRATION * model.margin]
        if not deep:
            break
        state = _pushed_out(state, world, deep)
        world = inputs.applied(state.applied(model.detecting))
        found = world.detect()
    return state, world, found, first_depth


def _pushed_out(state: State, world: AnyWorld, deep: list[tuple[Contact, float]]) -> State:
    """Least-norm body displacements (a twist's entries per body, rotations scaled by the body's size) that close each gap."""
    bodies = {b.name: b for b in world.bodies}
    names = sorted({c.body for c, _ in deep} | {c.other for c, _ in deep if c.other in bodies})
    width, dim = _twist_size(world), world.dimension
    column = {name: width * i for i, name in enumerate(names)}
    size = world.size
    rows = np.zeros((len(deep), width * len(names)))
    for row, (contact, _) in enumerate(deep):
        for name, sign in ((contact.body, 1.0), (contact.other, -1.0)):
            if name in column:
                com = bodies[name].body().com
                j = column[name]
                rows[row, j : j + dim] = sign * contact.normal
                rows[row, j + dim : j + width] = sign * _moment(contact.point - com, contact.normal) / size
    closing = np.array([-g for _, g in deep])
    displacement = np.linalg.lstsq(rows, closing, rcond=None)[0]
    poses = dict(state.bodies)
    for name in names:
        d = displacement[column[name] : column[name] + width]
        com = bodies[name].body().com
        poses[name] = advance_pose(poses[name], np.concatenate([d[:dim], d[dim:] / size]), com, 1.0)
    return replace(state, bodies=poses)


def _moment(arm: FloatArray, force: FloatArray) -> FloatArray:
    """``arm x force``: a 3-vector in space, a 1-vector (its z part) in the plane."""
    if len(arm) == 2:
        return np.array([arm[0] * force[1] - arm[1] * force[0]])
    return np.cross(arm, force)


def _twist_size(world: AnyWorld) -> int:
    return 3 if world.dimension == 2 else 6


# --------------------------------------------------------------------------- advance


def advance(evaluation: Evaluation, h: float) -> State:
    """The state after following the evaluation's motion for a time ``h``: screws for bodies and movers, joints integrated.

    Contacts the motion keeps closed (rolling or sliding) are closed again at the end of the step where
    they have drifted open (see :func:`_reclosed`).
    """
    state, world = evaluation.state, evaluation.world
    bodies = {b.name: advance_pose(state.bodies[b.name], evaluation.twist(b.name), b.body().com, h) for b in world.bodies}
    size = _twist_size(world)
    movers = {m.name: advance_pose(state.movers[m.name], _mover_twist(m.twist, size), m.pose.position, h) for m in world.movers}
    robots = {r.name: state.robots[r.name] + h * np.asarray(r.joint_velocities, dtype=float) for r in world.robots}
    return _reclosed(evaluation, State(state.time + h, bodies, movers, robots))


def _reclosed(evaluation: Evaluation, state: State) -> State:
    """``state`` with the contacts the motion kept closed moved shut again where they drifted open.

    A step follows the tangent of a curved path, so a closed contact sliding over a turning face ends
    the step a little open or a little inside (second order in the step). Inside is corrected at the next
    step (:data:`SIM_PENETRATION`); open would, past the margin, lose a contact the motion never broke.
    So a contact found after the step whose nearest contact of the same pair before it (within the
    look-ahead band) was closed, and which has opened beyond :data:`SIM_APPROACH` of the margin, is shut
    by the same least motion that corrects penetration, holding the other closed contacts where they are.
    Separating contacts are left alone.
    """
    if evaluation.motion is None:
        return state
    before = list(zip(evaluation.detection.contacts, evaluation.motion.modes, strict=True))
    if not any(mode in ("rolling", "sliding") for _, mode in before):
        return state
    world = evaluation.model.placed(state)  # poses only matter here: detection, and the bodies' centres of mass
    band = SIM_LOOKAHEAD * world.size
    found = evaluation.model.found_at(state, world)
    kept = [(c, gap) for c, gap in zip(found.contacts, found.gaps, strict=True) if _was_closed(before, c, band)]
    opened = SIM_APPROACH * evaluation.margin
    if all(gap <= opened for _, gap in kept):
        return state
    # the drifted ones shut, the other closed ones held where they are (a gap of 0 asks for no motion along its normal)
    return _pushed_out(state, world, [(c, gap if gap > opened else 0.0) for c, gap in kept])


def _was_closed(before: list[tuple[Contact, Mode]], contact: Contact, band: float) -> bool:
    """The contact of the same pair nearest to ``contact`` before the step lies within ``band`` and was rolling or sliding."""
    pair = (contact.body, contact.other)
    same_pair = [(math.dist(c.point, contact.point), mode) for c, mode in before if (c.body, c.other) == pair]
    if not same_pair:
        return False
    distance, mode = min(same_pair, key=lambda entry: entry[0])
    return distance <= band and mode in ("rolling", "sliding")


def _mover_twist(twist: npt.ArrayLike | None, size: int) -> FloatArray:
    return np.zeros(size) if twist is None else np.asarray(twist, dtype=float)


def step(model: SimModel, state: State, inputs: Inputs, h: float | None = None) -> tuple[State, StepResult]:
    """One step from ``state``: the answer there and the state ``h`` later (``model.options.dt`` by default).

    Where the answer has no motion to follow (``jammed``, ``unstable``, ``failed``, or ``ambiguous`` under the
    ``stop`` policy) the state is returned unchanged, with ``dt`` 0 in the result.
    """
    evaluation = evaluate(model, state, inputs)
    if evaluation.motion is None:
        return evaluation.state, StepResult.of(evaluation, 0.0)
    h = model.options.dt if h is None else h
    return advance(evaluation, h), StepResult.of(evaluation, h)


# --------------------------------------------------------------------------- step length


def safe_step(evaluation: Evaluation, h: float) -> float:
    """``h`` shortened so no point moves farther than the look-ahead band, and no approaching surface closes its gap."""
    world = evaluation.world
    band = SIM_LOOKAHEAD * world.size
    speed = _fastest_point(evaluation)
    if speed > 0:
        h = min(h, band / speed)
    margin = evaluation.margin
    for contact, gap in evaluation.near:
        closing = -float(contact.normal @ (_velocity(evaluation, contact.body, contact) - _velocity(evaluation, contact.other, contact)))
        if closing > 0:
            h = min(h, max(gap - SIM_APPROACH * margin, 0.0) / closing)
    return h


def _velocity(evaluation: Evaluation, name: str, contact: Contact) -> FloatArray:
    """World velocity of the material point of ``name`` at the contact point."""
    world = evaluation.world
    for body in world.bodies:
        if body.name == name:
            return point_velocity(evaluation.twist(name), body.body().com, contact.point)
    for mover in world.movers:
        if mover.name == name:
            return point_velocity(_mover_twist(mover.twist, _twist_size(world)), mover.pose.position, contact.point)
    if contact.jacobian is not None:  # a robot link
        robot = next(r for r in world.robots if contact.other.startswith(f"{r.name}/"))
        return np.asarray(contact.jacobian @ robot.joint_velocities, dtype=float)
    return np.zeros(world.dimension)


def _fastest_point(evaluation: Evaluation) -> float:
    """An upper bound on the speed of any point of a body, mover or robot link near the bodies."""
    world = evaluation.world
    dim = world.dimension
    reach = world.size + max((float(np.linalg.norm(b.body().com)) for b in world.bodies), default=0.0)
    speeds = [0.0]
    for body in world.bodies:
        twist = evaluation.twist(body.name)
        speeds.append(float(np.linalg.norm(twist[:dim]) + np.linalg.norm(twist[dim:]) * world.size))
    for mover in world.movers:
        twist = _mover_twist(mover.twist, _twist_size(world))
        extent = mover.shape.extent if mover.shape is not None and math.isfinite(mover.shape.extent) else reach
        speeds.append(float(np.linalg.norm(twist[:dim]) + np.linalg.norm(twist[dim:]) * extent))
    for robot in world.robots:
        rates = np.asarray(robot.joint_velocities, dtype=float)
        if not rates.any():
            continue
        spin = float(np.abs(rates).sum())  # |w| of any link is at most the sum of its joints' rates
        for collider in robot.colliders:
            v = robot.point_jacobian(collider.link, collider.pose.position) @ rates
            speeds.append(float(np.linalg.norm(v)) + spin * collider.shape.extent)
    return max(speeds)


def moving(evaluation: Evaluation) -> bool:
    """The run can go on from this evaluation."""
    return evaluation.motion is not None and evaluation.status in MOVING
