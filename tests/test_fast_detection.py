"""The fast path a simulation step takes: World.moved, a kept detection Layout, batched point Jacobians.

Each fast path is checked against the plain one it replaces: a World built afresh (URDF parsed again),
``detect`` on freshly placed colliders, ``point_jacobian`` one point at a time (itself checked against
finite differences in test_robot.py). The steps below move parts so that contacts appear and vanish:
a kept cache that went stale would show as a different list of contacts.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("coal")
pytest.importorskip("pinocchio")

import quasistatic as qs  # noqa: E402
from quasistatic.adapters import Collider, Layout, detect  # noqa: E402
from quasistatic.errors import SceneError  # noqa: E402
from quasistatic.model import Contact  # noqa: E402
from quasistatic.tools.bench.pipeline import ALLEGRO_URDF, allegro_grasp  # noqa: E402


def _fresh(world: qs.World) -> qs.World:
    """The same world built from nothing: every robot parsed again from its URDF, no kept state."""
    robots = tuple(qs.UrdfRobot(r.name, ALLEGRO_URDF, base=r.base, q=r.q, joint_velocities=r.joint_velocities) for r in world.robots)
    return qs.World(bodies=world.bodies, movers=world.movers, robots=robots, detection=world.detection)


def _rows(detection: qs.Detection) -> list[tuple[str, str, float, tuple[float, ...]]]:
    return [(c.body, c.other, c.mu, tuple(c.point)) for c in detection.contacts]


def _same_detection(fast: qs.Detection, plain: qs.Detection) -> None:
    assert [(c.body, c.other, c.mu) for c in fast.contacts] == [(c.body, c.other, c.mu) for c in plain.contacts]
    for mine, theirs in zip(fast.contacts, plain.contacts, strict=True):
        np.testing.assert_allclose(mine.point, theirs.point, rtol=0, atol=1e-12)
        np.testing.assert_allclose(mine.normal, theirs.normal, rtol=0, atol=1e-12)
        if theirs.jacobian is None:
            assert mine.jacobian is None
        else:
            assert mine.jacobian is not None
            np.testing.assert_allclose(mine.jacobian, theirs.jacobian, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast.gaps, plain.gaps, rtol=0, atol=1e-12)
    assert fast.isolated.keys() == plain.isolated.keys()


def _steps(q: np.ndarray, cube: qs.Pose) -> list[tuple[np.ndarray, qs.Pose]]:
    """Joint positions and cube poses along a short motion: grasp, index finger opened, cube lifted, grasp again."""
    opened = q.copy()
    opened[1] -= 0.3  # joint_1.0: the index tip leaves the cube
    lifted = qs.Pose(cube.position + [0.0, 0.0, 0.01], cube.rotation)  # off the table, still between the tips
    turned = qs.Pose.from_rpy(cube.position, (0.0, 0.0, 0.02))
    return [(q, cube), (opened, cube), (q, lifted), (q + 0.01, turned), (q, cube)]


def test_a_moved_world_finds_what_a_world_built_afresh_finds() -> None:
    world, q = allegro_grasp()
    cube = world.bodies[0].pose
    counts = []
    step = world
    for angles, pose in _steps(q, cube):
        step = step.moved({"cube": pose}, {"hand": angles})  # chained, as a simulation does: the kept state goes along
        fast, plain = step.detect(), _fresh(step).detect()
        _same_detection(fast, plain)
        counts.append((len(fast.contacts), sum(c.other == "table" for c in fast.contacts)))
    # The motion changes the contacts: 3 tips + 4 corners, 2 tips + 4, 3 tips and no table, ...
    assert counts[0] == (7, 4) and counts[1] == (6, 4) and counts[2] == (3, 0) and counts[4] == (7, 4)


def test_moved_contacts_carry_the_point_jacobian_of_their_link() -> None:
    world, q = allegro_grasp()
    moved = world.moved(robot_q={"hand": q + 0.01}, joint_velocities={"hand": np.ones(16)})
    hand = moved.robots[0]
    assert np.array_equal(hand.q, q + 0.01) and np.array_equal(hand.joint_velocities, np.ones(16))
    robot_contacts = [c for c in moved.scene().contacts if c.other.startswith("hand/")]
    assert len(robot_contacts) >= 2
    for contact in robot_contacts:
        link = contact.other.removeprefix("hand/")
        np.testing.assert_allclose(contact.jacobian, hand.point_jacobian(link, contact.point), rtol=0, atol=1e-14)


def test_moved_mover_poses_and_twists_reach_the_scene() -> None:
    """A pusher moved along its twist and given a new one: detection and the Scene see both."""
    from quasistatic.tools.bench.pipeline import resting_rows

    world = resting_rows(1)  # one sphere of radius 0.02 on the table at the origin
    pusher = qs.ShapedMover("pusher", qs.Sphere(0.01), qs.Pose((-0.1, 0.0, 0.02)), twist=[0.01, 0.0, 0.0, 0.0, 0.0, 0.0])
    world = qs.World(bodies=world.bodies, movers=(*world.movers, pusher), detection=world.detection)
    assert {c.other for c in world.detect().contacts} == {"table"}
    touching = world.moved(mover_poses={"pusher": qs.Pose((-0.03, 0.0, 0.02))}, mover_twists={"pusher": [0.0, 0.02, 0.0, 0.0, 0.0, 0.0]})
    assert {c.other for c in touching.detect().contacts} == {"table", "pusher"}
    assert np.array_equal(touching.scene().mover("pusher").twist, [0.0, 0.02, 0.0, 0.0, 0.0, 0.0])
    assert np.array_equal(world.scene().mover("pusher").twist, [0.01, 0.0, 0.0, 0.0, 0.0, 0.0])  # the original is unchanged


def test_moved_keeps_the_parsed_robot_and_shapes() -> None:
    world, q = allegro_grasp()
    moved = world.moved({"cube": qs.Pose((0.0, 0.0, 1.0))}, {"hand": q})
    assert moved.robots[0].collider_shapes is world.robots[0].collider_shapes  # not parsed or converted again
    assert moved.bodies[0].shape is world.bodies[0].shape
    assert moved.bodies[0].pose.position[2] == 1.0 and world.bodies[0].pose.position[2] != 1.0  # the original is unchanged
    assert moved.detection is world.detection and moved.movers == world.movers


@pytest.mark.parametrize(
    ("arguments", "field"),
    [
        ({"body_poses": {"ball": qs.Pose()}}, "body_poses.ball"),
        ({"body_poses": {"cube": [0.0, 0.0, 0.1]}}, "body_poses.cube"),
        ({"robot_q": {"arm": [0.0] * 16}}, "robot_q.arm"),
        ({"robot_q": {"hand": [0.0] * 3}}, "robots.hand.q"),
        ({"robot_q": {"hand": {"joint_99": 0.1}}}, "robots.hand.q.joint_99"),
        ({"mover_poses": {"floor": qs.Pose()}}, "mover_poses.floor"),
        ({"joint_velocities": {"arm": [0.0]}}, "joint_velocities.arm"),
        ({"mover_twists": {"floor": [0.0] * 6}}, "mover_twists.floor"),
    ],
)
def test_moved_names_a_bad_argument(arguments: dict[str, object], field: str) -> None:
    world, _ = allegro_grasp()
    with pytest.raises(SceneError) as error:
        world.moved(**arguments)  # type: ignore[arg-type]
    assert error.value.field == field


def test_a_kept_layout_gives_what_detect_gives_at_every_placement() -> None:
    """Balls and boxes thrown around a table: the kept layout against detect() on freshly placed colliders."""
    rng = np.random.default_rng(7)
    shapes = [qs.Sphere(0.05), qs.Box([0.1, 0.08, 0.06]), qs.Sphere(0.03), qs.Box([0.05, 0.05, 0.2]), qs.Halfspace()]
    owners = ["ball", "box", "pebble", "post", "table"]
    free = {"ball", "box", "pebble"}

    def may_touch(a: str, b: str) -> bool:
        return a in free or b in free

    layout = Layout(owners, shapes, may_touch)
    found = 0
    for _ in range(30):
        poses = [
            qs.Pose(rng.uniform([-0.1, -0.1, 0.0], [0.1, 0.1, 0.15]), qs.Pose.from_rpy((0, 0, 0), rng.uniform(-3, 3, 3)).rotation)
            for _ in owners[:-1]
        ]
        colliders = [Collider(o, s, p) for o, s, p in zip(owners, shapes, [*poses, qs.Pose()], strict=True)]
        positions = np.array([c.pose.position for c in colliders])
        rotations = np.array([c.pose.rotation for c in colliders])
        fast, plain = layout.detect(positions, rotations, 0.01), detect(colliders, may_touch, 0.01)
        assert [(c.first, c.second) for c in fast] == [(c.first, c.second) for c in plain]
        for mine, theirs in zip(fast, plain, strict=True):
            assert np.array_equal(mine.point, theirs.point) and np.array_equal(mine.normal, theirs.normal) and mine.gap == theirs.gap
        assert all(not (c.first == "post" and c.second == "table") for c in fast)  # two non-free owners never touch
        found += len(fast)
    assert found > 30  # the placements do bring parts together


def test_batched_point_jacobians_equal_one_at_a_time() -> None:
    world, _ = allegro_grasp()
    hand = world.robots[0]
    links = ["link_3.0_tip", "link_13.0", "link_3.0_tip", "palm_link"]
    points = np.random.default_rng(3).normal(scale=0.05, size=(4, 3))
    batch = hand.point_jacobians(links, points)
    assert batch.shape == (4, 3, 16)
    for link, point, jacobian in zip(links, points, batch, strict=True):
        np.testing.assert_allclose(jacobian, hand.point_jacobian(link, point), rtol=0, atol=1e-15)
    assert not np.any(batch[0][:, 4:])  # the index tip moves with joints 0-3 only


def test_a_trusted_contact_equals_a_checked_one() -> None:
    point, normal, jacobian = np.array([0.1, 0.2, 0.3]), np.array([0.0, 0.0, 1.0]), np.ones((3, 2))
    trusted = Contact.from_trusted_arrays("cube", "table", point, normal, 0.5, jacobian)
    checked = Contact("cube", "table", point, normal, mu=0.5, jacobian=jacobian)
    for name in ("body", "other", "mu", "point", "normal", "jacobian"):
        assert np.array_equal(getattr(trusted, name), getattr(checked, name)), name
    assert type(trusted.mu) is float
    assert not (
        trusted.point.flags.writeable or trusted.normal.flags.writeable or trusted.jacobian is None or trusted.jacobian.flags.writeable
    )


def test_a_moved_world_of_shapes_pickles_without_its_kept_layout() -> None:
    """A world of shapes goes to worker processes (batch solves): its kept layout holds coal objects, left out."""
    import pickle

    from quasistatic.tools.bench.pipeline import resting_rows

    world = resting_rows(12)
    moved = world.moved({"part0": qs.Pose((0.0, 0.0, 0.021))})  # lifted within the margin of nothing: off the table
    detection = moved.detect()  # builds the kept layout
    again = pickle.loads(pickle.dumps(moved))
    _same_detection(again.detect(), detection)
    assert _rows(again.detect()) == _rows(detection)
    assert _rows(detection) != _rows(world.detect())  # the move changed the contacts
