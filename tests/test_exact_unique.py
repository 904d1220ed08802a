"""The exact-cone uniqueness proof: interval arithmetic, Krawczyk's test, the fixed-mode laws' enclosure, and
the certified 3-D answers it gives (their independent check against every mode pattern is in
``test_mode_patterns.py``)."""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.interval import Interval, krawczyk, linear_solutions, matmul, point, unit_vectors
from quasistatic.laws import ModeMasks, contact_modes
from quasistatic.laws.fixed_modes import FixedModeLaws
from quasistatic.solvers import Options
from quasistatic.solvers.certified import solve_cheap_certified
from quasistatic.solvers.certify import exact_cone, exact_unique
from quasistatic.tools.bench.families import grasp_3d
from random_scenes import random_scene


def _random_interval(rng: np.random.Generator, shape: tuple[int, ...]) -> Interval:
    a, b = rng.normal(size=shape), rng.normal(size=shape)
    return Interval(np.minimum(a, b), np.maximum(a, b))


def _sample(rng: np.random.Generator, box: Interval) -> np.ndarray:
    return box.lo + rng.random(box.lo.shape) * (box.hi - box.lo)


def _holds(box: Interval, value: np.ndarray) -> bool:
    return bool(np.all(box.lo <= value) and np.all(value <= box.hi))


def test_interval_operations_hold_every_point_result() -> None:
    rng = np.random.default_rng(0)
    for _ in range(200):
        x, y = _random_interval(rng, (4,)), _random_interval(rng, (4,))
        A = rng.normal(size=(3, 4))
        positive = Interval(np.abs(x.lo) + 0.1, np.abs(x.lo) + 0.1 + (x.hi - x.lo))
        for _ in range(5):
            a, b, p = _sample(rng, x), _sample(rng, y), _sample(rng, positive)
            assert _holds(x + y, a + b) and _holds(x - y, a - b) and _holds(x * y, a * b)
            assert _holds(x.square(), a * a) and _holds(positive.sqrt(), np.sqrt(p)) and _holds(positive.reciprocal(), 1.0 / p)
            assert _holds(matmul(A, x), A @ a) and _holds(x.sum(), a.sum())


def test_interval_square_is_never_negative_and_reciprocal_refuses_zero() -> None:
    straddling = Interval(np.array([-1.0]), np.array([2.0]))
    assert straddling.square().lo[0] == 0.0 and straddling.square().hi[0] >= 4.0
    assert (straddling * straddling).lo[0] < 0.0  # the product does not know its factors are one number
    with pytest.raises(ZeroDivisionError):
        straddling.reciprocal()


def _square_minus_two(box: Interval) -> tuple[Interval, Interval]:
    return box.square() - 2.0, (box * 2.0)[:, None]  # F and F' (a 1 x 1 matrix)


@pytest.mark.parametrize(
    ("lo", "hi", "unique"),
    [(1.3, 1.5, True), (1.0, 2.0, True), (0.1, 3.0, False), (-2.0, 2.0, False), (1.5, 1.7, False)],
)
def test_krawczyk_proves_the_one_root_of_x2_minus_2_only_in_a_box_that_holds_it_alone(lo: float, hi: float, unique: bool) -> None:
    """x^2 - 2: one zero in [1.3, 1.5] and in [1, 2]; [0.1, 3] holds it too but is too wide for the test;
    [-2, 2] holds two (no test may pass); [1.5, 1.7] holds none."""
    box = Interval(np.array([lo]), np.array([hi]))
    center = box.mid
    residual = _square_minus_two(point(center))[0]
    test = krawczyk(center, box, residual, _square_minus_two(box)[1])
    assert test.unique is unique
    if 0.0 < lo < np.sqrt(2.0) < hi:  # (the box [-2, 2] has no inverse at its centre)
        assert test.image is not None and _holds(test.image, np.array([np.sqrt(2.0)]))  # every zero of the box


