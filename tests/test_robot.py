"""URDF robots through Pinocchio: joints, forward kinematics, point Jacobians, and bad robot input.

The planar hand of ``examples/robots/models/planar_hand.urdf`` has a Jacobian derived by hand; the Allegro hand
and the Panda (``example-robot-data``) are checked against finite differences of forward kinematics.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pinocchio")

import quasistatic as qs  # noqa: E402
from quasistatic.adapters.robot import installed_model_folders  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HAND = EXAMPLES / "robots" / "models" / "planar_hand.urdf"
LINK = 0.08
ALLEGRO = "package://example-robot-data/robots/allegro_hand_description/urdf/allegro_right_hand.urdf"
PANDA = "package://example-robot-data/robots/panda_description/urdf/panda.urdf"


def _tip(angles: np.ndarray) -> np.ndarray:
    """Fingertip centre of one planar finger relative to its base joint (x-z plane, joints about +y)."""
    first, both = angles[0], angles[0] + angles[1]
    return -LINK * np.array([np.sin(first) + np.sin(both), 0.0, np.cos(first) + np.cos(both)])


def _tip_jacobian(angles: np.ndarray) -> np.ndarray:
    first, both = angles[0], angles[0] + angles[1]
    return LINK * np.array([[-np.cos(first) - np.cos(both), -np.cos(both)], [0.0, 0.0], [np.sin(first) + np.sin(both), np.sin(both)]])


def test_planar_hand_matches_its_analytic_kinematics() -> None:
    rng = np.random.default_rng(3)
    base = qs.Pose.from_rpy([0.02, -0.01, 0.2], [0.0, 0.0, 0.4])
    for _ in range(5):
        q = rng.uniform(-1.2, 1.2, 4)
        robot = qs.UrdfRobot("hand", HAND, base=base, q=q)
        for finger, (side, columns) in enumerate((("left", slice(0, 2)), ("right", slice(2, 4)))):
            finger_base = np.array([-0.1 if finger == 0 else 0.1, 0.0, 0.0])
            tip = base.apply(finger_base + _tip(q[columns]))
            assert np.allclose(robot.link_pose(f"{side}_tip").position, tip, atol=1e-12)
            jacobian = robot.point_jacobian(f"{side}_tip", tip)
            expected = np.zeros((3, 4))
            expected[:, columns] = base.rotation @ _tip_jacobian(q[columns])
            assert np.allclose(jacobian, expected, atol=1e-12)


def _finite_difference(robot: qs.UrdfRobot, link: str, point: np.ndarray, step: float = 1e-7) -> np.ndarray:
    """Velocity of the material point of ``link`` now at ``point``, per joint, by central differences."""
    local = robot.link_pose(link).inverse().apply(point)
    columns = []
    for joint in range(len(robot.joint_names)):
        shift = np.zeros(len(robot.joint_names))
        shift[joint] = step
        ahead = robot.at(q=robot.q + shift).link_pose(link).apply(local)
        behind = robot.at(q=robot.q - shift).link_pose(link).apply(local)
        columns.append((ahead - behind) / (2 * step))
    return np.array(columns).T


@pytest.mark.parametrize(
    ("urdf", "links"),
    [(ALLEGRO, ["link_3.0_tip", "link_13.0", "link_15.0_tip"]), (PANDA, ["panda_link4", "panda_leftfinger", "panda_hand"])],
)
def test_real_robot_jacobians_match_finite_differences(urdf: str, links: list[str]) -> None:
    if not installed_model_folders():
        pytest.skip("example-robot-data is not installed (pip install '.[test]')")
    rng = np.random.default_rng(7)
    base = qs.Pose.from_rpy([0.1, -0.2, 0.3], [0.3, -0.2, 0.5])
    robot = qs.UrdfRobot("robot", urdf, base=base)
    robot = robot.at(q=rng.uniform(-0.3, 0.6, len(robot.joint_names)) * (np.arange(len(robot.joint_names)) < 7))
    for link in links:
        point = robot.link_pose(link).apply(rng.normal(scale=0.02, size=3))
        jacobian = robot.point_jacobian(link, point)
        assert np.abs(jacobian - _finite_difference(robot, link, point)).max() < 1e-7 * max(1.0, np.abs(jacobian).max())


def test_joint_positions_by_name_and_in_order_agree() -> None:
    by_name = qs.UrdfRobot("hand", HAND, q={"right_middle": 0.3, "left_base": -0.2}, joint_velocities={"left_middle": 1.0})
    in_order = qs.UrdfRobot("hand", HAND, q=[-0.2, 0.0, 0.0, 0.3], joint_velocities=[0.0, 1.0, 0.0, 0.0])
    assert np.array_equal(by_name.q, in_order.q)
    assert np.array_equal(by_name.joint_velocities, in_order.joint_velocities)
    assert by_name.joint_names == ("left_base", "left_middle", "right_base", "right_middle")


def test_colliders_follow_the_configuration() -> None:
    robot = qs.UrdfRobot("hand", HAND, base=qs.Pose([0.0, 0.0, 0.2]))
    tips = {c.owner: c.pose.position for c in robot.colliders}
    assert set(tips) == {"hand/palm", "hand/left_tip", "hand/right_tip"}
    assert np.allclose(tips["hand/left_tip"], [-0.1, 0.0, 0.2 - 2 * LINK])
    bent = robot.at(q=[np.pi / 2, 0.0, 0.0, 0.0])
    assert np.allclose({c.owner: c.pose.position for c in bent.colliders}["hand/left_tip"], [-0.1 - 2 * LINK, 0.0, 0.2], atol=1e-12)


@pytest.mark.parametrize(
    ("arguments", "field", "words"),
    [
        ({"urdf": "no/such/robot.urdf"}, "robots.hand.urdf", "cannot read the URDF"),
        ({"urdf": "package://no-such-package/robot.urdf"}, "robots.hand.urdf", "package folders"),
        ({"q": [0.1, 0.2]}, "robots.hand.q", "expected 4"),
        ({"q": {"thumb": 0.1}}, "robots.hand.q.thumb", "no joint of that name"),
        ({"joint_velocities": [0.0, float("nan"), 0.0, 0.0]}, "robots.hand.joint_velocities[1]", "finite"),
        ({"q": "up"}, "robots.hand.q", "expected a list"),
    ],
)
def test_bad_robot_input_names_the_field(arguments: dict[str, object], field: str, words: str) -> None:
    urdf = arguments.pop("urdf", HAND)
    with pytest.raises(qs.SceneError) as caught:
        qs.UrdfRobot("hand", urdf, **arguments)  # type: ignore[arg-type]
    assert caught.value.field == field
    assert words in caught.value.reason


def test_a_malformed_urdf_is_one_clear_error(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'>", encoding="utf-8")
    with pytest.raises(qs.SceneError) as caught:
        qs.UrdfRobot("hand", bad)
    assert caught.value.field == "robots.hand.urdf" and "not a valid URDF" in caught.value.reason
    assert capfd.readouterr().err == ""  # urdfdom's own error lines are folded into the message, not printed


def test_an_unknown_link_is_named() -> None:
    robot = qs.UrdfRobot("hand", HAND)
    with pytest.raises(qs.SceneError, match="no link of that name"):
        robot.point_jacobian("thumb", [0.0, 0.0, 0.0])


@pytest.mark.parametrize("scale", [1.0, 0.3])
def test_visual_meshes_sit_on_their_links_collision_shapes(scale: float) -> None:
    """The URDF's visual meshes (what a viewer draws), placed at a configuration, lie where each link's collision shape is."""
    if not installed_model_folders():
        pytest.skip("example-robot-data is not installed")
    hand = qs.UrdfRobot("hand", ALLEGRO)
    hand = hand.at(q=scale * np.linspace(0.1, 0.8, len(hand.joint_names)))
    colliders = {c.link: c for c in hand.colliders}
    visuals = hand.visuals
    assert len(visuals) == 21 and {v.link for v in visuals} == set(colliders)
    for visual in visuals:
        assert visual.vertices is not None and visual.faces is not None
        assert visual.faces.min() >= 0 and visual.faces.max() < len(visual.vertices) and len(visual.faces) > 100
        placed = visual.vertices @ visual.pose.rotation.T + visual.pose.position
        centre = 0.5 * (placed.min(axis=0) + placed.max(axis=0))
        collider = colliders[visual.link]
        assert np.linalg.norm(centre - collider.pose.position) < 0.5 * collider.shape.extent, visual.link


def test_a_urdf_without_visual_geometry_has_no_visuals() -> None:
    hand = qs.load_world(Path(__file__).resolve().parents[1] / "examples" / "robots" / "planar_hand.yaml").robots[0]
    assert hand.visuals == ()


def test_point_jacobian_rates_match_pinocchio_at_nearby_configurations() -> None:
    """UrdfRobot.point_jacobian_rates (the Lie brackets of the joints' spatial twists) against central differences of
    point_jacobian at q +- h e_j (Pinocchio's forward kinematics), for the Panda on a turned, shifted base, at a world
    point held fixed: a bracket in the wrong order or a missing ancestor fails."""
    c, s = np.cos(0.7), np.sin(0.7)
    base = qs.Pose([0.1, 0.2, 0.3], [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    robot = qs.UrdfRobot("panda", PANDA, q=[0.1, -0.7, 0.2, -2.3, 0.1, 1.5, 0.7, 0.02, 0.02], base=base)
    point = np.array([0.3, 0.05, 0.5])
    rates = robot.point_jacobian_rates("panda_leftfinger", point)
    assert rates.shape == (3, 9, 9) and float(np.abs(rates).max()) > 0.5
    h = 1e-6
    for j in range(9):
        step = np.zeros(9)
        step[j] = h
        ahead, behind = robot.at(q=robot.q + step), robot.at(q=robot.q - step)
        difference = (ahead.point_jacobian("panda_leftfinger", point) - behind.point_jacobian("panda_leftfinger", point)) / (2 * h)
        np.testing.assert_allclose(rates[:, j, :], difference, atol=1e-8, err_msg=f"q[{j}]")
