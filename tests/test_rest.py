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
from quasistatic.laws.polyhedral import aligned_edges  # noqa: E402
from quasistatic.solvers import Options  # noqa: E402
from quasistatic.solvers.certify import rest as rest_module  # noqa: E402
from quasistatic.solvers.certify.exact_cone import RANGE_EDGES  # noqa: E402
from quasistatic.solvers.certify.rest import load_cannot_descend, no_motion_away_from_rest  # noqa: E402
from quasistatic.solvers.certify.rest_lp import rest_proven_by_lps  # noqa: E402
from quasistatic.solvers.numerics import forces as forces_module  # noqa: E402
from quasistatic.solvers.numerics.forces import forces_at_twist, indeterminate_forces, measured_masks  # noqa: E402
from quasistatic.solvers.numerics.highs import solve_lp  # noqa: E402
from quasistatic.solvers.numerics.ranges import ranges_are_wide, value_ranges  # noqa: E402
from quasistatic.tolerances import LP_FEASIBILITY  # noqa: E402

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


# --------------------------------------------------------------------------- the proof by LPs (certify/rest_lp.py)

LP_WORDS = "LPs: Gordan multipliers, singular values, Farkas twists"


def _finger_at(rng: np.random.Generator, size: float, centre: np.ndarray) -> qs.ShapedMover:
    """A still spherical fingertip touching a random point of one side face of the cube of edge ``size`` at ``centre``."""
    side, along, height = rng.choice([-0.5, 0.5]) * size, rng.uniform(-0.4, 0.4) * size, rng.uniform(-0.4, 0.4) * size
    axis = int(rng.integers(0, 2))
    point, outward = np.array([along, along, height]), np.zeros(3)
    point[axis], outward[axis] = side, np.sign(side)
    radius = 0.1 * size
    return qs.ShapedMover(f"finger{rng.integers(1 << 30)}", qs.Sphere(radius), qs.Pose(centre + point + radius * outward))


def _resting_world(seed: int) -> qs.World:
    """A seeded resting scene, every mover still: a box (its com sometimes off-centre, so it may tip), a ball or a lying
    cylinder (they may roll), or two stacked boxes, on a table, with 0 to 3 still fingertips on the box; friction per
    pair, a quarter of them frictionless (a part may slide at no cost), gravity sometimes tilted (it may slide)."""
    rng = np.random.default_rng(seed)
    kind = str(rng.choice(["box", "ball", "cylinder", "stack"]))
    size = float(rng.uniform(0.02, 0.3))

    def mu() -> float:
        return 0.0 if rng.random() < 0.25 else float(rng.uniform(0.05, 1.0))

    centre, upright = np.array([0.0, 0.0, size / 2]), qs.Pose([0.0, 0.0, size / 2])
    movers, pairs = [qs.ShapedMover("table", qs.Halfspace([0, 0, 1], 0.0))], [qs.FrictionPair(("b0", "table"), mu())]
    if kind == "ball":
        bodies = [qs.SolidBody("b0", 1.0, qs.Sphere(size / 2), upright)]
    elif kind == "cylinder":
        lying = qs.Pose(centre, [[1, 0, 0], [0, 0, -1], [0, 1, 0]])
        bodies = [qs.SolidBody("b0", 1.0, qs.Cylinder(size / 2, size), lying)]
    else:
        com = [*(rng.uniform(-0.7, 0.7, 2) * size), 0.0] if rng.random() < 0.3 else [0.0, 0.0, 0.0]
        bodies = [qs.SolidBody("b0", 1.0, qs.Box([size] * 3), upright, com=com)]
        for _ in range(int(rng.integers(0, 4))):
            movers.append(_finger_at(rng, size, centre))
            pairs.append(qs.FrictionPair(("b0", movers[-1].name), mu()))
    if kind == "stack":
        top, shift = float(rng.uniform(0.3, 1.0)) * size, rng.uniform(-0.3, 0.3, 2) * size
        bodies.append(qs.SolidBody("b1", 0.5, qs.Box([top] * 3), qs.Pose([*shift, size + top / 2])))
        pairs.append(qs.FrictionPair(("b0", "b1"), mu()))
    gravity = [float(rng.uniform(-6.0, 6.0)) if rng.random() < 0.3 else 0.0, 0.0, -9.81]
    detection = qs.ContactDetection(mu=0.5, pairs=tuple(pairs))
    return qs.World(bodies=tuple(bodies), movers=tuple(movers), detection=detection, gravity=gravity)