def test_krawczyk_contraction_is_measured_in_the_box_own_scale() -> None:
    """Two decoupled equations, one in units 10^6 times the other's: the norm is the worse one's, not 10^6."""

    def laws(box: Interval) -> tuple[Interval, Interval]:
        x, y = box[0:1], box[1:2]
        jacobian = Interval(np.zeros((2, 2)), np.zeros((2, 2)))
        dx, dy = x * 2.0, (y * 2e-6) * 1e-6
        jacobian.lo[0, 0], jacobian.hi[0, 0], jacobian.lo[1, 1], jacobian.hi[1, 1] = dx.lo[0], dx.hi[0], dy.lo[0], dy.hi[0]
        return Interval(
            np.concatenate([(x.square() - 2.0).lo, (y.square() * 1e-12 - 2.0).lo]),
            np.concatenate([(x.square() - 2.0).hi, (y.square() * 1e-12 - 2.0).hi]),
        ), jacobian

    root = np.array([np.sqrt(2.0), 1e6 * np.sqrt(2.0)])
    box = Interval(root * 0.99, root * 1.01)
    test = krawczyk(root, box, laws(point(root))[0], laws(box)[1])
    assert test.unique and test.contraction < 0.1


def test_linear_solutions_hold_the_solution_of_every_system_of_the_family() -> None:
    rng = np.random.default_rng(2)
    for _ in range(50):
        A_mid = rng.normal(size=(4, 4)) + 4.0 * np.eye(4)
        A = Interval(A_mid - 0.05 * rng.random((4, 4)), A_mid + 0.05 * rng.random((4, 4)))
        b = _random_interval(rng, (4,))
        box = linear_solutions(A, b)
        assert box is not None
        for _ in range(20):
            assert _holds(box, np.linalg.solve(_sample(rng, A), _sample(rng, b)))


def test_linear_solutions_refuse_a_family_holding_a_singular_matrix() -> None:
    A = Interval(np.array([[1.0, 0.0], [0.0, -0.1]]), np.array([[1.0, 0.0], [0.0, 0.1]]))  # diag(1, 0) among them
    assert linear_solutions(A, point(np.ones(2))) is None


@pytest.mark.parametrize("centre", [0.0, 0.5 * np.pi, np.pi, -0.5 * np.pi, 1.0, 3.0, -3.1, 7.0])
def test_unit_vectors_hold_every_direction_of_the_arc_and_its_extremes(centre: float) -> None:
    lo, hi = np.array([centre - 0.2, centre - 1e-9]), np.array([centre + 0.3, centre + 1e-9])
    box = unit_vectors(lo, hi)
    for k in range(2):
        for angle in np.linspace(lo[k], hi[k], 101):
            assert _holds(box[k], np.array([np.cos(angle), np.sin(angle)]))
    assert np.all(box.hi[1] - box.lo[1] < 1e-8)  # a thin arc gives a thin box


def _solved_grasp() -> tuple[qs.Problem, FixedModeLaws, np.ndarray]:
    """A benchmark grasp whose motion slides at two contacts: its fixed-mode laws and their unknowns at the motion."""
    problem = qs.assemble(grasp_3d(4, 0))
    motion = solve_cheap_certified(problem, Options()).motions[0]
    laws = FixedModeLaws(problem, ModeMasks.of(problem, contact_modes(problem, motion.q)))
    return problem, laws, laws.start(motion.q, motion.c)


def test_the_fixed_mode_enclosure_holds_the_residual_and_jacobian_across_its_box() -> None:
    _, laws, x = _solved_grasp()
    rng = np.random.default_rng(1)
    for radius in (1e-6, 1e-3, 1e-2):
        box = Interval(x - radius, x + radius)
        enclosure = laws.enclosure(box)
        assert enclosure is not None
        for _ in range(20):
            y = _sample(rng, box)
            assert _holds(enclosure[0], laws.residual(y)) and _holds(enclosure[1], laws.jacobian(y))


def test_the_fixed_mode_enclosure_refuses_a_box_where_a_slip_may_vanish() -> None:
    problem, laws, x = _solved_grasp()
    huge = Interval(x - 100.0, x + 100.0)
    assert laws.enclosure(huge) is None  # a sliding contact's slip direction is not smooth through zero slip


