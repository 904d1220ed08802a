"""Whole-array twins (what runs without numba) of the frictionless LP's and the audit's kernels.

Each twin must give its compiled kernel's results: the same masks, ranks and
verdicts, residuals to round-off. Without numba the module names are the twins
themselves, so the comparisons need numba to mean anything. With numba the
twins of the LP's analysis call the compiled rank test; the LAPACK singular
values it uses without numba are held to the Jacobi kernel's ranks apart.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

import quasistatic as qs
from quasistatic import compiled
from quasistatic.check import audit
from quasistatic.solvers import lp
from quasistatic.solvers.numerics.lcp import PIVOTS_PER_ROW
from quasistatic.tolerances import FORCE_RANK, MODE_SPEED, MOTION_RANK, PIVOT, ZERO
from quasistatic.tools.bench.families import FAMILIES

numba = pytest.importorskip("numba")


def _rank_deficient(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    rank = int(rng.integers(0, min(rows, cols) + 1))
    if rank == 0:
        return np.zeros((rows, cols))
    return rng.normal(size=(rows, rank)) @ rng.normal(size=(rank, cols))


def _matrices(rng: np.random.Generator) -> Iterator[np.ndarray]:
    """Random matrices of every rank (small to JACOBI_MAX wide), repeated rows, a zero column, and empty ones."""
    for trial in range(300):
        rows, cols = (int(x) for x in rng.integers(1, lp.JACOBI_MAX + 1, size=2))
        A = _rank_deficient(rng, rows, cols) * 10.0 ** rng.uniform(-3, 2)
        if trial % 4 == 0 and rows > 1:
            A[1] = A[0]
        if trial % 7 == 0:
            A[:, 0] = 0.0
        yield A
    yield np.zeros((0, 6))
    yield np.zeros((3, 0))


def test_lapack_singular_values_give_the_jacobi_kernels_ranks() -> None:
    """The same singular values to round-off, so the same rank decision wherever none sits within round-off of the tolerance."""
    rng = np.random.default_rng(5)
    for A in _matrices(rng):
        jacobi = np.sort(lp._singular_values(A) if A.size else np.zeros(0))[::-1]
        lapack = lp._singular_values_numpy(A) if A.size else np.zeros(0)
        scale = max(1.0, float(lapack.max(initial=0.0)))
        np.testing.assert_allclose(lapack, jacobi, rtol=0, atol=1e-13 * scale)
        for tol in (MOTION_RANK, FORCE_RANK):
            if np.any(np.abs(lapack - tol) <= 1e-12 * scale):
                continue  # a value at the threshold: either answer is round-off
            assert np.count_nonzero(lapack > tol) == np.count_nonzero(jacobi > tol)  # what _full_rank decides


def test_lapack_singular_values_do_not_depend_on_the_blas_threads() -> None:
    """Up to JACOBI_MAX columns (any number of rows) one thread and several give the same bits."""
    rng = np.random.default_rng(8)
    for _ in range(40):
        rows, cols = int(rng.integers(1, 400)), int(rng.integers(1, lp.JACOBI_MAX + 1))
        A = rng.normal(size=(rows, cols)) if rng.random() < 0.5 else rng.normal(size=(cols, rows))
        with threadpool_limits(1):
            one = lp._singular_values_numpy(A)
        with threadpool_limits(4):
            several = lp._singular_values_numpy(A)
        np.testing.assert_array_equal(one, several)


def _assert_same_analysis(got: tuple, want: tuple) -> None:
    residual, *masks_and_ranks = want
    assert got[0] == pytest.approx(residual, rel=1e-12, abs=1e-14)
    np.testing.assert_allclose(got[1], masks_and_ranks[0], rtol=1e-13, atol=1e-14)  # slacks
    for a, b in zip(got[2:5], masks_and_ranks[1:4], strict=True):
        np.testing.assert_array_equal(a, b)
    assert got[5:] == tuple(masks_and_ranks[4:])


def _pairs(rng: np.random.Generator) -> Iterator[tuple[np.ndarray, ...]]:
    """Primal-dual pairs: exactly complementary ones on rank-deficient normals (ties at zero slack and zero force),
    perturbed ones, and ones with more closed contacts than twist entries."""
    for trial in range(200):
        m, n = int(rng.integers(1, 14)), int(rng.integers(1, 8))
        Jn = _rank_deficient(rng, m, n) if trial % 2 else rng.normal(size=(m, n))
        q = rng.normal(size=n)
        state = rng.integers(0, 3, size=m)  # 0: open, 1: closed and loaded, 2: closed, unloaded
        slack = np.where(state == 0, rng.uniform(0.1, 1.0, m), 0.0)
        forces = np.where(state == 1, rng.uniform(0.1, 1.0, m), 0.0)
        bn = Jn @ q - slack
        g = -Jn.T @ forces
        if trial % 3 == 0:
            forces = forces + rng.normal(scale=1e-3, size=m)
        yield Jn, bn, g, q, forces


def test_analysis_twin_equals_the_kernel() -> None:
    rng = np.random.default_rng(13)
    for Jn, bn, g, q, forces in _pairs(rng):
        args = (Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        _assert_same_analysis(lp._analyse_numpy(*args), lp._analyse(*args))


def test_analysis_twin_of_a_non_finite_pair_or_no_contacts() -> None:
    """Not finite: infinite residual and no rank claimed; no contacts: nothing closed, forces unique."""
    Jn, bn, g = np.eye(3), np.zeros(3), np.zeros(3)
    for q, forces in ((np.array([np.nan, 0.0, 0.0]), np.zeros(3)), (np.zeros(3), np.array([0.0, np.inf, 0.0]))):
        got = lp._analyse_numpy(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        assert got[0] == np.inf and got[5:] == (0, 0)
        _assert_same_analysis(got, lp._analyse(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK))
    empty = (np.zeros((0, 3)), np.zeros(0), np.array([0.0, 0.0, -1.0]), np.zeros(3), np.zeros(0), ZERO, MOTION_RANK, FORCE_RANK)
    got = lp._analyse_numpy(*empty)
    assert got[0] == 1.0 and got[6] == 1
    _assert_same_analysis(got, lp._analyse(*empty))


@pytest.mark.parametrize("family", ["grasp-2d-nf", "grasp-3d-nf", "box-push-nf", "pile-nf"])
def test_lemke_pair_twin_equals_the_kernel_on_bench_scenes(family: str) -> None:
    """Lemke's pair and its analysis on the frictionless bench families, as the frictionless default runs them: the
    kernel's body as plain Python (what runs without numba) against the kernel."""
    plain = getattr(lp._lemke_pair, "py_func", lp._lemke_pair)
    make = FAMILIES[family].make
    for size in FAMILIES[family].quick_sizes[:2]:
        for instance in range(2):
            data = lp._Frictionless(qs.assemble(make(size, instance)))
            args = (data.J, data.b, data.mu, data.g, data.frictional, data.base, data.Jn, data.bn)
            tolerances = (MODE_SPEED, PIVOT, PIVOTS_PER_ROW, ZERO, MOTION_RANK, FORCE_RANK)
            status, q, c, analysis = plain(*args, *tolerances)
            want = lp._lemke_pair(*args, *tolerances)
            assert status == want[0]
            np.testing.assert_allclose(q, want[1], rtol=1e-12, atol=1e-14)
            np.testing.assert_allclose(c, want[2], rtol=1e-12, atol=1e-14)
            assert c.min(initial=0.0) >= 0.0
            _assert_same_analysis(analysis, want[3])
            if compiled.HAVE_KERNELS:  # the C analysis (what runs without numba) on the kernel's pair: the kernel's bits
                pair = (data.Jn, data.bn, data.g, want[1], want[2][:, -1].copy(), ZERO, MOTION_RANK, FORCE_RANK)
                for got, kernel in zip(lp._analyse_compiled(*pair), lp._analyse(*pair), strict=True):
                    np.testing.assert_array_equal(got, kernel)


