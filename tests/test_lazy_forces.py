"""Whether a solved motion's forces are indeterminate is decided when first read, and equals the eager decision.

A certified 2-D solve no longer decides ``forces_indeterminate`` (a rank test, often an LP) unless something
reads it: the flag, the message's claim, the JSON, the table, the ranges. These tests pin that a default
solve leaves it undecided, that every way of reading it gives what the eager decision
(:func:`~quasistatic.solvers.numerics.forces.indeterminate_forces` on the same twist) gives, on the bench
grasps and on scenes whose forces are indeterminate, and that pickling works it out first.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws.polyhedral import aligned_edges
from quasistatic.sim import Inputs, SimModel, State, StepOptions, evaluate
from quasistatic.solution import Later, LaterField
from quasistatic.solvers.numerics.forces import indeterminate_forces
from quasistatic.tolerances import LP_FEASIBILITY
from quasistatic.tools.bench.families import grasp_2d
from quasistatic.tools.bench.simulation import planar_two_finger_push


def _decided(solution: qs.Solution) -> bool:
    field = type(solution).__dict__["forces_indeterminate"]
    assert isinstance(field, LaterField)
    return field.decided(solution)


def _eager(problem: qs.Problem, twist: np.ndarray) -> bool:
    return indeterminate_forces(problem, aligned_edges(problem, problem.friction.edges), twist) is not None


def _scaled_twist(problem: qs.Problem, motion: qs.Motion) -> np.ndarray:
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    return np.concatenate([motion.twists[b.name] for b in problem.scene.bodies]) / units


def _pushed_box(heights: tuple[float, ...], pull: float = 0.0) -> qs.Scene:
    """A 2-D box on two table corners (mu 0.5) pushed in +x by frictionless fingers at ``heights`` (none: at rest)."""
    box = qs.Body("box", mass=1.0, com=[0.0, 0.05])
    movers = [qs.Mover("table")] + [qs.Mover(f"finger{k}", twist=[0.01, 0.0, 0.0]) for k in range(len(heights))]
    contacts = [qs.Contact("box", "table", point=[x, 0.0], normal=[0.0, 1.0], mu=0.5) for x in (-0.05, 0.05)]
    contacts += [qs.Contact("box", f"finger{k}", point=[-0.05, h], normal=[1.0, 0.0]) for k, h in enumerate(heights)]
    return qs.Scene(bodies=[box], movers=movers, contacts=contacts, dimension=2, gravity=[pull, -9.81])


SCENES = [grasp_2d(m, i) for m in (2, 4, 6, 8) for i in range(6)] + [
    _pushed_box((0.03, 0.07)),  # sliding, two fingers: indeterminate
    _pushed_box((0.05,)),  # sliding, one finger at the com's height: unique
    _pushed_box((), pull=1.0),  # at rest, a pull shared by two supports: indeterminate friction
]


@pytest.mark.parametrize("scene", SCENES)
def test_the_deferred_decision_equals_the_eager_one(scene: qs.Scene) -> None:
    problem = qs.assemble(scene)
    solution = qs.solve(problem)
    motions = solution.solutions or ((solution.motion,) if solution.motion is not None else ())
    if solution.status not in ("solved", "ambiguous") or (solution.motion is not None and solution.motion.continuum):
        assert not solution.forces_indeterminate
        return
    assert not _decided(solution)  # nothing read it yet
    eager = _eager(problem, _scaled_twist(problem, motions[0]))
    assert solution.forces_indeterminate == eager
    assert solution.to_dict()["forces_indeterminate"] == eager
    if solution.status == "solved":
        claim = "; the contact forces are indeterminate" if eager else " with unique contact forces"
        assert solution.message.endswith(claim)
        assert qs.solve(problem).message == solution.message  # the message alone decides it the same way
    for motion in motions:
        if not motion.continuum:
            assert motion.forces_indeterminate == _eager(problem, _scaled_twist(problem, motion))
            assert any(c.normal_force_range is not None for c in motion.contacts) == motion.forces_indeterminate


def test_indeterminate_scenes_are_among_the_checked_ones() -> None:
    """The scenes above hold both answers, so the equality is not checked on one side only."""
    flags = {qs.solve(scene).forces_indeterminate for scene in SCENES[-3:]}
    assert flags == {True, False}


def test_a_pickled_solution_carries_the_decided_values() -> None:
    solution = qs.solve(_pushed_box((0.03, 0.07)))
    assert not _decided(solution)
    back = pickle.loads(pickle.dumps(solution))
    assert _decided(back) and back.forces_indeterminate and back.message == solution.message
    assert [c.normal_force_range for c in back.contacts] == [c.normal_force_range for c in solution.contacts]


def test_a_simulation_step_does_not_decide_it() -> None:
    """A planar push step reads the motion, its modes and forces, never whether the forces are indeterminate."""
    world = planar_two_finger_push()
    model = SimModel(world, StepOptions(0.05))
    evaluation = evaluate(model, State.of(world), Inputs())
    assert evaluation.solution.status == "solved"
    evaluation.contact_records()
    assert not _decided(evaluation.solution)
    assert isinstance(evaluation.solution.forces_indeterminate, bool)


def test_later_works_its_value_out_once() -> None:
    calls: list[int] = []
    later = Later(lambda: calls.append(1) or len(calls))
    assert not later.decided
    assert later.value() == 1 and later.value() == 1 and calls == [1] and later.decided


def _tipping_box(height: float, mu: float) -> qs.Scene:
    """The sweep bench's box (0.2 m wide, 2 kg) pushed at ``height`` by a frictionless pusher; mu on the floor."""
    box = qs.Body("box", mass=2.0, com=[0.0, 0.2])
    contacts = [qs.Contact("box", "floor", point=[x, 0.0], normal=[0.0, 1.0], mu=mu) for x in (-0.1, 0.1)]
    contacts.append(qs.Contact("box", "pusher", point=[-0.1, height], normal=[1.0, 0.0]))
    movers = [qs.Mover("floor"), qs.Mover("pusher", twist=[0.01, 0.0, 0.0])]
    return qs.Scene(bodies=[box], movers=movers, contacts=contacts, dimension=2)


