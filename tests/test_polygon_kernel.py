"""A polygon of half-planes (``solvers/numerics/polygon.py``): the mode branch and bound's plane of twists.

The installed kernel (numba, its loops in C, or whole-array numpy) and the numpy twin agree on every polygon:
empty, unbounded, too close to call, or the same vertices; the vertices are the polygon's (each meets every
row, and the hull holds every point that meets them). The C loops give the numba kernel's bits.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest

from quasistatic import compiled
from quasistatic.solvers.certify import patterns
from quasistatic.solvers.numerics import polygon as kernel_module
from quasistatic.solvers.numerics.polygon import NEAR_SEED, UNBOUNDED, polygon_ball, polygon_vertices

PARALLEL, SKEW, SLACK = patterns._PARALLEL, patterns._SKEW, patterns.ROUNDOFF_SLACK  # the branch and bound's


def _polygons() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """``(rates, reserve, rows)``: random half-planes around the origin (bounded), shifted off it (often empty),
    in a half-plane's worth of directions (unbounded), with zero rows met or not, parallel and near-parallel
    pairs, and rows left out."""
    rng = np.random.default_rng(11)
    for count in (3, 4, 6, 10, 19):
        for shift in (0.0, 3.0):
            for _ in range(6):
                angles = rng.uniform(0.0, 2.0 * np.pi, count)
                rates = np.stack([np.cos(angles), np.sin(angles)], axis=1) * rng.uniform(0.5, 2.0, (count, 1))
                yield rates, rng.uniform(0.2, 1.0, count) - shift * rng.random(count), rng.random(count) < 0.9
    half = np.linspace(0.1, 3.0, 5)
    yield np.stack([np.cos(half), np.sin(half)], axis=1), np.ones(5), np.ones(5, dtype=bool)  # unbounded
    square = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [0.0, 0.0]])
    for zero_row in (1.0, -1.0):  # a zero row met everywhere, or nowhere
        yield square, np.array([1.0, 1.0, 1.0, 1.0, zero_row]), np.ones(5, dtype=bool)
    tilted = np.vstack([square[:4], [1.0, 1e-11]])  # nearly parallel to the first row: too close to call
    yield tilted, np.ones(5), np.ones(5, dtype=bool)
    yield np.vstack([square[:4], [2.0, 0.0]]), np.array([1.0, 1.0, 1.0, 1.0, 0.5]), np.ones(5, dtype=bool)  # parallel


def _vertices(kernel: Callable[..., int], rates: np.ndarray, reserve: np.ndarray, rows: np.ndarray) -> tuple[int, np.ndarray]:
    kept = int(rows.sum())
    vertices = np.full((kept * (kept - 1) // 2, 2), np.nan)
    count = kernel(np.ascontiguousarray(rates), reserve, rows, PARALLEL, SKEW, SLACK, vertices)
    return count, vertices[: max(count, 0)]


def test_the_kernel_and_its_numpy_twin_find_the_same_polygons() -> None:
    answers = set()
    for rates, reserve, rows in _polygons():
        count, vertices = _vertices(polygon_vertices, rates, reserve, rows)
        count_twin, vertices_twin = _vertices(kernel_module._polygon_vertices_numpy, rates, reserve, rows)
        assert count == count_twin
        np.testing.assert_allclose(vertices, vertices_twin, rtol=1e-12, atol=1e-15)
        answers.add("empty" if count == 0 else "unbounded" if count == UNBOUNDED else "polygon")
    assert answers == {"empty", "unbounded", "polygon"}


def test_the_vertices_are_the_polygons() -> None:
    """Each vertex meets every kept row; random points that meet them all lie in the vertices' hull."""
    rng = np.random.default_rng(5)
    for rates, reserve, rows in _polygons():
        count, vertices = _vertices(polygon_vertices, rates, reserve, rows)
        if count <= 0:
            continue
        slack = rates[rows] @ vertices.T + reserve[rows][:, None]
        assert np.all(slack >= -1e-9)
        points = rng.uniform(vertices.min(axis=0) - 1.0, vertices.max(axis=0) + 1.0, (400, 2))
        inside = points[np.all(rates[rows] @ points.T + reserve[rows][:, None] >= 0.0, axis=0)]
        for point in inside:  # a point of the polygon is no farther out than some vertex, along every direction
            for direction in rates[rows]:
                assert direction @ point >= (vertices @ direction).min() - 1e-9


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_c_loops_give_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(polygon_vertices, numba.core.registry.CPUDispatcher)
    for rates, reserve, rows in _polygons():
        count, vertices = _vertices(polygon_vertices, rates, reserve, rows)
        count_c, vertices_c = _vertices(compiled.polygon_vertices, rates, reserve, rows)
        assert count_c == count
        np.testing.assert_array_equal(vertices_c, vertices)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_c_loops_reject_bad_arguments() -> None:
    rates, reserve, rows = np.ones((4, 2)), np.ones(4), np.ones(4, dtype=bool)
    with pytest.raises(ValueError, match="vertices must have a row for every pair"):
        compiled.polygon_vertices(rates, reserve, rows, PARALLEL, SKEW, SLACK, np.empty((5, 2)))
    with pytest.raises(ValueError, match="rates must have 2 dimensions"):
        compiled.polygon_vertices(np.ones((4, 3)), reserve, rows, PARALLEL, SKEW, SLACK, np.empty((6, 2)))
    with pytest.raises(ValueError, match="rows must be a C-contiguous bool"):
        compiled.polygon_vertices(rates, reserve, np.ones(4), PARALLEL, SKEW, SLACK, np.empty((6, 2)))


