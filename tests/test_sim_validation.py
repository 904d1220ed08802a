"""The simulator against results derived by hand, and against MuJoCo (issue 13, "Validation").

Each case reads its example in ``examples/sim/``, whose header derives the expected answer.
A certified step costs a few seconds here, so the default suite checks each case at one
instant (the answer a step follows) or over a short run; the long runs are marked ``slow``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.sim import Evaluation, Inputs, SimModel, State, StepOptions, advance, evaluate, simulate

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "sim"
GRAVITY = 9.81
PUSH = (0.01 / math.sqrt(2), 0.01 / math.sqrt(2))  # push_puck_centre.yaml pushes along (1, 1)/sqrt 2 at 1 cm/s


def _evaluation(name: str) -> Evaluation:
    world = qs.load_world(EXAMPLES / name)
    return evaluate(SimModel(world, StepOptions(ambiguous="min_power")), State.of(world), Inputs())


def _yaw(rotation: np.ndarray) -> float:
    return math.atan2(rotation[1, 0], rotation[0, 0])


def _moment_z(point: np.ndarray, direction: np.ndarray, centre: np.ndarray) -> float:
    """z-moment about ``centre`` of a unit force along ``direction`` through ``point`` (its vote's sign)."""
    return float(np.cross(point - centre, direction)[2])


# --------------------------------------------------------------------------- pushing a puck


def test_offcentre_push_turns_the_way_the_voting_theorem_says() -> None:
    """Every certified motion turns the puck the way the pusher's line and both (frictionless) cone edges vote."""
    evaluation = _evaluation("push_puck_offcentre.yaml")
    finger = next(m for m in evaluation.world.movers if m.name == "finger")
    contact = next(c for c in evaluation.detection.contacts if c.other == "finger")
    centre = evaluation.state.bodies["puck"].position
    motion_line = _moment_z(contact.point, np.asarray(finger.twist[:3]), centre)
    cone_edge = _moment_z(contact.point, contact.normal, centre)  # mu = 0: both edges lie on the normal
    vote = np.sign(motion_line + 2 * cone_edge)
    assert vote == np.sign(motion_line) == np.sign(cone_edge) == -1.0  # the example's set-up: all vote clockwise
    assert evaluation.certified and evaluation.status in ("solved", "ambiguous")
    motions = evaluation.solution.solutions or (evaluation.solution.motion,)
    for motion in motions:
        assert motion.audit.passed
        assert np.sign(motion.twists["puck"][5]) == vote, motion.twists["puck"]


def test_centre_push_translates_with_the_pusher() -> None:
    """Through its centre the puck goes with the fingertip, unturned: the one certified motion, at cos(pi/4) mu m g v."""
    evaluation = _evaluation("push_puck_centre.yaml")
    assert evaluation.certified and evaluation.status == "solved"
    np.testing.assert_allclose(evaluation.twist("puck"), [*PUSH, 0, 0, 0, 0], atol=1e-9)
    pyramid_resistance = math.cos(math.pi / 4) * 0.4 * 0.5 * GRAVITY  # the 4-edge pyramid slid toward a face's middle
    assert evaluation.solution.motion.power.input == pytest.approx(pyramid_resistance * 0.01, rel=1e-6)


@pytest.mark.slow
def test_centre_push_run_keeps_the_puck_with_the_pusher() -> None:
    trajectory = simulate(EXAMPLES / "push_puck_centre.yaml", duration=0.5, dt=0.25)  # every step solved: no choice made
    assert trajectory.status == "completed" and trajectory.certified
    np.testing.assert_allclose(trajectory.positions("puck")[-1], [*(0.5 * np.array(PUSH)), 0.01], atol=1e-6)
    assert abs(_yaw(trajectory.rotations("puck")[-1])) < 1e-9


ALIGN_PUSH = (0.01 * math.cos(math.radians(11.25)), 0.01 * math.sin(math.radians(11.25)))  # push_align.yaml's pusher
ALIGN_FRAME = 11.25  # the pusher's direction on the table [deg]


@pytest.mark.slow
def test_misaligned_box_starts_turning_toward_the_flat_pusher() -> None:
    """Only the upper fingertip touches; every certified motion turns the box's face toward the pusher (yaw down)."""
    evaluation = _evaluation("push_align.yaml")
    assert {c.other for c in evaluation.detection.contacts} == {"table", "upper"}
    motions = evaluation.solution.solutions or (evaluation.solution.motion,)
    assert all(m.twists["box"][5] < 0 for m in motions)


@pytest.mark.slow
def test_flat_pusher_aligns_the_box_monotonically() -> None:
    """From 10 degrees the yaw falls monotonically to 0; then both fingertips carry the box along, aligned."""
    trajectory = simulate(EXAMPLES / "push_align.yaml", duration=2.5, dt=0.5, ambiguous="min_power")
    assert trajectory.status == "completed" and trajectory.certified
    yaw = np.degrees([_yaw(r) for r in trajectory.rotations("box")]) - ALIGN_FRAME
    assert yaw[0] == pytest.approx(10.0, abs=0.05)
    assert np.all(np.diff(yaw) <= 1e-6), yaw
    assert abs(yaw[-1]) < 0.05
    last = trajectory.steps[-1]
    assert {(c.other, c.mode) for c in last.contacts if c.other != "table"} == {("upper", "rolling"), ("lower", "rolling")}
    np.testing.assert_allclose(last.twists["box"], [*ALIGN_PUSH, 0, 0, 0, 0], atol=1e-9)  # carried along
    assert any(e.kind == "contact made" and e.pair == ("box", "lower") for e in trajectory.events)


# --------------------------------------------------------------------------- rolling

ROLLING_SPIN = 2 * 0.01 / 0.04  # relative speed of the fingers / diameter [rad/s]


def test_cylinder_rolling_on_both_fingers_spins_at_relative_speed_over_diameter() -> None:
    """With every contact held rolling, the one motion leaves the centre still and spins at 2v/D, with no slip."""
    solution = qs.solve(qs.load_world(EXAMPLES / "roll_cylinder.yaml"), modes=["rolling"] * 4)
    assert solution.status == "solved" and solution.certified
    np.testing.assert_allclose(solution.motion.twists["roller"], [0, 0, 0, 0, ROLLING_SPIN, 0], atol=1e-9)
    assert all(np.allclose(c.slip, 0, atol=1e-9) for c in solution.motion.contacts)


@pytest.mark.slow
def test_cylinder_rolls_between_opposed_fingers_among_equal_power_motions() -> None:
    """Rolling at 2v/D with the centre still is certified; the squeeze is free, so slipping motions are too, at equal power."""
    evaluation = _evaluation("roll_cylinder.yaml")
    assert evaluation.certified and evaluation.status == "ambiguous"
    motions = evaluation.solution.solutions
    rolling = [m for m in motions if all(c.mode == "rolling" for c in m.contacts)]
    assert len(rolling) == 1
    np.testing.assert_allclose(rolling[0].twists["roller"], [0, 0, 0, 0, ROLLING_SPIN, 0], atol=1e-9)
    assert all(any(c.mode == "sliding" for c in m.contacts) for m in motions if m is not rolling[0])
    np.testing.assert_allclose([m.power.input for m in motions], 0.0, atol=1e-9)
    # min_power cannot choose among them, and the run's record says so
    others = ", ".join(str(i) for i in range(2, len(motions) + 1))
    assert evaluation.choice.startswith(f"ambiguous: took motion 1 of {len(motions)}, the least input power; motions {others} tie with it")


# --------------------------------------------------------------------------- against MuJoCo

BOX, MASS, MU, FINGER, SPEED = 0.1, 1.0, 0.5, 0.005, 0.01


def _push_scene() -> dict[str, object]:
    """A cube pushed through its centre of mass by a frictionless fingertip touching it."""
    return {
        "quasistatic": 1,
        "friction": "pyramid:4",
        "bodies": {"box": {"mass": MASS, "shape": {"box": [BOX] * 3}, "pose": {"position": [0.0, 0.0, BOX / 2]}}},
        "movers": {
            "table": {"shape": {"halfspace": {"normal": [0.0, 0.0, 1.0], "offset": 0.0}}},
            "finger": {
                "shape": {"sphere": FINGER},
                "pose": {"position": [-BOX / 2 - FINGER, 0.0, BOX / 2]},
                "twist": [SPEED, 0.0, 0.0, 0.0, 0.0, 0.0],
            },
        },
        "contact_detection": {"friction": {"default": MU, "pairs": [{"between": ["box", "finger"], "mu": 0.0}]}},
    }


def _mujoco_push(duration: float) -> tuple[np.ndarray, float]:
    """The box's final position and yaw in MuJoCo: the same numbers, the fingertip a mocap body moved at SPEED."""
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo cross-check: pip install 'quasistatic[test]'")
    half = BOX / 2
    xml = f"""
    <mujoco>
      <option timestep="0.001" cone="pyramidal" gravity="0 0 -{GRAVITY}"/>
      <worldbody>
        <geom name="table" type="plane" size="1 1 0.1" friction="{MU} 0 0"/>
        <body name="box" pos="0 0 {half}"><freejoint/>
          <geom name="box" type="box" size="{half} {half} {half}" mass="{MASS}" friction="{MU} 0 0"/></body>
        <body name="finger" mocap="true" pos="{-half - FINGER} 0 {half}">
          <geom name="finger" type="sphere" size="{FINGER}" contype="0" conaffinity="0"/></body>
      </worldbody>
      <contact><pair geom1="finger" geom2="box" condim="1"/></contact>
    </mujoco>"""
    model, data = _settled(mujoco, xml)
    start = data.qpos[:3].copy()
    finger = np.array([-half - FINGER, 0.0, half])
    for i in range(int(round(duration / model.opt.timestep))):
        data.mocap_pos[0] = finger + [SPEED * (i + 1) * model.opt.timestep, 0.0, 0.0]
        mujoco.mj_step(model, data)
    _settle(mujoco, model, data)  # the finger stopped: whatever momentum the box had is spent
    w, _, _, z = data.qpos[3:7]
    return data.qpos[:3] - start + [0.0, 0.0, half], 2.0 * math.atan2(z, w)


def _compare_with_mujoco(duration: float) -> None:
    """Final box poses agree within 0.2 mm and 0.1 degree.

    The quasi-static box moves exactly with the fingertip (rigid contact). MuJoCo's contact is soft:
    the fingertip sinks into the box until the spring carries the push mu m g (measured 0.07 mm
    behind after 2 cm), and the box slides on a spring-damper that lets it lag and creep. 0.2 mm is
    three times that lag and 1 % of a 2 cm push; 0.1 degree, for a push along a symmetry line,
    allows round-off and the pyramid's edges (both use 4 edges along the contact's tangents).
    """
    mujoco_position, mujoco_yaw = _mujoco_push(duration)
    trajectory = simulate(_push_scene(), duration=duration, dt=duration / 2, ambiguous="min_power")
    assert trajectory.status == "completed" and trajectory.certified
    position = trajectory.positions("box")[-1]
    np.testing.assert_allclose(position, [SPEED * duration, 0.0, BOX / 2], atol=1e-9)  # by hand
    np.testing.assert_allclose(mujoco_position, position, atol=2e-4)
    assert abs(math.degrees(mujoco_yaw - _yaw(trajectory.rotations("box")[-1]))) < 0.1


def test_slow_push_agrees_with_mujoco() -> None:
    _compare_with_mujoco(1.0)


@pytest.mark.slow
def test_longer_push_agrees_with_mujoco() -> None:
    _compare_with_mujoco(2.0)


# --------------------------------------------------------------------------- peg in hole (Whitney)

PEG_HALF_WIDTH, PEG_LENGTH, PEG_MASS = 0.01, 0.08, 0.1  # peg_in_hole_*.yaml: r, L [m], mass [kg]
SLOT_HALF_WIDTH, SLOT_MU = 0.0105, 0.3  # the slot's D / 2 [m] and its walls' friction
PUSH_ANGLE, PEG_SPEED = math.radians(45.0), 0.01  # the inclined pusher's normal from vertical; the fingertips' speed [m/s]


def _peg_pose(pose: qs.Pose) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Tilt theta [rad], two-point depth l [m] (axial distance from the tip to the slot's lower left edge), axis, tip centre."""
    axis = pose.rotation[:, 2]
    tip = pose.position + PEG_LENGTH / 2 * axis
    edge = np.array([-SLOT_HALF_WIDTH, 0.0, 0.0])
    return math.atan2(axis[0], axis[2]), float(axis @ (tip - edge)), axis, tip


def _two_point_depth(theta: float) -> float:
    """Depth at which a peg tilted by theta spans the slot: 2r cos(theta) + l sin(theta) = D."""
    return (2 * SLOT_HALF_WIDTH - 2 * PEG_HALF_WIDTH * math.cos(theta)) / math.sin(theta)


def _whitney_limit(theta: float) -> float:
    """Whitney's two-point line for a push at psi = phi + theta to the axis, at the bottom corner: it jams iff l <= l*."""
    r, mu, slope = PEG_HALF_WIDTH, SLOT_MU, math.tan(PUSH_ANGLE + theta)
    return 2 * mu * r * ((PEG_LENGTH / r - mu) * slope - 1) / (1 + mu * slope)


def _peg_statics(pose: qs.Pose) -> tuple[float, float, float]:
    """Normal forces N1 (right wall), N2 (left edge) and the push P of the peg sliding in, from equilibrium in the x-z plane."""
    theta, _, axis, tip = _peg_pose(pose)
    side = np.array([math.cos(theta), 0.0, -math.sin(theta)])  # the peg's +x face normal
    mu = SLOT_MU
    directions = [np.array([-1.0, 0.0, -mu]), side - mu * axis, np.array([-math.sin(PUSH_ANGLE), 0.0, math.cos(PUSH_ANGLE)])]
    points = [tip + PEG_HALF_WIDTH * side, np.array([-SLOT_HALF_WIDTH, 0.0, 0.0]), tip - PEG_LENGTH * axis + PEG_HALF_WIDTH * side]
    com = pose.position
    rows = np.array([[f[0], f[2], (p - com)[2] * f[0] - (p - com)[0] * f[2]] for f, p in zip(directions, points, strict=True)]).T
    n1, n2, push = np.linalg.solve(rows, [0.0, PEG_MASS * GRAVITY, 0.0])
    return float(n1), float(n2), float(push)


def _pair_force(step: qs.sim.StepResult, other: str) -> np.ndarray:
    return np.sum([c.force for c in step.contacts if c.other == other], axis=0)


def _contact_time(scene: Path) -> float:
    """When the rising peg's left side comes within the contact margin of the slot's lower left edge [s]."""
    world = qs.load_world(scene)
    theta, _, _, tip = _peg_pose(world.bodies[0].pose)
    side = np.array([math.cos(theta), 0.0, -math.sin(theta)])
    gap = -PEG_HALF_WIDTH - side @ (np.array([-SLOT_HALF_WIDTH, 0.0, 0.0]) - tip)
    return (gap - world.contact_margin) / (PEG_SPEED * math.sin(theta))  # rising by dz closes it by dz sin(theta)


def test_peg_jams_at_two_point_contact_inside_whitneys_region() -> None:
    """Tilted 2.5 degrees, the peg reaches two-point contact at l = 23.4 mm < l* = 33.5 mm: jammed there, at once."""
    scene = EXAMPLES / "peg_in_hole_jam.yaml"
    dt = 0.25
    trajectory = simulate(scene, duration=1.0, dt=dt)
    assert trajectory.status == "jammed" and trajectory.certified
    made = [e for e in trajectory.events if e.kind == "contact made"]
    jam = next(e for e in trajectory.events if e.kind == "jammed")
    assert [e.pair for e in made] == [("peg", "left")] and jam.time == made[0].time == trajectory.times[-1]
    assert abs(jam.time - _contact_time(scene)) <= dt / 64  # located within the event window
    theta, depth, _, _ = _peg_pose(trajectory.states[-1].bodies["peg"])
    assert theta == pytest.approx(math.radians(2.5), abs=1e-9)  # it rose unturned in one-point contact
    # the contact is made within the margin (8 um), 8 um / sin(theta) = 0.18 mm before the exact span
    assert abs(depth - _two_point_depth(theta)) < 0.25e-3
    assert depth < _whitney_limit(theta)  # inside Whitney's jamming region
    assert {c.other for c in trajectory.steps[-1].contacts} == {"left", "right", "pusher", "finger", "front", "back"}
    # Whitney's two-point wedge: friction at the two walls holds the peg (the guides and fingertips are frictionless)
    assert jam.detail.endswith("friction wedges it at: peg/left, peg/right")


def _check_peg_slides_in(duration: float, dt: float) -> None:
    """From two-point contact the peg rises while it straightens, spanning the slot, with the forces of the statics."""
    scene = EXAMPLES / "peg_in_hole_slide.yaml"
    trajectory = simulate(scene, duration=duration, dt=dt, ambiguous="min_power")
    assert trajectory.status == "completed" and trajectory.certified
    made = next(e for e in trajectory.events if e.kind == "contact made")
    assert made.pair == ("peg", "left") and abs(made.time - _contact_time(scene)) <= dt / 64
    assert any(e.kind == "contact broken" and e.pair == ("peg", "finger") for e in trajectory.events)
    sliding = [i for i, t in enumerate(trajectory.times) if t >= made.time]
    assert len(sliding) >= 3
    margin = qs.load_world(scene).contact_margin
    poses = [_peg_pose(trajectory.states[i].bodies["peg"]) for i in sliding]
    theta, depth = np.array([p[0] for p in poses]), np.array([p[1] for p in poses])
    assert depth[0] > _whitney_limit(theta[0])  # outside Whitney's jamming region
    assert np.all(np.diff(theta) < 0) and np.all(np.diff(depth) > 0)
    span = 2 * PEG_HALF_WIDTH * np.cos(theta) + depth * np.sin(theta) - 2 * SLOT_HALF_WIDTH
    assert np.all(np.abs(span) <= margin)  # it keeps spanning the slot: the left contact is never lost
    for i in sliding:
        step = trajectory.steps[i]
        assert sum(c.other == "left" and c.mode == "sliding" for c in step.contacts) == 2
        n1, n2, push = _peg_statics(trajectory.states[i].bodies["peg"])
        assert min(n1, n2, push) > 0
        assert np.linalg.norm(_pair_force(step, "pusher")) == pytest.approx(push, rel=2e-3)
        assert -_pair_force(step, "right")[0] == pytest.approx(n1, rel=2e-3)


def test_peg_slides_in_outside_whitneys_region() -> None:
    """Tilted 1.5 degrees, two-point contact comes at l = 38.5 mm > l* = 32.4 mm: the peg slides in."""
    _check_peg_slides_in(duration=0.75, dt=0.25)


@pytest.mark.slow
def test_peg_slides_in_over_a_longer_run() -> None:
    _check_peg_slides_in(duration=1.5, dt=0.1)


# --------------------------------------------------------------------------- a lift against MuJoCo

LIFT_SIDE, LIFT_MASS, LIFT_MU, LIFT_SPEED = 0.05, 0.2, 0.8, 0.01  # the cube [m], [kg], friction, the jaws' speed up [m/s]
JAW_ANGLE = math.radians(60.0)  # each jaw's face from vertical: a wedge narrowing downward
JAW_SIZE, JAW_BELOW = (0.01, 0.08, 0.05), 0.008  # jaw box (thickness, width, length) [m]; face length below the contact
STAND_RADIUS = 0.01  # the cube rests on a ball stand (one point, at z = 0) between the jaws


def _jaw_pose(side: int) -> tuple[np.ndarray, np.ndarray]:
    """Centre and rotation of the jaw whose inclined face touches the cube's bottom edge on ``side`` (-1 left, +1 right)."""
    normal = np.array([-side * math.cos(JAW_ANGLE), 0.0, math.sin(JAW_ANGLE)])  # into the cube
    along = np.array([side * math.sin(JAW_ANGLE), 0.0, math.cos(JAW_ANGLE)])  # up the face
    thickness, _, length = JAW_SIZE
    centre = np.array([side * LIFT_SIDE / 2, 0.0, 0.0]) + along * (length / 2 - JAW_BELOW) - normal * thickness / 2
    c, s = math.cos(side * JAW_ANGLE), math.sin(side * JAW_ANGLE)
    return centre, np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # about y: local x to the face normal


def _lift_scene(jaws: bool = True) -> dict[str, object]:
    """The cube on its ball stand between two jaws moving up: inclined into a wedge, or (``jaws=False``) parallel plates."""
    movers: dict[str, object] = {"stand": {"shape": {"sphere": STAND_RADIUS}, "pose": {"position": [0.0, 0.0, -STAND_RADIUS]}}}
    for name, side in (("left", -1), ("right", 1)):
        centre, rotation = _jaw_pose(side) if jaws else (np.array([side * (LIFT_SIDE + JAW_SIZE[0]) / 2, 0.0, LIFT_SIDE / 2]), np.eye(3))
        movers[name] = {
            "shape": {"box": list(JAW_SIZE)},
            "pose": {"position": centre.tolist(), "rotation": {"matrix": rotation.tolist()}},
            "twist": [0.0, 0.0, LIFT_SPEED, 0.0, 0.0, 0.0],
        }
    return {
        "quasistatic": 1,
        "friction": "pyramid:4",
        "bodies": {"cube": {"mass": LIFT_MASS, "shape": {"box": [LIFT_SIDE] * 3}, "pose": {"position": [0.0, 0.0, LIFT_SIDE / 2]}}},
        "movers": movers,
        "contact_detection": {"friction": {"default": LIFT_MU}},
    }


def _mujoco_lift(duration: float) -> tuple[np.ndarray, float]:
    """The cube's final position and turn [rad] in MuJoCo: the same numbers, the jaws mocap bodies moved at LIFT_SPEED."""
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo cross-check: pip install 'quasistatic[test]'")
    half, jaws = LIFT_SIDE / 2, []
    for name, side in (("left", -1), ("right", 1)):
        centre, rotation = _jaw_pose(side)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, rotation.flatten())
        jaws.append(
            f'<body name="{name}" mocap="true" pos="{" ".join(map(str, centre))}" quat="{" ".join(map(str, quat))}">'
            f'<geom type="box" size="{" ".join(str(x / 2) for x in JAW_SIZE)}" friction="{LIFT_MU} 0 0"/></body>'
        )
    xml = f"""
    <mujoco>
      <option timestep="0.001" cone="pyramidal" gravity="0 0 -{GRAVITY}"/>
      <worldbody>
        <geom name="stand" type="sphere" pos="0 0 {-STAND_RADIUS}" size="{STAND_RADIUS}" friction="{LIFT_MU} 0 0"/>
        <body name="cube" pos="0 0 {half}"><freejoint/>
          <geom type="box" size="{half} {half} {half}" mass="{LIFT_MASS}" friction="{LIFT_MU} 0 0"/></body>
        {"".join(jaws)}
      </worldbody>
    </mujoco>"""
    model, data = _settled(mujoco, xml)
    start, jaw_start = data.qpos[:3].copy(), data.mocap_pos.copy()
    for i in range(int(round(duration / model.opt.timestep))):
        data.mocap_pos[:] = jaw_start + [0.0, 0.0, LIFT_SPEED * (i + 1) * model.opt.timestep]
        mujoco.mj_step(model, data)
    _settle(mujoco, model, data)  # the jaws stopped: whatever the cube still moves is spent
    turn = 2.0 * math.acos(min(1.0, abs(float(data.qpos[3]))))
    return data.qpos[:3] - start + [0.0, 0.0, half], turn


LIFT_TOLERANCE = 1e-4
"""Final cube positions agree within 0.1 mm (and turns within 0.1 degree).

The quasi-static cube rises exactly with the jaws (both contacts rolling, rigid). MuJoCo's contacts are
soft: once the jaws carry the weight instead of the stand, the cube sinks into them until their springs
carry m g (measured 0.020 mm behind, whatever the lift). 0.1 mm is five times that and 1 % of a 1 cm lift; the
lift is along a symmetry line, so 0.1 degree allows round-off and the pyramids' edges.
"""


def _check_lift_against_mujoco(positions: np.ndarray, rotation: np.ndarray, duration: float) -> None:
    mujoco_position, mujoco_turn = _mujoco_lift(duration)
    np.testing.assert_allclose(positions, [0.0, 0.0, LIFT_SIDE / 2 + LIFT_SPEED * duration], atol=1e-9)  # by hand
    assert math.acos(min(1.0, (np.trace(rotation) - 1) / 2)) < 1e-9
    np.testing.assert_allclose(mujoco_position, positions, atol=LIFT_TOLERANCE)
    assert math.degrees(mujoco_turn) < 0.1


def test_wedge_lift_step_agrees_with_mujoco() -> None:
    """One certified step of 0.5 s: every listed motion lifts the cube with the jaws, off its stand, as MuJoCo does."""
    world = qs.load_world(_lift_scene())
    evaluation = evaluate(SimModel(world, StepOptions(ambiguous="min_power")), State.of(world), Inputs())
    assert evaluation.certified and evaluation.status in ("solved", "ambiguous")
    for motion in evaluation.solution.solutions or (evaluation.solution.motion,):  # several listed: the same twist
        np.testing.assert_allclose(motion.twists["cube"], [0, 0, LIFT_SPEED, 0, 0, 0], atol=1e-12)
        stand = {c.mode for c, found in zip(motion.contacts, evaluation.detection.contacts, strict=True) if found.other == "stand"}
        assert stand == {"separating"}
    cube = advance(evaluation, 0.5).bodies["cube"]
    _check_lift_against_mujoco(cube.position, cube.rotation, 0.5)


@pytest.mark.slow
def test_lift_run_agrees_with_mujoco() -> None:
    trajectory = simulate(_lift_scene(), duration=1.0, dt=0.5, ambiguous="min_power")
    assert trajectory.status == "completed" and trajectory.certified
    assert any(e.kind == "contact broken" and e.pair == ("cube", "stand") for e in trajectory.events)
    _check_lift_against_mujoco(trajectory.positions("cube")[-1], trajectory.rotations("cube")[-1], 1.0)


@pytest.mark.slow
def test_parallel_jaws_leave_the_lift_ambiguous() -> None:
    """With parallel jaws the squeeze is free: the cube lifted and the cube left behind, the jaws slipping, both obey the laws."""
    solution = qs.solve(qs.load_world(_lift_scene(jaws=False)))
    assert solution.status == "ambiguous" and solution.certified
    rises = [float(m.twists["cube"][2]) for m in solution.solutions]
    assert any(v == pytest.approx(LIFT_SPEED, abs=1e-9) for v in rises)
    assert any(abs(v) < 1e-9 for v in rises)


def test_peg_slide_is_certified_unique_without_a_policy() -> None:
    """Sliding in, the peg's motion is unique at every step: no policy is needed, and the last state's answer is
    the one motion ``scip`` finds. (HiGHS's presolve once called the found motion's own pattern infeasible, and
    that was read as a continuum free in every direction: a second, bogus motion and an ``ambiguous`` stop.)"""
    scene = EXAMPLES / "peg_in_hole_slide.yaml"
    run = qs.simulate(scene, duration=1.5, dt=0.25)
    assert run.status == "completed", run.message
    final = run.final.applied(qs.load_world(scene))
    default, searched = qs.solve(final), qs.solve(final, method="scip")
    assert default.status == searched.status == "solved" and default.certified
    assert default.motion is not None and searched.motion is not None
    np.testing.assert_allclose(default.motion.twists["peg"], searched.motion.twists["peg"], atol=1e-9)


def test_an_unmeasured_extent_is_an_error_not_a_free_direction() -> None:
    """An LP that cannot answer (here: an empty polyhedron) never makes a twist entry free."""
    from quasistatic.errors import SolverError
    from quasistatic.solvers.numerics.ranges import twist_extremes

    empty = (np.array([[1.0, 0.0]]), np.array([1.0]), np.array([[-1.0, 0.0]]), np.array([0.0]))  # x0 = 1 and x0 <= 0
    with pytest.raises(SolverError, match="could not be measured"):
        twist_extremes(2, *empty)
    _, free = twist_extremes(2, np.array([[1.0, 0.0]]), np.array([1.0]), np.zeros((0, 2)), np.zeros(0))
    assert set(free) == {2, -2}  # x0 is pinned at 1, x1 runs both ways


def _settled(mujoco: Any, xml: str) -> tuple[Any, Any]:
    """The MuJoCo model of ``xml`` and its data after :func:`_settle`: soft contacts sink until they carry the load
    before the run starts."""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    _settle(mujoco, model, data)
    return model, data


def _settle(mujoco: Any, model: Any, data: Any) -> None:
    """0.2 s of MuJoCo steps with nothing driven."""
    for _ in range(int(0.2 / model.opt.timestep)):
        mujoco.mj_step(model, data)
