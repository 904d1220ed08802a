"""Sensitivities (issue 15, section 3): derivatives against finite differences of ``qs.solve``, margins, refusals."""

from __future__ import annotations

import functools
import pickle
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws.inputs import InputVector
from random_scenes import random_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SEEDS = {2: range(30), 3: range(40)}
CHECKED_INPUTS = 4  # per scene: a 3-D scene has up to 24 inputs, each costing two solves


def _stacked(solution: qs.Solution) -> tuple[np.ndarray, np.ndarray]:
    return np.concatenate(list(solution.twists.values())), np.array([c.force for c in solution.contacts])


def _central_difference(scene: qs.Scene, j: int, h: float) -> tuple[np.ndarray, np.ndarray] | None:
    """(d twist, d forces) per unit of input j by central differences of the forward solve; None if a side is not solved."""
    inputs = InputVector.of(scene)
    values = inputs.values(scene)
    sides = []
    for sign in (1.0, -1.0):
        moved = values.copy()
        moved[j] += sign * h
        solution = qs.solve(inputs.apply(scene, moved), certify=False)  # the motion, not its proof (3-D proofs cost 0.1-1 s)
        if solution.status != "solved":
            return None
        sides.append(_stacked(solution))
    return (sides[0][0] - sides[1][0]) / (2 * h), (sides[0][1] - sides[1][1]) / (2 * h)


@functools.cache  # several tests check the same scenes; each solve and its sensitivity is worked out once
def _differentiable(dimension: int, friction: str = "exact") -> list[tuple[qs.Scene, qs.Solution, qs.Sensitivity]]:
    found = []
    for seed in SEEDS[dimension]:
        scene = random_scene(dimension, seed, friction)
        solution = qs.solve(scene)
        result = qs.sensitivity(scene, solution)
        if isinstance(result, qs.Sensitivity):
            found.append((scene, solution, result))
    return found


@pytest.mark.parametrize(("dimension", "friction"), [(2, "exact"), (3, "exact"), (3, "pyramid:8")])
def test_derivatives_match_finite_differences_of_the_solve(dimension: int, friction: str) -> None:
    """Every column of d(twist)/d(input) and d(force)/d(input) against central differences of qs.solve.

    The tolerance is relative to the largest column: a column that is more than a thousandth of it and has
    the wrong sign, or belongs to another input (a transpose), fails. On 3-D pyramids the sliding contacts
    are on a face of the friction polygon (slip along its normal) or on one edge (slip inside its sector).
    """
    cases = _differentiable(dimension, friction)
    assert len(cases) >= 5, f"only {len(cases)} random {dimension}-D scenes had a derivative"
    compared = 0
    for scene, _, result in cases:
        twist, forces = _stacked(qs.solve(scene, certify=False))
        for j, margin in enumerate(result.margins[:CHECKED_INPUTS]):
            h = 1e-3 * min(1.0, margin.below, margin.above)  # inside the mode on both sides
            # The solves' own round-off (1e-10 of the values) divided by the step, plus a thousandth of the largest column:
            twist_scale = 1e-3 * float(np.max(np.abs(result.twist_jacobian))) + 1e-10 * float(np.max(np.abs(twist))) / h
            force_scale = 1e-3 * float(np.max(np.abs(result.forces))) + 1e-10 * float(np.max(np.abs(forces))) / h
            difference = _central_difference(scene, j, h)
            if difference is None:
                continue
            d_twist, d_forces = difference
            compared += 1
            assert np.allclose(result.twist_jacobian[:, j], d_twist, rtol=1e-3, atol=twist_scale), (result.inputs[j], d_twist)
            assert np.allclose(result.forces[:, :, j], d_forces, rtol=1e-3, atol=force_scale), (result.inputs[j], d_forces)
    assert compared >= 15