@pytest.mark.parametrize(("height", "mu"), [(0.236, 0.5), (0.38, 1.0), (0.164, 1.0)])
def test_a_lifted_corner_is_decided_by_the_rank_test(monkeypatch: pytest.MonkeyPatch, height: float, mu: float) -> None:
    """A tipping box lifts one corner: that contact's friction edges and slack are held at zero with its normal force,
    so the dense rank test proves the forces unique, as every component's LP range says, without building the set."""
    from quasistatic.solvers.numerics import forces as forces_module

    problem = qs.assemble(_tipping_box(height, mu))
    solution = qs.solve(problem)
    assert solution.modes[0] == "separating" and solution.status == "solved"
    edges = aligned_edges(problem, problem.friction.edges)
    q = _scaled_twist(problem, solution.motion)
    masks = forces_module.measured_masks(problem, edges, q)
    every = forces_module.forces_at_twist(problem, edges, q, masks)
    units = np.eye(problem.n_contacts * 2).reshape(-1, problem.n_contacts, 2)
    assert all(hi is not None and hi - lo <= LP_FEASIBILITY for lo, hi in every.ranges(units))  # the LPs: unique

    def built(*args: object) -> None:
        raise AssertionError("the force set was built")

    monkeypatch.setattr(forces_module, "forces_at_twist", built)
    assert indeterminate_forces(problem, edges, q) is None
    assert forces_module._forces_fixed(problem, edges, q, masks, forces_module._component_rows(edges))  # the polytope's test too
    assert not solution.forces_indeterminate and solution.message.endswith(" with unique contact forces")


def test_a_3d_rest_proven_on_the_exact_cones_defers_its_force_claim_too() -> None:
    """A box at rest on a table (3-D, exact cones): the message ends with the exact-cone proof, after the force claim
    worked out when read; the claim and the flag are the eager decision's on the 16-edge pyramid of the ranges."""
    pytest.importorskip("coal")  # the world's contacts are found by the robots extra
    from quasistatic.solvers.certify.exact_cone import RANGE_EDGES

    body = qs.SolidBody("box", mass=1.0, shape=qs.Box([0.1, 0.1, 0.1]), pose=qs.Pose([0.0, 0.0, 0.05]))
    world = qs.World(bodies=(body,), movers=(qs.ShapedMover("table", qs.Halfspace([0, 0, 1], 0.0)),), detection=qs.ContactDetection(mu=0.5))
    problem = qs.assemble(world.scene())
    solution = qs.solve(problem)
    assert solution.status == "solved" and not _decided(solution)
    eager = indeterminate_forces(problem, aligned_edges(problem, RANGE_EDGES), np.zeros(problem.n_dof)) is not None
    assert eager and solution.forces_indeterminate
    assert "solved: one motion; the contact forces are indeterminate; unique for the exact cones: " in solution.message
