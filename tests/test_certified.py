"""The default certified method (``certified``: cheap certificates, then the SCIP search) against ``scip``.

``certified`` must never contradict the complete search of ``scip``: the same
status, and the same motions (twists within ``TWIST_RTOL``) wherever the
search's list is complete. The default run takes 60 random 2-D scenes, 6
random 3-D ones and the 2-D benchmark grasps; ``pytest -m slow`` sweeps 300
more 2-D and 40 more 3-D scenes. The kinematic bound is checked against the
true extent of the admissible twists, computed by LPs.
"""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
from quasistatic.solvers import BACKENDS, Options
from quasistatic.solvers.certify.cheap import kinematic_radius, seed_point
from quasistatic.solvers.certify.search import enumerate_motions
from quasistatic.solvers.numerics.forces import DeferredIndeterminacy, ForcesAtTwist, forces_at_twist, indeterminate_forces, measured_masks
from quasistatic.solvers.numerics.highs import solve_lp
from quasistatic.solvers.numerics.ranges import value_ranges
from quasistatic.tolerances import LP_FEASIBILITY
from quasistatic.tools.bench.families import grasp_2d
from random_scenes import random_scene

TWIST_RTOL = 1e-6  # scene-relative twist agreement required between the methods


def _twist(problem: qs.Problem, motion: qs.Motion) -> np.ndarray:
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    return np.concatenate([motion.twists[b.name] for b in problem.scene.bodies]) / units


def _motions(solution: qs.Solution) -> tuple[qs.Motion, ...]:
    return solution.solutions or ((solution.motion,) if solution.motion is not None else ())


def _listed(problem: qs.Problem, motion: qs.Motion, among: tuple[qs.Motion, ...]) -> bool:
    twist = _twist(problem, motion)
    scale = max(1.0, float(np.max(np.abs(twist))))
    return any(
        other.continuum == motion.continuum and np.max(np.abs(_twist(problem, other) - twist)) <= TWIST_RTOL * scale for other in among
    )


def _agree(scene: qs.Scene) -> None:
    problem = qs.assemble(scene)
    new = qs.solve(problem)  # the default: method "certified"
    old = qs.solve(problem, method="scip")
    assert new.method == "certified" and new.status == old.status, f"certified: {new.message}; scip: {old.message}"
    assert new.certified == old.certified or (new.certified and new.status == "solved"), "a kinematic proof may only add certainty"
    if new.status in ("solved", "ambiguous") and old.search_complete is not False and new.search_complete is not False:
        mine, theirs = _motions(new), _motions(old)
        assert len(mine) == len(theirs)
        assert all(_listed(problem, motion, theirs) for motion in mine)
    for motion in _motions(new):
        assert motion.audit.passed


@pytest.mark.parametrize("seed", range(60))
def test_certified_agrees_with_scip_2d(seed: int) -> None:
    _agree(random_scene(2, seed))


@pytest.mark.parametrize("seed", range(6))
def test_certified_agrees_with_scip_3d(seed: int) -> None:
    _agree(random_scene(3, seed))


@pytest.mark.parametrize(("contacts", "instance"), [(m, i) for m in (2, 3, 4, 6, 8) for i in range(4)])
def test_certified_agrees_with_scip_on_benchmark_grasps(contacts: int, instance: int) -> None:
    _agree(grasp_2d(contacts, instance))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(60, 360))
def test_certified_agrees_with_scip_2d_sweep(seed: int) -> None:
    _agree(random_scene(2, seed))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6, 46))
def test_certified_agrees_with_scip_3d_sweep(seed: int) -> None:
    _agree(random_scene(3, seed))


def test_kinematic_certificate_decides_a_squeezing_grasp() -> None:
    """Seven of eight fingers close around the ellipse: non-penetration alone fixes the twist."""
    problem = qs.assemble(grasp_2d(8, 0))
    solution = qs.solve(problem)
    assert solution.status == "solved" and solution.certified
    assert "non-penetration" in dict(solution.notes).get("certificate", "")
    _agree(grasp_2d(8, 0))


