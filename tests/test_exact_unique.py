"""The exact-cone uniqueness proof: interval arithmetic, Krawczyk's test, the fixed-mode laws' enclosure, and
the certified 3-D answers it gives (their independent check against every mode pattern is in
``test_mode_patterns.py``)."""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.interval import Interval, krawczyk, matmul, point
from quasistatic.laws import ModeMasks, contact_modes
from quasistatic.laws.fixed_modes import FixedModeLaws
from quasistatic.solvers import Options
from quasistatic.solvers.certified import solve_cheap_certified
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