def test_a_pushed_box_follows_its_pusher() -> None:
    """A box pushed along a floor by a rolling finger moves with the finger: d v_x/d finger.v_x = 1, forces constant."""
    scene = qs.Scene(
        bodies=[qs.Body("box", 0.5, [0.0, 0.05])],
        movers=[qs.Mover("floor"), qs.Mover("finger", twist=[0.01, 0.0, 0.0], origin=[-0.05, 0.05])],
        contacts=[
            qs.Contact("box", "floor", [-0.05, 0.0], [0.0, 1.0], mu=0.3),
            qs.Contact("box", "floor", [0.05, 0.0], [0.0, 1.0], mu=0.3),
            qs.Contact("box", "finger", [-0.05, 0.05], [1.0, 0.0]),  # frictionless: the forces are unique
        ],
        dimension=2,
    )
    result = qs.sensitivity(scene, inputs=["finger"])
    assert isinstance(result, qs.Sensitivity)
    assert result.inputs == ("finger.v_x", "finger.v_y", "finger.omega_z")
    np.testing.assert_allclose(result.twists["box"][:, 0], [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(result.forces[:, :, 0], 0.0, atol=1e-12)
    # Slowing the finger to zero stops the slide: the floor contacts stick at finger.v_x = 0, 0.01 below.
    assert result.margins[0].below == pytest.approx(0.01, rel=1e-9)
    assert result.margins[0].below_change is not None and result.margins[0].below_change.what == "slip"
    assert result.margins_exact


@pytest.mark.parametrize(("dimension", "friction"), [(2, "exact"), (3, "pyramid:8")])
def test_the_margin_is_exact_where_the_laws_are_linear(dimension: int, friction: str) -> None:
    """In 2-D and on 3-D pyramids, along one input, the predicted motion is the forward answer up to the margin, and
    the motion there sits on a mode boundary: the sensitivity then refuses with the reason."""
    checked = 0
    for scene, solution, result in _differentiable(dimension, friction):
        assert result.margins_exact and result.ball_exact
        inputs = InputVector.of(scene)
        values = inputs.values(scene)
        for j, margin in enumerate(result.margins):
            if not np.isfinite(margin.above) or margin.above > 1.0:
                continue
            inside = values.copy()
            inside[j] += 0.5 * margin.above
            moved = qs.solve(inputs.apply(scene, inside))
            predicted = _stacked(solution)[0] + 0.5 * margin.above * result.twist_jacobian[:, j]
            motions = moved.solutions or ((moved.motion,) if moved.motion else ())
            assert any(np.allclose(np.concatenate(list(m.twists.values())), predicted, atol=1e-7) for m in motions)
            edge = values.copy()
            edge[j] += margin.above
            at_edge = inputs.apply(scene, edge)
            refused = qs.sensitivity(at_edge)
            assert isinstance(refused, qs.NoSensitivity)
            assert refused.reason in (
                qs.NoSensitivityReason.MODE_BOUNDARY,
                qs.NoSensitivityReason.NOT_SOLVED,
                qs.NoSensitivityReason.FORCES_INDETERMINATE,
            )
            checked += 1
    assert checked >= 5


def test_what_has_no_derivative_says_why() -> None:
    jammed = qs.load_scene(EXAMPLES / "push_into_wall.yaml")
    refused = qs.sensitivity(jammed)
    assert isinstance(refused, qs.NoSensitivity) and refused.reason is qs.NoSensitivityReason.NOT_SOLVED
    assert "jammed" in refused.message
    assert refused.to_dict()["available"] is False and refused.to_dict()["reason"] == "not_solved"


def test_forces_indeterminate_have_no_force_derivative() -> None:
    squeeze = qs.load_scene(EXAMPLES / "squeeze.yaml")
    solution = qs.solve(squeeze)
    refused = qs.sensitivity(squeeze, solution)
    assert isinstance(refused, qs.NoSensitivity)
    assert refused.reason in (qs.NoSensitivityReason.FORCES_INDETERMINATE, qs.NoSensitivityReason.NOT_SOLVED)


def test_an_unknown_input_is_named() -> None:
    scene = random_scene(2, 1)
    with pytest.raises(ValueError, match="inputs: 'nobody'"):
        qs.sensitivity(scene, inputs=["nobody"])


def test_a_robot_joint_turns_the_box_through_its_jacobian() -> None:
    """examples/robot_tip.yaml: the box turns about the notch corner, so its fingertip point moves at (0, 0.1 w); the
    closed frictionless fingertip (normal n = (-0.6, 0.8)) makes 0.08 w = n . (J qdot). With J = [[0, 0.2],
    [-0.3, -0.15]]: dw/dqdot = n^T J / 0.08 = [-3, -3] (J transposed would give [2, 0.75]), and the com, at
    (0.05, 0.05) from the corner, moves at w (-0.05, 0.05)."""
    scene = qs.load_scene(EXAMPLES / "robot_tip.yaml")
    result = qs.sensitivity(scene, inputs=["arm"])
    assert isinstance(result, qs.Sensitivity)
    assert result.inputs == ("arm.joint[0]", "arm.joint[1]")
    np.testing.assert_allclose(result.twists["box"], [[0.15, 0.15], [-0.15, -0.15], [-3.0, -3.0]], atol=1e-12)
    np.testing.assert_allclose(result.forces, 0.0, atol=1e-12)  # frictionless: the forces balance gravity alone
    assert result.certified and result.margins_exact


def test_a_solution_differentiates_itself() -> None:
    """``solution.sensitivity()`` (issue 15's spelling): the same derivative as ``qs.sensitivity(scene, solution)``,
    from the scene the Solution keeps; that scene is not in the JSON, nor in a pickle, and a batch attaches it again."""
    scene = qs.load_scene(EXAMPLES / "robot_tip.yaml")
    solution = qs.solve(scene)
    assert solution.scene is scene
    own = solution.sensitivity(inputs=["arm"])
    assert isinstance(own, qs.Sensitivity)
    np.testing.assert_allclose(own.twists["box"], [[0.15, 0.15], [-0.15, -0.15], [-3.0, -3.0]], atol=1e-12)
    np.testing.assert_array_equal(own.twist_jacobian, qs.sensitivity(scene, solution, inputs=["arm"]).twist_jacobian)
    assert "scene" not in solution.to_dict() and "source" not in solution.to_dict()
    assert pickle.loads(pickle.dumps(solution)).source is None
    for batched in qs.solve_many([scene, scene, scene], n_jobs=2):
        assert batched.scene is scene
        np.testing.assert_array_equal(batched.sensitivity(inputs=["arm"]).twist_jacobian, own.twist_jacobian)


def test_a_solution_without_a_derivative_says_why() -> None:
    refused = qs.solve(qs.load_scene(EXAMPLES / "push_into_wall.yaml")).sensitivity()
    assert isinstance(refused, qs.NoSensitivity) and refused.reason is qs.NoSensitivityReason.NOT_SOLVED
    by_hand = qs.Solution("failed", "made by hand", "none", "exact")
    with pytest.raises(ValueError, match="source: this Solution was not made by solve"):
        by_hand.sensitivity()


def _moved_contact(scene: qs.Scene, parameter: str, h: float) -> qs.Scene:
    """The scene with one geometry parameter moved by ``h``: a contact point's coordinate, or its normal turned about
    a world axis (about the plane's normal in 2-D) by ``h`` rad (Rodrigues), everything else as it was."""
    i = int(parameter.split("[")[1].split("]")[0])
    kind, axis = parameter.split(".")[-2:]
    contacts = list(scene.contacts)
    c = contacts[i]
    point, normal = np.array(c.point, dtype=float), np.array(c.normal, dtype=float)
    if kind == "point":
        point["xyz".index(axis)] += h
    elif scene.dimension == 2:
        normal = np.array([[np.cos(h), -np.sin(h)], [np.sin(h), np.cos(h)]]) @ normal
    else:
        a = np.eye(3)["xyz".index(axis[-1])]
        normal = normal * np.cos(h) + np.cross(a, normal) * np.sin(h) + a * (a @ normal) * (1 - np.cos(h))
    contacts[i] = qs.Contact(c.body, c.other, point, normal, mu=c.mu, jacobian=c.jacobian)
    movers = [qs.Mover(m.name, None if m.robot else m.twist, m.origin, m.robot) for m in scene.movers]
    return qs.Scene(scene.bodies, contacts, movers, scene.robots, scene.dimension, scene.gravity, scene.friction)


@pytest.mark.parametrize("dimension", [2, 3])
def test_geometry_derivatives_match_finite_differences_of_the_solve(dimension: int) -> None:
    """d(twist, world forces)/d(contact point, normal turn) against central differences of qs.solve on the scene with
    that contact moved or its normal turned; a wrong sign, a transposed arm or a frame turned the wrong way fails
    (the tolerance is a thousandth of the largest column, plus the solves' round-off over the step)."""
    compared = 0
    for scene, solution, _ in _differentiable(dimension)[:6]:
        result = solution.sensitivity(geometry=True)
        assert isinstance(result, qs.Sensitivity) and result.geometry is not None
        geometry = result.geometry
        assert len(geometry.parameters) == len(scene.contacts) * (3 if dimension == 2 else 6)
        twist, forces = _stacked(solution)
        jacobian = np.concatenate(list(geometry.twists.values()))
        h = 1e-6
        for j in range(0, len(geometry.parameters), 2 if dimension == 2 else 5):  # points and normals of every contact
            sides = [qs.solve(_moved_contact(scene, geometry.parameters[j], sign * h), certify=False) for sign in (1.0, -1.0)]
            if any(side.status != "solved" or side.modes != solution.modes for side in sides):
                continue
            d_twist = (_stacked(sides[0])[0] - _stacked(sides[1])[0]) / (2 * h)
            d_forces = (_stacked(sides[0])[1] - _stacked(sides[1])[1]) / (2 * h)
            twist_scale = 1e-3 * float(np.max(np.abs(jacobian))) + 1e-10 * float(np.max(np.abs(twist))) / h
            force_scale = 1e-3 * float(np.max(np.abs(geometry.forces))) + 1e-10 * float(np.max(np.abs(forces))) / h
            name = geometry.parameters[j]
            np.testing.assert_allclose(jacobian[:, j], d_twist, rtol=1e-3, atol=twist_scale, err_msg=name)
            np.testing.assert_allclose(geometry.forces[:, :, j], d_forces, rtol=1e-3, atol=force_scale, err_msg=name)
            compared += 1
    assert compared >= 12


def test_geometry_derivatives_are_refused_on_3d_pyramids() -> None:
    scene = random_scene(3, 16, "pyramid:8")
    with pytest.raises(ValueError, match="geometry: derivatives through the geometry"):
        qs.sensitivity(scene, geometry=True)


def _hand_push(robot: qs.UrdfRobot, joint_velocities: np.ndarray) -> qs.Scene:
    """A 6 cm cube of 0.2 kg on three table points (mu 0.3), pushed along +x at (-0.03, 0, 0.045) by the planar hand's
    left fingertip (frictionless), whose contact Jacobian comes from ``robot`` (examples/robots/models/planar_hand.urdf)."""
    point = np.array([-0.03, 0.0, 0.045])
    supports = [[-0.03, -0.03, 0.0], [0.03, -0.03, 0.0], [0.0, 0.03, 0.0]]
    contacts = [qs.Contact("box", "table", p, [0.0, 0.0, 1.0], mu=0.3) for p in supports]
    contacts.append(qs.Contact("box", "hand/left_tip", point, [1.0, 0.0, 0.0], mu=0.0, jacobian=robot.point_jacobian("left_tip", point)))
    return qs.Scene(
        bodies=[qs.Body("box", 0.2, [0.0, 0.0, 0.03])],
        movers=[qs.Mover("table"), qs.Mover("hand/left_tip", robot="hand")],
        robots=[qs.Robot("hand", joint_velocities, joint_names=robot.joint_names)],
        contacts=contacts,
        dimension=3,
    )


def test_joint_position_derivatives_match_finite_differences_of_the_solve() -> None:
    """d(twist, forces)/d(joint position) of a URDF robot, contact points and normals held: against central differences
    of qs.solve with the fingertip's Jacobian taken at q +- h e_j (Pinocchio). The fingertip pushes the cube along +x
    while both left joints turn, so their positions change how fast the fingertip's point moves along the normal."""
    pytest.importorskip("pinocchio")
    urdf = EXAMPLES / "robots" / "models" / "planar_hand.urdf"
    q = np.array([-1.233011444981106, 1.4277306614691663, 1.233011444981106, -1.4277306614691663])
    robot = qs.UrdfRobot("hand", urdf, base=qs.Pose([0.0, 0.0, 0.15]), q=q)
    jacobian = robot.point_jacobian("left_tip", [-0.03, 0.0, 0.045])
    joint_velocities = np.r_[np.linalg.lstsq(jacobian[:, :2], [0.01, 0.0, 0.0], rcond=None)[0], 0.0, 0.0]
    scene = _hand_push(robot, joint_velocities)
    solution = qs.solve(scene)
    assert solution.status == "solved" and solution.modes[:3] == ("sliding",) * 3
    plain = solution.sensitivity(geometry=True)  # a Scene's solution knows no URDF robot: points and normals only
    assert isinstance(plain, qs.Sensitivity) and plain.geometry is not None
    assert not any(name.startswith("robots.") for name in plain.geometry.parameters)
    with pytest.raises(ValueError, match="robots: 'hand' is not at the configuration"):
        qs.sensitivity(scene, solution, geometry=True, robots=[robot.at(q=q + 0.1)])
    with pytest.raises(ValueError, match="robots: joint-position derivatives come with the geometry"):
        qs.sensitivity(scene, solution, robots=[robot])
    result = qs.sensitivity(scene, solution, geometry=True, robots=[robot])
    assert isinstance(result, qs.Sensitivity) and result.geometry is not None
    names = result.geometry.parameters[-4:]
    assert names == tuple(f"robots.hand.q.{joint}" for joint in robot.joint_names)
    jacobian_columns = np.concatenate(list(result.geometry.twists.values()))[:, -4:]
    assert float(np.abs(jacobian_columns[:, :2]).max()) > 1e-3  # the left joints turn the push; the right ones do nothing
    np.testing.assert_array_equal(jacobian_columns[:, 2:], 0.0)
    # The frictionless push only sets the cube's speed along x; the forces are statics' (friction 0.3 of the weight
    # against the slip along x): no joint position changes them.
    np.testing.assert_allclose(result.geometry.forces[:, :, -4:], 0.0, atol=1e-12)
    h = 1e-6
    for j in range(2):
        step = np.zeros(4)
        step[j] = h
        sides = [qs.solve(_hand_push(robot.at(q=q + sign * step), joint_velocities)) for sign in (1.0, -1.0)]
        assert all(side.status == "solved" and side.modes == solution.modes for side in sides)
        d_twist = (_stacked(sides[0])[0] - _stacked(sides[1])[0]) / (2 * h)
        d_forces = (_stacked(sides[0])[1] - _stacked(sides[1])[1]) / (2 * h)
        np.testing.assert_allclose(jacobian_columns[:, j], d_twist, rtol=1e-5, atol=1e-7, err_msg=names[j])
        np.testing.assert_allclose(result.geometry.forces[:, :, -4 + j], d_forces, rtol=1e-5, atol=1e-6, err_msg=names[j])


def test_a_worlds_solution_keeps_its_robots_for_joint_position_derivatives() -> None:
    pytest.importorskip("pinocchio")
    solution = qs.solve(qs.load_world(EXAMPLES / "robots" / "planar_hand.yaml"))
    assert solution.source is not None and [r.name for r in solution.source.robots] == ["hand"]