def _true_extent(A: np.ndarray, t: np.ndarray) -> float:
    """Largest |d_j| over ``A d >= t``, by 2 n LPs (inf when unbounded, 0 when the set is empty)."""
    n = A.shape[1]
    worst = 0.0
    for j in range(n):
        for sign in (1.0, -1.0):
            lp = solve_lp(sign * np.eye(n)[j], A, t, np.full(len(t), np.inf), maximize=True)
            if lp.status == "infeasible":
                return 0.0
            if lp.status != "optimal":
                return np.inf
            worst = max(worst, abs(lp.x[j]))
    return worst


@pytest.mark.parametrize("seed", range(40))
def test_kinematic_radius_bounds_every_admissible_twist(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    k = int(rng.integers(n + 1, n + 5))
    A = rng.normal(size=(k, n))
    A[-1] = -rng.uniform(0.2, 1.0, k - 1) @ A[:-1]  # positive multipliers exist: a pointed set
    t = rng.normal(size=k)  # the bound is linear in t: order one keeps HiGHS's 1e-7 tolerance out of the comparison
    radius = kinematic_radius(A, t)
    extent = _true_extent(A, t)
    assert np.isfinite(extent)
    assert extent <= radius * (1.0 + 1e-6) + 1e-6, (extent, radius)


def test_kinematic_radius_refuses_an_open_set() -> None:
    A = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])  # every row points one way: d can grow along (1, 1)
    assert kinematic_radius(A, np.zeros(3)) == np.inf


@pytest.mark.parametrize("seed", range(10))
def test_seeded_search_lists_the_same_motions(seed: int) -> None:
    problem = qs.assemble(random_scene(2, seed))
    form = polyhedral_form(problem, aligned_edges(problem, 2))
    x = seed_point(form)
    if x is None:
        pytest.skip("Lemke finds no motion here")
    plain, complete = enumerate_motions(form, Options().start_clock())
    seeded, seeded_complete = enumerate_motions(form, Options().start_clock(), x)
    assert complete == seeded_complete and len(plain) == len(seeded)
    for a in seeded:
        assert any(np.max(np.abs(a.q - b.q)) <= 1e-6 and a.continuum == b.continuum for b in plain)


def _eager_normal_ranges(problem: qs.Problem, edges: np.ndarray, q: np.ndarray) -> list[tuple[float, float | None]]:
    """Every normal force's range at twist ``q`` by two LPs each: what the lazy decision must agree with."""
    masks = measured_masks(problem, edges, q)
    forces = forces_at_twist(problem, edges, q, masks)
    normal = np.arange(forces.fixed.size)[forces.polytope.normal]
    return value_ranges(forces.A, forces.rhs, normal, np.zeros(forces.fixed.size))


def _eager_component_ranges(problem: qs.Problem, edges: np.ndarray, q: np.ndarray) -> list[tuple[float | None, float | None]]:
    """Every contact-frame force component's range at twist ``q`` (tangents and normal), two LPs each."""
    forces = forces_at_twist(problem, edges, q, measured_masks(problem, edges, q))
    m, d = problem.n_contacts, problem.scene.dimension
    units = np.eye(m * d).reshape(m * d, m, d)
    return forces.ranges(units)


def _wide(ranges: list[tuple[float | None, float | None]]) -> bool:
    return any(lo is None or hi is None or hi - lo > LP_FEASIBILITY for lo, hi in ranges)


@pytest.mark.parametrize("scene", [grasp_2d(m, i) for m in (2, 4, 6, 8) for i in range(6)] + [random_scene(2, seed) for seed in range(30)])
def test_deferred_frictional_force_ranges_decide_indeterminacy_as_the_ranges_do(scene: qs.Scene) -> None:
    """``indeterminate_forces`` says "indeterminate" exactly when some force component's range (friction included),
    worked out by LPs, is wide, and the normal ranges it defers are those LPs' ranges."""
    problem = qs.assemble(scene)
    edges = aligned_edges(problem, problem.friction.edges)
    result = BACKENDS["scip"].solver(problem, Options())
    for motion in (m for m in result.motions if not m.continuum):
        eager = _eager_normal_ranges(problem, edges, motion.q)
        found = indeterminate_forces(problem, edges, motion.q)
        assert (found is not None) == _wide(_eager_component_ranges(problem, edges, motion.q))
        if found is not None:
            ranges = found.known if found.known is not None else found.lazy()
            assert [lo for lo, _ in ranges] == pytest.approx([lo for lo, _ in eager], abs=1e-9)
            assert [hi for _, hi in ranges] == pytest.approx([hi for _, hi in eager], abs=1e-9)