# --------------------------------------------------------------------------- the audit's kernel


def _audit_scenes() -> Iterator[qs.Scene]:
    """Planar and spatial scenes: mover contacts, contacts between free bodies (the pile), exact cones and pyramids."""
    for family, size in (("grasp-2d", 4), ("pile", 10), ("grasp-3d", 6), ("box-push", 16)):
        yield FAMILIES[family].make(size, 1)
    from quasistatic.tools.bench.families import grasp_3d

    yield grasp_3d(6, 1, friction="pyramid:4")


def _kernel_of(scene: qs.Scene) -> Callable[..., tuple[np.ndarray, ...]]:
    return audit._laws_2d if scene.dimension == 2 else audit._laws_3d


def _assert_same_evaluation(got: tuple[np.ndarray, ...], want: tuple[np.ndarray, ...]) -> None:
    scale = max(1.0, *(float(np.max(np.abs(w), initial=0.0)) for w in want))
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-13 * scale)


def test_audit_twin_equals_the_kernel() -> None:
    """Random twists and forces (some contacts sliding past the slide speed, some still), and the rest twist."""
    rng = np.random.default_rng(17)
    for scene in _audit_scenes():
        geometry = audit.AuditGeometry.of(scene)
        links, contacts, loads, facets, directions = geometry.arrays
        k = 3 if scene.dimension == 2 else 6
        for trial in range(6):
            T = rng.normal(size=(len(scene.bodies), k)) if trial else np.zeros((len(scene.bodies), k))
            forces = rng.normal(size=(len(scene.contacts), scene.dimension))
            forces[::3] = 0.0
            args = (links, contacts, loads, T, forces, facets, directions, geometry.facet_scale, 0.5)
            _assert_same_evaluation(audit._laws_numpy(*args), _kernel_of(scene)(*args))