def test_the_force_matrix_holds_the_equilibrium_columns_for_every_slip_direction_in_its_boxes() -> None:
    """``E`` of ``g + E f = 0`` (a sliding contact's column ``n - mu T^T e``) for sampled directions ``e``, and
    at the motion's own slips the laws' Jacobian block."""
    problem, laws, x = _solved_grasp()
    n = problem.n_dof
    slips = problem.velocities(x[:n])[:, :2]
    angles = np.arctan2(slips[:, 1], slips[:, 0])
    at_motion = laws.force_matrix(unit_vectors(angles, angles))
    assert _holds(at_motion, laws.jacobian(x)[:n, n:])
    box = laws.force_matrix(unit_vectors(angles - 0.1, angles + 0.1))
    sliding = np.flatnonzero(laws.masks.sliding)
    rng = np.random.default_rng(3)
    for _ in range(20):
        E = laws.jacobian(x)[:n, n:].copy()
        for i in sliding:
            a = angles[i] + rng.uniform(-0.1, 0.1)
            e = np.array([np.cos(a), np.sin(a)])
            E[:, laws.column[i] - n] = problem.Jn[i] - problem.mu[i] * (problem.Jt[i].T @ e)
        assert _holds(box, E)


def test_krawczyk_proves_the_grasp_motion_alone_in_a_small_box_not_a_wide_one() -> None:
    _, laws, x = _solved_grasp()
    residual = laws.enclosure(point(x))
    assert residual is not None
    for radius, unique in ((1e-5, True), (1e-2, False)):
        box = Interval(x - radius, x + radius)
        enclosure = laws.enclosure(box)
        assert enclosure is not None
        assert krawczyk(x, box, residual[0], enclosure[1]).unique is unique


@pytest.mark.parametrize("seed", [4, 5, 13])
def test_exact_cone_grasps_with_sliding_contacts_are_certified_unique(seed: int) -> None:
    """Random 3-D scenes whose motion slides at some contacts: ``solved`` is now proven on the circles."""
    solution = qs.solve(random_scene(3, seed))
    assert solution.status == "solved", solution.message
    assert solution.certified is True
    assert "sliding" in solution.modes
    assert "unique for the exact cones" in solution.message and "Krawczyk" in solution.message


def test_a_benchmark_grasp_is_certified_on_the_exact_cones() -> None:
    solution = qs.solve(grasp_3d(4, 0))
    assert solution.status == "solved" and solution.certified is True, solution.message
    assert solution.modes.count("sliding") == 2