def _box_pushed_by_fingers(heights: tuple[float, ...], mu: float) -> qs.Scene:
    """A 2-D box sliding on two corners (friction ``mu``), pushed in +x by frictionless fingers at ``heights``."""
    box = qs.Body("box", mass=1.0, com=[0.0, 0.05])
    movers = [qs.Mover("table")] + [qs.Mover(f"finger{k}", twist=[0.01, 0.0, 0.0]) for k in range(len(heights))]
    contacts = [qs.Contact("box", "table", point=[x, 0.0], normal=[0.0, 1.0], mu=mu) for x in (-0.05, 0.05)]
    contacts += [qs.Contact("box", f"finger{k}", point=[-0.05, h], normal=[1.0, 0.0]) for k, h in enumerate(heights)]
    return qs.Scene(bodies=[box], movers=movers, contacts=contacts, dimension=2)


@pytest.mark.parametrize(("heights", "mu"), [((0.03, 0.07), 0.5), ((0.01, 0.09), 0.3), ((0.02, 0.05, 0.08), 0.8), ((0.04,), 0.5)])
def test_sliding_2d_contacts_decide_indeterminacy_as_the_ranges_do(heights: tuple[float, ...], mu: float) -> None:
    """A 2-D box sliding on two corners: a sliding contact's force lies on one edge of its cone, so a balanced
    point decides "indeterminate" without an LP (two or more fingers); the ranges, built when read, are the LPs'."""
    problem = qs.assemble(_box_pushed_by_fingers(heights, mu))
    edges = aligned_edges(problem, problem.friction.edges)
    raw = BACKENDS["certified"].solver(problem, Options())
    assert raw.status == "solved"
    q = raw.motions[0].q
    eager = _eager_normal_ranges(problem, edges, q)
    found = indeterminate_forces(problem, edges, q)
    wide = any(hi is None or hi - lo > LP_FEASIBILITY for lo, hi in eager)
    assert (found is not None) == wide == (len(heights) > 1)
    if found is not None:
        assert found.known is None and found.lazy is not None  # decided without working the ranges out
        assert not isinstance(found.force_set, ForcesAtTwist)  # nor building the force set: no LP at all
        ranges = found.lazy()
        assert [lo for lo, _ in ranges] == pytest.approx([lo for lo, _ in eager], abs=1e-9)
        assert [hi for _, hi in ranges] == pytest.approx([hi for _, hi in eager], abs=1e-9)


def test_indeterminate_frictional_forces_are_reported_without_running_their_ranges() -> None:
    """The 8-finger grasps are proven unique by kinematics with indeterminate forces: the decision and the ranges
    wait until read, and reading the decision runs no range."""
    for instance in range(3):
        problem = qs.assemble(grasp_2d(8, instance))
        raw = BACKENDS["certified"].solver(problem, Options())
        deferred = raw.motions[0].deferred
        assert isinstance(deferred, DeferredIndeterminacy) and "found" not in deferred.__dict__  # not decided yet
        assert raw.status == "solved" and raw.motions[0].forces_indeterminate
        found = deferred.found
        assert found is not None and found.known is None and found.lazy is not None
        solution = qs.solve(problem)
        assert solution.forces_indeterminate
        widths = [
            hi - lo if hi is not None else np.inf for lo, hi in (c.normal_force_range for c in solution.contacts if c.normal_force_range)
        ]
        assert max(widths) > 0.0


def _pulled_box(pull: float) -> qs.Scene:
    """A box on two supports 0.1 apart, mu = 0.5, 1 kg, its weight with a sideways part ``pull`` [N]."""
    box = qs.Body("box", mass=1.0, com=[0.0, 0.05])
    supports = tuple(qs.Contact("box", "table", point=[x, 0.0], normal=[0.0, 1.0], mu=0.5) for x in (-0.05, 0.05))
    return qs.Scene(dimension=2, bodies=(box,), movers=(qs.Mover("table"),), contacts=supports, gravity=[pull, -9.81])


def _pushed_box() -> qs.Scene:
    """The box of :func:`_pulled_box`, unpulled, pushed at the height of its com by a frictionless fingertip."""
    scene = _pulled_box(0.0)
    finger = qs.Contact("box", "finger", point=[-0.05, 0.05], normal=[1.0, 0.0], mu=0.0)
    return qs.Scene(
        dimension=2,
        bodies=scene.bodies,
        movers=(qs.Mover("table"), qs.Mover("finger", twist=[0.01, 0.0, 0.0])),
        contacts=(*scene.contacts, finger),
        gravity=scene.gravity,
    )