def _lp_against_scip(seeds: range) -> dict[str, int]:
    """On each resting scene that passes step 1: the LP proof may only say "rest" where SCIP's program is infeasible."""
    counts = {"descends": 0, "lp proven": 0, "scip proven only": 0, "scip finds a motion": 0}
    for seed in seeds:
        problem = qs.assemble(_resting_world(seed).scene())
        if not load_cannot_descend(problem):
            counts["descends"] += 1
            continue
        by_lps = rest_proven_by_lps(problem)
        by_scip = no_motion_away_from_rest(problem, Options(time_limit=60.0).start_clock())
        assert by_scip or not by_lps, f"seed {seed}: the LPs proved rest where SCIP finds another motion"
        key = "lp proven" if by_lps else ("scip proven only" if by_scip else "scip finds a motion")
        counts[key] += 1
    return counts


def test_the_lp_proof_never_certifies_rest_where_scip_finds_another_motion() -> None:
    counts = _lp_against_scip(range(40))
    # The draw holds every case, so the implication above was tested both ways.
    assert min(counts.values()) >= 1, counts


@pytest.mark.slow
def test_the_lp_proof_never_certifies_rest_where_scip_finds_another_motion_many_scenes() -> None:
    counts = _lp_against_scip(range(40, 400))
    assert min(counts.values()) >= 10, counts


@pytest.mark.parametrize("fingers", [[], [(-0.05, 0.01, 0.07), (0.05, -0.02, 0.03)]])
def test_a_box_on_a_table_is_proven_at_rest_by_lps(fingers: list[tuple[float, float, float]]) -> None:
    """One corner can be still while the box turns about it, but no single corner holds the box up: no SCIP needed."""
    solution = qs.solve(_box_world(fingers))
    assert solution.status == "solved" and solution.certified and LP_WORDS in solution.message


def _allegro() -> qs.World:
    pytest.importorskip("pinocchio")
    from quasistatic.tools.bench.pipeline import allegro_grasp

    try:
        world, _ = allegro_grasp()
    except qs.SceneError:
        pytest.skip("example-robot-data is not installed")
    return world


def test_the_allegro_grasp_is_certified_without_scip_or_force_lps(monkeypatch: pytest.MonkeyPatch) -> None:
    """The benchmark's grasp: rest proven by the LPs (SCIP's program is never run), and its forces shown indeterminate
    by a segment through a balanced point (no LP); the ranges themselves still come from LPs when read."""
    world = _allegro()

    def refused(*args: object, **kwargs: object) -> None:
        raise AssertionError("not expected on this grasp")

    monkeypatch.setattr(rest_module, "no_motion_away_from_rest", refused)
    monkeypatch.setattr(forces_module, "solve_lp", refused)
    solution = qs.solve(world)
    assert solution.status == "solved" and solution.certified and LP_WORDS in solution.message
    assert solution.forces_indeterminate
    monkeypatch.undo()
    ranges = [c.normal_force_range for c in solution.contacts]
    assert all(r is not None for r in ranges) and any(hi is None or hi - lo > 0.0 for lo, hi in ranges)  # the squeeze has no bound


@pytest.mark.parametrize("seed", range(24))
def test_indeterminate_rest_forces_agree_with_their_ranges(seed: int) -> None:
    """The segment proof of indeterminacy (no LP) says "indeterminate" only where the ranges, by LPs, are wide."""
    problem = qs.assemble(_resting_world(seed).scene())
    edges = aligned_edges(problem, RANGE_EDGES)
    rest = np.zeros(problem.n_dof)
    masks = measured_masks(problem, edges, rest)
    forces = forces_at_twist(problem, edges, rest, masks)
    normal = np.arange(forces.fixed.size)[forces.polytope.normal]
    if solve_lp(np.zeros(forces.fixed.size), forces.A, forces.rhs, forces.rhs, np.zeros(forces.fixed.size)).status != "optimal":
        return  # nothing balances the load at rest: no forces to compare
    eager = value_ranges(forces.A, forces.rhs, normal, np.zeros(forces.fixed.size))
    m, d = problem.n_contacts, 3
    friction = forces.ranges(np.eye(m * d).reshape(m * d, m, d))  # every component, tangents included
    wide = ranges_are_wide(eager) or any(lo is None or hi is None or hi - lo > LP_FEASIBILITY for lo, hi in friction)
    assert (indeterminate_forces(problem, edges, rest) is not None) == wide