@pytest.mark.parametrize("first_proof", [True, False])
def test_a_second_exact_motion_met_by_the_far_part_makes_the_answer_ambiguous(first_proof: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """Seed 181: the 8-edge pyramid's only motion tips the box about two table corners, but the circles also let
    it slide flat on all three (the pyramid misses it). With the fast path's motion withheld, the far part's
    surviving leaf is no motion itself; Newton's method from it with the leaf's modes reaches that one. With it,
    the fast path's motion is that one (its first proof pauses), so no proof runs. Either way the answer lists
    both, each audited."""
    if not first_proof:
        monkeypatch.setattr(exact_cone, "_newton_from_lemke", lambda problem: None)
    solution = qs.solve(random_scene(3, 181))
    assert solution.status == "ambiguous", solution.message
    assert len(solution.solutions) == 2 and all(motion.audit.passed for motion in solution.solutions)
    assert sorted(motion.modes.count("sliding") for motion in solution.solutions) == [1, 4]
    assert "incomplete" in solution.message
    found = "Newton's method from where Lemke's path ends found" if first_proof else "the exact-cone uniqueness proof met"
    assert f"{found} a second exact motion" in dict(solution.notes)["exact_cone"]


@pytest.mark.parametrize(("seed", "paused_in"), [(172, "far"), (26, "near")])
def test_a_paused_proof_resumed_ends_as_the_proof_run_at_once(seed: int, paused_in: str) -> None:
    """A proof paused after one round (seed 172's takes two), or at the near part's first arc (seed 26's fails it),
    and then resumed, reaches the verdict and the round count of the proof run without a pause."""
    problem = qs.assemble(random_scene(3, seed))
    motion = exact_cone._newton_from_lemke(problem)
    assert motion is not None

    def is_motion(q: np.ndarray) -> bool:
        return exact_cone._exact_forces(problem, q) is not None

    whole = exact_unique.prove_unique_exact(problem, motion, Options(time_limit=30.0).start_clock(), is_motion)
    first = exact_unique.prove_unique_exact(problem, motion, Options(time_limit=30.0).start_clock(), is_motion, pause_after=1)
    assert whole.proven and whole.rounds >= 2
    assert not first.proven and first.paused is not None and (first.paused.far is None) == (paused_in == "near")
    resumed = exact_unique.resume_unique_exact(first.paused, Options(time_limit=30.0).start_clock(), is_motion)
    assert (resumed.proven, resumed.rounds) == (whole.proven, whole.rounds)


def test_an_arc_that_passes_after_a_wider_one_failed_is_widened_and_then_closes_the_far_part() -> None:
    """Seed 111 (three sliding contacts, ill-conditioned): the first arc fails Krawczyk's test and the shrunk one
    (1.4e-4 rad) leaves the far part a leaf next to it in every round; widened towards the arc that failed
    (7.3e-4) the far part closes, so the answer is certified."""
    solution = qs.solve(random_scene(3, 111))
    assert solution.status == "solved" and solution.certified is True, solution.message
    assert solution.modes.count("sliding") == 3
    assert "unique for the exact cones" in solution.message


@pytest.fixture(scope="module")
def near_grasp_motion() -> tuple[exact_unique._NearMotion, ModeMasks, np.ndarray]:
    """Grasp 4 #0's motion for Krawczyk's exclusion of slip pieces, its masks, and its sliding slip angles (solved
    once for the module)."""
    problem, laws, x = _solved_grasp()
    residual = laws.enclosure(point(x))
    assert residual is not None
    slips = problem.velocities(x[: laws.n])[:, :2]
    return exact_unique._NearMotion(problem, laws, x, residual[0]), laws.masks, np.arctan2(slips[:, 1], slips[:, 0])


@pytest.mark.parametrize(
    ("offsets", "excluded"),
    [
        (((-1e-3, 1e-3), (-1e-3, 1e-3)), False),  # holds the motion: never excluded
        (((-1e-2, 1e-2), (-1e-2, 1e-2)), False),
        (((1e-3, 2e-3), (-1e-3, 1e-3)), True),  # next to it
        (((-1e-3, 1e-3), (-3e-3, -1e-3)), True),
        (((1e-2, 3e-2), (1e-2, 3e-2)), True),
        (((0.3, 0.5), (-1e-3, 1e-3)), True),
    ],
)
def test_krawczyk_excludes_slip_pieces_beside_the_motion_never_one_that_holds_it(
    near_grasp_motion: tuple[exact_unique._NearMotion, ModeMasks, np.ndarray], offsets: tuple[tuple[float, float], ...], excluded: bool
) -> None:
    """The far part's exclusion of a leaf next to the arcs: a piece of slip angles (offsets from the motion's, at
    grasp 4 #0's two sliding contacts) is excluded only where the fixed-mode laws have no zero in it."""
    near, masks, angles = near_grasp_motion
    sliding = np.flatnonzero(masks.sliding)
    assert sliding.size == len(offsets)
    ends = np.zeros((masks.sliding.size, 2))
    for i, (lo, hi) in zip(sliding, offsets, strict=True):
        ends[i] = angles[i] + lo, angles[i] + hi
    assert near.excludes(masks, ends) is excluded


def test_an_ill_conditioned_sliding_grasp_is_certified_by_excluding_the_leaves_beside_its_arcs() -> None:
    """Seed 221 (four sliding contacts, one slipping 40 times slower than the others): a leaf next to the arcs
    survived every halving of the sector relaxation; Krawczyk's operator excludes those, and the answer is
    certified."""
    solution = qs.solve(random_scene(3, 221))
    assert solution.status == "solved" and solution.certified is True, solution.message
    assert solution.modes.count("sliding") == 4
    assert "unique for the exact cones" in solution.message
