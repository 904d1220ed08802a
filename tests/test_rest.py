"""Rest proven the only motion on the exact 3-D cones when every mover is still (solvers/certify/rest.py).

The proof must fire where rest is the only motion (a box on a table, held by still fingers, the Panda
example) and must not where another motion exists (a ball on a table rolls with no work done), and a
certified rest must survive the independent check the issue asks for: prescribing contact-mode patterns
never yields a motion other than rest.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("coal")

import quasistatic as qs  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REST_WORDS = "unique for the exact cones: every mover is still"


def _box_world(fingers: list[tuple[float, float, float]], mu: float = 0.5, size: float = 0.1) -> qs.World:
    """A cube of edge ``size`` on a table, with still spherical fingertips touching its faces at the given points."""
    radius = 0.1 * size
    movers = [qs.ShapedMover("table", qs.Halfspace([0, 0, 1], 0.0))]
    for index, point in enumerate(fingers):
        at = np.array(point, dtype=float)
        outward = np.zeros(3)
        axis = int(np.argmax(np.abs(at[:2] / (size / 2))))
        outward[axis] = np.sign(at[axis])
        movers.append(qs.ShapedMover(f"finger{index}", qs.Sphere(radius), qs.Pose(at + radius * outward)))
    body = qs.SolidBody("box", mass=1.0, shape=qs.Box([size, size, size]), pose=qs.Pose([0.0, 0.0, size / 2]))
    return qs.World(bodies=(body,), movers=tuple(movers), detection=qs.ContactDetection(mu=mu))


def test_a_box_at_rest_on_a_table_is_certified_on_the_exact_cones() -> None:
    solution = qs.solve(_box_world([]))
    assert solution.status == "solved" and solution.certified and solution.forces_indeterminate
    assert REST_WORDS in solution.message
    assert solution.motion is not None and np.allclose(solution.motion.twists["box"], 0.0)


def test_still_fingers_against_the_box_keep_the_proof() -> None:
    solution = qs.solve(_box_world([(-0.05, 0.01, 0.07), (0.05, -0.02, 0.03)], mu=0.3))
    assert solution.status == "solved" and solution.certified and REST_WORDS in solution.message


def test_the_panda_example_is_certified_with_exact_cones() -> None:
    pytest.importorskip("pinocchio")
    world = qs.load_world(EXAMPLES / "robots" / "panda_gripper.yaml")
    assert isinstance(world, qs.World) and str(world.friction) == "exact"
    solution = qs.solve(world)
    assert solution.status == "solved" and solution.certified and solution.forces_indeterminate
    assert REST_WORDS in solution.message


def test_a_ball_on_a_table_is_not_proven_at_rest() -> None:
    """A ball may roll with no work done (its contact sticks): rest is not the only motion, and no proof may say so."""
    ball = qs.World(
        bodies=(qs.SolidBody("ball", mass=1.0, shape=qs.Sphere(0.05), pose=qs.Pose([0, 0, 0.05])),),
        movers=(qs.ShapedMover("table", qs.Halfspace([0, 0, 1], 0.0)),),
        detection=qs.ContactDetection(mu=0.5),
    )
    solution = qs.solve(ball, time_limit=30)
    assert REST_WORDS not in solution.message
    assert solution.status == "ambiguous"


def test_a_load_that_could_descend_gets_no_rest_proof() -> None:
    """Gravity tilted within the friction cone: rest is the motion, but the LP step (no friction) cannot exclude sliding."""
    world = _box_world([])
    tilted = qs.World(bodies=world.bodies, movers=world.movers, detection=world.detection, gravity=[3.0, 0.0, -9.81])
    solution = qs.solve(tilted, time_limit=30)
    assert REST_WORDS not in solution.message


def _no_other_motion_with_prescribed_modes(world: qs.World, patterns: int, seed: int) -> None:
    scene = world.scene()
    rng = np.random.default_rng(seed)
    every = list(itertools.product(["rolling", "sliding", "separating"], repeat=len(scene.contacts)))
    for index in rng.choice(len(every), size=min(patterns, len(every)), replace=False):
        answer = qs.solve(scene, modes=list(every[index]), time_limit=20)
        for motion in ([answer.motion] if answer.motion else []) + list(answer.solutions):
            assert np.abs(motion.twists["box"]).max() <= 1e-9, (every[index], answer.status, motion.twists["box"])


def _random_fingers(rng: np.random.Generator) -> list[tuple[float, float, float]]:
    fingers = []
    for _ in range(int(rng.integers(0, 3))):
        side, along, height = rng.choice([-0.05, 0.05]), rng.uniform(-0.04, 0.04), rng.uniform(0.01, 0.09)
        fingers.append((side, along, height) if rng.random() < 0.5 else (along, side, height))
    return fingers


def test_certified_rest_survives_prescribed_mode_patterns() -> None:
    world = _box_world([(-0.05, 0.01, 0.07)])
    assert REST_WORDS in qs.solve(world).message
    _no_other_motion_with_prescribed_modes(world, patterns=12, seed=1)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(8))
def test_random_certified_rest_survives_prescribed_mode_patterns(seed: int) -> None:
    rng = np.random.default_rng(seed)
    world = _box_world(_random_fingers(rng), mu=float(rng.uniform(0.1, 1.0)), size=float(rng.uniform(0.02, 0.3)))
    solution = qs.solve(world)
    assert solution.status == "solved"
    if REST_WORDS in solution.message:
        _no_other_motion_with_prescribed_modes(world, patterns=40, seed=seed)