def test_friction_forces_that_share_a_load_are_indeterminate() -> None:
    """A box on two supports pulled gently sideways stays at rest. Its normal forces are fixed (moments about the
    com: 4.405 and 5.405 N), but how the two supports share the 1 N pull is not: any split with each friction
    force within mu = 0.5 of its normal force balances it. So the forces are indeterminate, and each support's
    friction ranges over [-mu N_i, -1 + mu N_j] (the other support taking the rest, up to its own limit)."""
    solution = qs.solve(_pulled_box(1.0))
    assert solution.status == "solved" and solution.certified
    assert np.allclose(solution.twists["box"], 0.0)
    assert solution.forces_indeterminate and "the contact forces are indeterminate" in solution.message
    normal = np.array([4.405, 5.405])
    for contact, n in zip(solution.contacts, normal, strict=True):
        assert contact.normal_force_range == pytest.approx((n, n))  # only the friction varies
    boxes = solution.motion.force_ranges
    assert boxes is not None
    for i, j in ((0, 1), (1, 0)):
        (x_lo, x_hi), (y_lo, y_hi) = boxes[i]
        assert (x_lo, x_hi) == pytest.approx((-0.5 * normal[i], -1.0 + 0.5 * normal[j]))
        assert (y_lo, y_hi) == pytest.approx((normal[i], normal[i]))
    contacts = solution.to_dict()["contacts"]
    assert contacts[0]["force_range"] == [pytest.approx([x_lo, x_hi]) for x_lo, x_hi in [boxes[0][0]]] + [pytest.approx([4.405, 4.405])]


def test_friction_forces_fixed_by_sliding_are_claimed_unique() -> None:
    """Pushed by a frictionless fingertip at the height of its com, the box slides; both friction forces are then mu
    times their normal forces, which the moments fix, and the push balances them: one force distribution, and
    the answer says so."""
    solution = qs.solve(_pushed_box())
    assert solution.status == "solved" and solution.certified and solution.twists["box"][0] == pytest.approx(0.01)
    assert not solution.forces_indeterminate and "with unique contact forces" in solution.message
    assert solution.motion.force_ranges is None
    forces = np.array([c.force for c in solution.contacts])[:2]
    assert forces[:, 0] == pytest.approx(-0.5 * forces[:, 1])


@pytest.mark.parametrize("pushed, indeterminate", [(False, True), (True, False)])
def test_the_ranges_decide_friction_indeterminacy_where_the_shortcuts_cannot(
    monkeypatch: pytest.MonkeyPatch, pushed: bool, indeterminate: bool
) -> None:
    """With both shortcuts (the balanced point's segment, the relative interior's LP) undecided, the ranges decide:
    a sideways pull shared by two supports is indeterminate, the sliding push's friction is not."""
    from quasistatic.solvers.numerics import forces as forces_module

    monkeypatch.setattr(forces_module, "_wide_through_balanced_point", lambda *args: False)
    monkeypatch.setattr(forces_module, "_forces_vary", lambda *args: None)
    solution = qs.solve(_pushed_box() if pushed else _pulled_box(1.0))
    assert solution.status == "solved" and solution.forces_indeterminate is indeterminate


def test_an_lp_the_dual_simplex_leaves_without_a_status_is_answered() -> None:
    """A sector relaxation's leaf of the puck example (four coplanar sliding supports, narrow sectors): HiGHS's
    dual simplex stops on it without a status even with presolve off; the interior-point retry answers it."""
    import json
    from pathlib import Path

    from quasistatic.solvers.numerics.highs import solve_lp

    data = {k: np.asarray(v) for k, v in json.loads((Path(__file__).parent / "data" / "highs_no_status_lp.json").read_text()).items()}
    rows = np.vstack([data["E"], data["A"]])
    lower = np.concatenate([data["e"] - 1e-7, data["a"] - 1e-7])
    upper = np.concatenate([data["e"] + 1e-7, np.full(len(data["a"]), np.inf)])
    assert solve_lp(np.zeros(rows.shape[1]), rows, lower, upper).status == "infeasible"