def test_audit_twin_without_contacts_and_on_values_that_are_not_finite() -> None:
    """No contacts: only the loads' balance; a NaN force or an infinite twist: a check sum that is not finite."""
    scene = next(_audit_scenes())
    links, contacts, loads, facets, directions = audit.AuditGeometry.of(scene).arrays
    T = np.array([[0.1, -0.2, 0.3]])
    none = (links[:0], contacts[:0], loads, T, np.zeros((0, 2)), facets, directions, 1.0, 0.5)
    _assert_same_evaluation(audit._laws_numpy(*none), audit._laws_2d(*none))
    for bad_twist, bad_force in ((np.inf, 0.0), (0.0, np.nan)):
        forces = np.ones((len(links), 2))
        forces[1, 0] += bad_force
        got = audit._laws_numpy(links, contacts, loads, T + bad_twist, forces, facets, directions, 1.0, 0.5)
        assert not np.isfinite(got[0][audit._CHECK])


def test_many_contacts_are_audited_by_the_twin_without_numba(monkeypatch: pytest.MonkeyPatch) -> None:
    """Past ``LOOP_CONTACTS`` contacts the audit without numba runs the twin: the same verdict and residuals."""
    problem = qs.assemble(FAMILIES["box-push-nf"].make(64, 0))
    assert problem.n_contacts > audit.LOOP_CONTACTS
    solution = qs.solve(problem, method="lp")
    geometry = audit.AuditGeometry.of(problem.scene)
    twists = np.array([solution.twists[name] for name in geometry.names])
    forces = np.array([contact.force for contact in solution.contacts])
    want = audit.audit_arrays(geometry, twists, forces, problem.scales)
    monkeypatch.setattr(audit, "HAVE_NUMBA", False)
    monkeypatch.setattr(audit, "HAVE_KERNELS", False)  # an install without a C compiler
    got = audit.audit_arrays(geometry, twists, forces, problem.scales)
    assert got[0].passed and want[0].passed
    for field in ("equilibrium", "cone", "complementarity", "dissipation", "power"):
        assert getattr(got[0], field) == pytest.approx(getattr(want[0], field), rel=1e-9, abs=1e-15)
    _assert_same_evaluation((got[2].velocities, got[2].slips, got[2].normal), (want[2].velocities, want[2].slips, want[2].normal))


@pytest.mark.parametrize("twin", ["numpy", "C"])
def test_roundoff_twin_equals_the_kernel(twin: str) -> None:
    """Entries within their column's round-off of zero set to 0 in place, others (NaN included) kept: the numpy twin,
    and the C extension's loop (``compiled.drop_roundoff``, what runs without numba where it was built)."""
    from quasistatic.check import motion

    if twin == "C" and not compiled.HAVE_KERNELS:
        pytest.skip("built without the C extensions")
    drop = motion._drop_roundoff_numpy if twin == "numpy" else compiled.drop_roundoff

    rng = np.random.default_rng(19)
    for rows, cols in ((0, 3), (1, 3), (7, 2), (40, 6)):
        values = rng.normal(size=(rows, cols)) * 10.0 ** rng.integers(-14, 1, size=(rows, cols))
        if rows:
            values[0, 0] = np.nan
        roundoff = np.full(cols, 1e-9)
        roundoff[0] = 0.0  # exact zeros only
        want = motion._drop_roundoff(values.copy(), roundoff)
        copy = values.copy()
        got = drop(copy, roundoff)
        assert got is copy
        np.testing.assert_array_equal(got, want)