def _balls() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """``(q0, directions, vertices, seed, spread)``: random planes of twists and polygons on them, without a seed, with
    one far from them, and with one at their middle (the polygon shrunk into its box, or not)."""
    rng = np.random.default_rng(8)
    for count in (1, 3, 7):
        q0 = rng.standard_normal(6)
        directions = np.ascontiguousarray(np.linalg.qr(rng.standard_normal((6, 2)))[0].T)
        for size in (1.0, 1e-9):
            vertices = size * rng.standard_normal((count, 2))
            middle = q0 + vertices.mean(axis=0) @ directions
            for seed in (np.zeros(0), middle + 1.0, middle):
                yield q0, directions, vertices, seed, np.full(6, 1e-10)


def _ball(kernel: Callable[..., float], case: tuple[np.ndarray, ...]) -> tuple[float, np.ndarray]:
    center = np.full(6, np.nan)
    return kernel(*case, patterns.SAME_TWIST, patterns.DISTINCT_TWIST, center), center


def test_the_ball_holds_the_polygons_twists_or_they_are_the_seeds() -> None:
    answers = set()
    for case in _balls():
        q0, directions, vertices, seed, spread = case
        reach, center = _ball(polygon_ball, case)
        twists = q0 + vertices @ directions
        near = bool(seed.size) and np.abs(twists - seed).max() <= 0.5 * patterns.SAME_TWIST
        if reach == NEAR_SEED:
            assert near
        else:
            assert not near
            assert np.linalg.norm(twists - center, axis=1).max() <= reach * (1.0 + 1e-12)
        answers.add(reach == NEAR_SEED)
    assert answers == {True, False}


def test_the_ball_kernel_and_its_numpy_twin_agree() -> None:
    for case in _balls():
        reach, center = _ball(polygon_ball, case)
        reach_twin, center_twin = _ball(kernel_module._polygon_ball_numpy, case)
        assert (reach == NEAR_SEED) == (reach_twin == NEAR_SEED)
        if reach != NEAR_SEED:
            np.testing.assert_allclose(reach, reach_twin, rtol=1e-12, atol=1e-15)
            np.testing.assert_allclose(center, center_twin, rtol=1e-12, atol=1e-15)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_ball_c_loops_give_the_numba_kernels_bits() -> None:
    numba = pytest.importorskip("numba")
    assert isinstance(polygon_ball, numba.core.registry.CPUDispatcher)
    for case in _balls():
        reach, center = _ball(polygon_ball, case)
        reach_c, center_c = _ball(compiled.polygon_ball, case)
        assert reach_c == reach
        if reach != NEAR_SEED:
            np.testing.assert_array_equal(center_c, center)


@pytest.mark.skipif(not compiled.HAVE_KERNELS, reason="built without the C extensions")
def test_the_ball_c_loops_reject_bad_arguments() -> None:
    q0, directions, spread, center = np.zeros(6), np.zeros((2, 6)), np.zeros(6), np.empty(6)
    with pytest.raises(ValueError, match="vertices must hold a vertex"):
        compiled.polygon_ball(q0, directions, np.zeros((0, 2)), np.zeros(0), spread, 1.0, 1.0, center)
    with pytest.raises(ValueError, match="seed must be shaped as q0"):
        compiled.polygon_ball(q0, directions, np.zeros((1, 2)), np.zeros(3), spread, 1.0, 1.0, center)
