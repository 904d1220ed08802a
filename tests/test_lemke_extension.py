"""The compiled extension ``quasistatic._lemke``: Lemke's method in C, pivot for pivot the numba kernel's.

It runs wherever it was built: called from Python where numba is missing (the
default install), and from compiled kernels through its plain C entry point where
numba is installed. So it must make the kernel's choices exactly: the same status,
pivot count and final basis, and the same point to round-off, on well-posed,
degenerate (many ties), ray-ending and pivot-limited LCPs, and on the LCPs of the
benchmark scenes, by either door. The reference is numba's own kernel when numba
is installed, else the numpy twin (itself checked against the kernel in ``test_fast.py``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from quasistatic import compiled
from quasistatic.jit import HAVE_NUMBA
from quasistatic.laws import fixed_modes
from quasistatic.solvers.numerics import lcp
from quasistatic.solvers.numerics import lemke as lemke_module
from quasistatic.solvers.numerics.lemke import PIVOT_LIMIT, RAY, SOLUTION, lemke
from quasistatic.tools.bench.families import FAMILIES

TOL = 1e-11
NO_EXTENSION = "QUASISTATIC_NO_EXTENSION"  # set to 1 where an install without a C compiler is intended

needs_extension = pytest.mark.skipif(not compiled.HAVE_EXTENSION, reason=f"built without the C extension ({NO_EXTENSION} set)")
REFERENCE: Callable[..., Any] = lemke_module.numba_lemke if HAVE_NUMBA else lemke_module._lemke_numpy
# The extension's two doors: its Python function, and (numba installed) its C entry point called by compiled ``lemke``.
DOORS = [pytest.param(compiled.lemke, id="python-api")]
if HAVE_NUMBA:
    DOORS.append(pytest.param(lemke, id="from-numba"))


def test_the_extension_was_built() -> None:
    """``pip install .`` builds ``quasistatic._lemke`` wherever a C compiler and the Python headers exist.

    The build is optional (a machine without a compiler still installs, and runs
    the slower numpy twin), so a broken build would pass silently; this test makes
    it loud. It requires the extension unless the environment variable
    ``QUASISTATIC_NO_EXTENSION=1`` says a compiler-less install is intended.
    """
    if os.environ.get(NO_EXTENSION) == "1":
        pytest.skip(f"{NO_EXTENSION}=1: an install without the C extension is intended")
    assert compiled.HAVE_EXTENSION, "quasistatic._lemke did not build: is there a C compiler and the Python headers?"


def test_an_extension_built_from_an_older_source_is_not_used() -> None:
    """An editable install keeps the .so of an older ``_lemke.c`` until rebuilt: it is left unused, with a warning.

    In a fresh interpreter: reloading ``compiled`` here would give the other modules' imported wrappers new twins.
    """
    code = (
        "import sys, types, warnings; sys.modules['quasistatic._lemke'] = types.ModuleType('quasistatic._lemke')\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always'); from quasistatic import compiled\n"
        "print(compiled.HAVE_EXTENSION, compiled.LEMKE_ADDRESS, [str(w.message) for w in caught])"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert run.stdout.startswith("False 0 [") and "built from an older source" in run.stdout, run.stdout + run.stderr


def _same_run(got: tuple, want: tuple) -> None:
    """The same status, pivots and basis, and the same point to round-off."""
    assert (int(got[0]), int(got[2])) == (int(want[0]), int(want[2]))
    np.testing.assert_array_equal(got[3], want[3])
    np.testing.assert_allclose(got[1], want[1], rtol=1e-9, atol=1e-12)


def _random_lcps(rng: np.random.Generator, count: int) -> Iterator[tuple[str, np.ndarray, np.ndarray]]:
    """LCPs of every kind Lemke meets: positive definite, copositive, general, and degenerate integer ones with many ties."""
    for trial in range(count):
        n = int(rng.integers(0, 16))
        A = rng.normal(size=(n, n))
        kind = ("definite", "copositive", "general", "degenerate")[trial % 4]
        if kind == "definite":
            M, q = A @ A.T + 0.1 * np.eye(n), rng.normal(size=n)
        elif kind == "copositive":
            M, q = np.abs(A) * (rng.random((n, n)) < 0.5), rng.normal(size=n)
        elif kind == "general":
            M, q = A, rng.normal(size=n)
        else:  # small integers: equal ratios and equal rows of B^-1 at many pivots
            M = np.round(A)
            q = np.round(rng.normal(size=n)) * (rng.random(n) < 0.5) - (rng.random(n) < 0.3)
        yield kind, M, q


@needs_extension
@pytest.mark.parametrize("door", DOORS)
def test_the_extension_pivots_as_the_kernel_on_random_lcps(door: Callable[..., Any]) -> None:
    rng = np.random.default_rng(3)
    seen: set[int] = set()
    for _, M, q in _random_lcps(rng, 400):
        d = np.ones(q.shape[0])
        for max_pivots, free in ((1000, 0), (3, 0), (1000, q.shape[0] // 2)):  # free: z[:free] never leave once basic
            want = REFERENCE(M, q, d, max_pivots, TOL, free)
            _same_run(door(M, q, d, max_pivots, TOL, free), want)
            seen.add(int(want[0]))
    assert seen == {SOLUTION, RAY, PIVOT_LIMIT}  # every ending was met


@needs_extension
@pytest.mark.parametrize("door", DOORS)
@pytest.mark.parametrize("n", [0, 1])
def test_the_extension_on_the_smallest_lcps(n: int, door: Callable[..., Any]) -> None:
    for q in ([], [2.0]) if n == 0 else ([-2.0], [2.0], [0.0]):
        for M in (np.full((n, n), 3.0), np.full((n, n), -1.0)):
            args = (M, np.array(q[:n], float), np.full(n, 0.5), 10, TOL, n)
            _same_run(door(*args), REFERENCE(*args))


def test_the_numpy_twins_tie_break_is_the_kernels() -> None:
    """The whole-array tie-break (installs without a compiler) keeps the kernel's column loop's row among tied rows."""
    rng = np.random.default_rng(5)
    ties = 0
    for trial in range(150):
        n = int(rng.integers(2, 12))
        # small integers (many equal values, so later columns decide) or the identity (the first pivot's ties)
        Binv = np.eye(n) if trial % 3 == 0 else np.round(rng.normal(size=(n, n)))
        col = rng.integers(1, 3, n).astype(float)
        rows = np.flatnonzero(rng.random(n) < 0.7)
        if rows.size < 2:
            continue
        ties += 1
        xB = np.where(np.isin(np.arange(n), rows), 0.0, 1.0)  # the rows tie at ratio 0, the others are above it
        want = lemke_module._ratio_test(Binv, xB, col, np.zeros(n, np.int64), 2 * n, TOL, 0)
        assert lemke_module._tie_break_numpy(Binv, col, rows, TOL) == want
    assert ties > 100


def _bench_lcps() -> Iterator[tuple[str, np.ndarray, np.ndarray, int]]:
    """The split-twist LCPs of the benchmark rows where Lemke's method dominates the time, and their twist halves' count."""
    rows = [("grasp-2d", 2), ("grasp-2d", 4), ("grasp-2d", 8), ("grasp-3d", 4), ("grasp-2d-nf", 8)]
    rows += [("box-push-nf", 4), ("box-push-nf", 16), ("box-push-nf", 64), ("pile-nf", 10)]
    for family, size in rows:
        for instance in range(2):
            data = qs.assemble(FAMILIES[family].make(size, instance)).derived("fast", lcp.LemkeInputs)
            Jn, bn, Jt, bt, mu_f = lcp._split_rows(data.J, data.b, data.mu, data.frictional)
            edges = lcp._edges(data.base, np.zeros(data.frictional.shape[0]), data.J.shape[1] - 1)
            M, q = lcp._assemble(Jn, Jt, bn, bt, mu_f, data.g, edges, data.frictional)
            yield f"{family} {size} #{instance}", M, q, 2 * data.J.shape[2]


@needs_extension
@pytest.mark.parametrize("door", DOORS)
def test_the_extension_pivots_as_the_kernel_on_the_bench_lcps(door: Callable[..., Any]) -> None:
    for name, M, q, twist_halves in _bench_lcps():
        d = np.ones(q.shape[0])
        cap = lcp.PIVOTS_PER_ROW * q.shape[0]
        for free in (0, twist_halves):  # the textbook path, and the fast path's (the twist free)
            got, want = door(M, q, d, cap, TOL, free), REFERENCE(M, q, d, cap, TOL, free)
            assert int(want[2]) > 0, name  # Lemke pivots on every one
            _same_run(got, want)


@needs_extension
@pytest.mark.parametrize(
    ("M", "q", "d", "message"),
    [
        (np.zeros((3, 2)), -np.ones(3), np.ones(3), r"M must have shape \(3, 3\)"),
        (np.zeros(9), -np.ones(3), np.ones(3), r"M must have shape \(3, 3\)"),
        (np.zeros((3, 3)), -np.ones(3), np.ones(2), r"d must have shape \(3,\)"),
        (np.zeros((3, 3)), -np.ones((3, 1)), np.ones(3), "q must be one-dimensional"),
    ],
)
def test_bad_shapes_raise(M: np.ndarray, q: np.ndarray, d: np.ndarray, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        compiled.lemke(M, q, d, 10, TOL, 0)


@pytest.mark.skipif(not HAVE_NUMBA, reason="the compiled door needs numba")
@pytest.mark.parametrize(("M", "d"), [(np.zeros((3, 2)), np.ones(3)), (np.zeros((2, 3)), np.ones(3)), (np.zeros((3, 3)), np.ones(2))])
def test_bad_shapes_raise_through_the_compiled_door(M: np.ndarray, d: np.ndarray) -> None:
    """The C entry point trusts its sizes: the compiled ``lemke`` checks them first (never an out-of-bounds read)."""
    with pytest.raises(ValueError, match=r"M must be \(n, n\) and d \(n,\)"):
        lemke(M, -np.ones(3), d, 10, TOL, 0)


@needs_extension
def test_bad_output_buffers_raise() -> None:
    """The raw entry point checks the buffers it fills: their length, type and layout."""
    from quasistatic import _lemke  # type: ignore[attr-defined]

    M, q, d = np.eye(3), -np.ones(3), np.ones(3)
    with pytest.raises(ValueError, match=r"z must have shape \(3,\)"):
        _lemke.lemke(M, q, d, 10, TOL, 0, np.empty(2), np.empty(3, np.int64))
    with pytest.raises(ValueError, match="basis must be a C-contiguous int64"):
        _lemke.lemke(M, q, d, 10, TOL, 0, np.empty(3), np.empty(3, np.int32))
    with pytest.raises(ValueError):
        _lemke.lemke(M, q, d, 10, TOL, 0, np.empty(3), np.empty(6, np.int64)[::2])
    with pytest.raises(ValueError):
        _lemke.lemke(M, q, d, 10, TOL, 0, np.empty(3)[::-1], np.empty(3, np.int64))
    frozen = np.empty(3)
    frozen.flags.writeable = False
    with pytest.raises(ValueError):
        _lemke.lemke(M, q, d, 10, TOL, 0, frozen, np.empty(3, np.int64))
    with pytest.raises(TypeError):
        _lemke.lemke(M, q, d, 10, TOL, 0, np.empty(3))


@needs_extension
@pytest.mark.parametrize("door", DOORS)
@pytest.mark.parametrize("where", ["M", "q", "d", "all"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_nan_and_inf_end_within_the_pivot_limit(where: str, value: float, door: Callable[..., Any]) -> None:
    """Non-finite data give a meaningless but bounded run (callers audit every answer): no crash, no endless loop."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(6, 6))
    M, q, d = A @ A.T, -np.ones(6), np.ones(6)
    if where in ("M", "all"):
        M[rng.random((6, 6)) < 0.3] = value
    if where in ("q", "all"):
        q[1] = value
    if where in ("d", "all"):
        d[2] = value
    status, z, pivots, basis = door(M, q, d, 40, TOL, 0)
    assert status in (SOLUTION, RAY, PIVOT_LIMIT) and 0 <= pivots <= 40
    assert z.shape == (6,) and set(basis.tolist()) <= set(range(13))  # w, z or z0 in every row


def test_without_numba_the_default_install_runs_the_extension() -> None:
    """With numba unimportable, ``lemke`` is the extension's wrapper (or, without it, the numpy twin) and solves."""
    code = textwrap.dedent(
        """
        import sys
        sys.modules["numba"] = None
        import numpy as np
        from quasistatic import compiled
        from quasistatic.solvers.numerics import lemke as module
        expected = compiled.lemke if compiled.HAVE_EXTENSION else module._lemke_numpy
        assert module.lemke is expected, module.lemke
        status, z, pivots, _ = module.lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]), np.ones(2), 10, 1e-11, 0)
        assert status == module.SOLUTION and np.allclose(z, [4 / 3, 7 / 3])
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba's kernels only")
def test_with_numba_but_no_extension_the_kernels_call_numbas_lemke() -> None:
    """numba installed, the extension not built: compiled callers reach numba's own kernel through the same C name.

    The kernels cached on disk by this session's processes (which call the extension) are loaded here with the
    extension gone: the name must still be bound (to numba's kernel as a ``cfunc``), or loading them would crash.
    """
    code = textwrap.dedent(
        """
        import sys
        sys.modules["quasistatic._lemke"] = None  # as if no C compiler had built it
        import numpy as np
        import quasistatic as qs
        from quasistatic import compiled
        from quasistatic.solvers.numerics import lemke as module
        from quasistatic.tools.bench.families import grasp_2d
        assert not compiled.HAVE_EXTENSION
        rng = np.random.default_rng(1)
        for n in (0, 3, 12):
            A = rng.normal(size=(n, n))
            args = (A @ A.T + np.eye(n), rng.normal(size=n), np.ones(n), 100, 1e-11, 0)
            got, want = module.lemke(*args), module.numba_lemke(*args)
            assert (got[0], got[2]) == (want[0], want[2]) and (got[3] == want[3]).all() and (got[1] == want[1]).all()
        assert qs.solve(qs.assemble(grasp_2d(4, 0)), method="fast").status == "solved"
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# --------------------------------------------------------------------------- the fixed-mode laws in C


def _laws_cases() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]]:
    """Bench scenes (2-D and 3-D, frictional and frictionless contacts) at random modes and random unknowns."""
    rng = np.random.default_rng(8)
    for family, size in (("grasp-2d", 4), ("grasp-3d", 4), ("grasp-3d", 8), ("box-push", 4), ("box-push-nf", 4)):
        data = qs.assemble(FAMILIES[family].make(size, 0)).derived("fast", lcp.LemkeInputs)
        m, d, n = data.J.shape
        for trial in range(8):
            kind = rng.integers(0, 3, m).astype(np.int64)  # separating, rolling and sliding mixed
            if trial == 0:
                kind[:] = fixed_modes.SLIDING
            column, unknowns = fixed_modes.columns(kind, n, d - 1)
            x = rng.normal(size=unknowns)
            if trial == 1:
                x[:n] = np.linalg.lstsq(data.J[:, :-1].reshape(-1, n), data.b[:, :-1].ravel(), rcond=None)[0]  # slips near zero
            yield data.J, data.b, data.mu, data.g, x, kind, column, n


@needs_extension
def test_the_extensions_fixed_mode_laws_are_the_kernels() -> None:
    """Residual, Jacobian and forces as the kernel gives them (the same loops: equal to round-off, in practice to the bit)."""
    reference = fixed_modes.system if HAVE_NUMBA else fixed_modes._system_numpy
    for case in _laws_cases():
        for got, want in zip(compiled.fixed_mode_system(*case), reference(*case), strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-14)


@needs_extension
def test_the_extensions_fixed_mode_laws_check_their_arrays() -> None:
    J, b, mu, g, x, kind, column, n = next(_laws_cases())
    with pytest.raises(ValueError, match="J must have shape"):
        compiled.fixed_mode_system(J[0], b, mu, g, x, kind, column, n)
    with pytest.raises(ValueError, match=r"b must have shape"):
        compiled.fixed_mode_system(J, b[:-1], mu, g, x, kind, column, n)
    with pytest.raises(ValueError, match="J must have shape"):
        compiled.fixed_mode_system(J, b, mu, g, x, kind, column, n + 1)
    with pytest.raises(ValueError, match="outside x"):
        compiled.fixed_mode_system(J, b, mu, g, x[: n + 1], np.full_like(kind, fixed_modes.ROLLING), column, n)
    with pytest.raises(ValueError, match="is not 0, 1 or 2"):
        compiled.fixed_mode_system(J, b, mu, g, x, np.full_like(kind, 7), column, n)


# --------------------------------------------------------------------------- the fast path's whole kernel in C


def _split_lcp_cases() -> Iterator[tuple[str, lcp.LemkeInputs]]:
    """The fast kernel's inputs on the bench families (2-D, 3-D exact and pyramid cones, frictionless) and random 3-D scenes.

    Among them every ending of the kernel: Lemke's first motion, a ray, Newton's method (first, and after a
    re-alignment: random #28), a ray after re-alignment (grasp-3d 5 #2), and re-alignment run to its limit
    without converging (grasp-3d 5 #4, random #287).
    """
    from random_scenes import random_scene

    rows = [("grasp-2d", 2), ("grasp-2d", 4), ("grasp-2d", 8), ("grasp-3d", 4), ("grasp-3d", 6), ("grasp-3d", 8)]
    rows += [("grasp-2d-nf", 8), ("box-push", 4), ("box-push-nf", 16), ("pile-nf", 10)]
    cases = [(family, size, instance) for family, size in rows for instance in range(3)] + [("grasp-3d", 5, 2), ("grasp-3d", 5, 4)]
    for family, size, instance in cases:
        yield f"{family} {size} #{instance}", qs.assemble(FAMILIES[family].make(size, instance)).derived("fast", lcp.LemkeInputs)
    for seed in [*range(30), 28, 287]:
        friction = "exact" if seed % 3 else "pyramid:4"
        yield f"random 3-D #{seed} {friction}", qs.assemble(random_scene(3, seed, friction)).derived("fast", lcp.LemkeInputs)


def _kernel_arguments(data: lcp.LemkeInputs, short_path: bool = True) -> tuple[Any, ...]:
    """The kernel's arguments: the fast path's (the twist free, :data:`lcp.GAP_COVERING`), or the textbook path's."""
    tolerances = (lcp.FRICTION_ALIGNMENT, lcp.MODE_SPEED, lcp.PIVOT, lcp.BASIS_FEASIBILITY, lcp.PIVOTS_PER_ROW)
    path = (True, lcp.GAP_COVERING) if short_path else (False, 1.0)
    return (data.J, data.b, data.mu, data.g, data.frictional, data.base, data.exact, *path, lcp.REALIGNMENTS, *tolerances)


@needs_extension
@pytest.mark.skipif(not HAVE_NUMBA, reason="the reference is the numba kernel")
def test_the_extensions_split_lcp_kernel_is_the_numba_kernels() -> None:
    """The same status, stage, pivots and re-alignments, and the same motion to 1e-9 relative, on every case; every stage met."""
    stages: dict[bool, set[tuple[int, int]]] = {False: set(), True: set()}
    for name, data in _split_lcp_cases():
        for short_path in (False, True):  # the textbook path (the LP's, the certified candidate's) and the fast path's
            arguments = _kernel_arguments(data, short_path)
            got, want = lcp._solve_split_lcp_compiled(*arguments), lcp.solve_split_lcp(*arguments)
            assert [int(v) for v in (got[0], got[1], got[4], got[5])] == [int(v) for v in (want[0], want[1], want[4], want[5])], name
            for g, w in ((got[2], want[2]), (got[3], want[3])):
                np.testing.assert_allclose(g, w, rtol=1e-9, atol=1e-9 * max(1.0, float(np.abs(w).max(initial=0.0))), err_msg=name)
            stages[short_path].add((int(want[0]), int(want[1])))
    for short_path, met in stages.items():
        assert {(SOLUTION, 0), (SOLUTION, 2), (RAY, 0), (RAY, 1), (lcp.NOT_CONVERGED, 2)} <= met, (short_path, met)


@needs_extension
def test_the_extensions_split_lcp_kernel_checks_its_arrays() -> None:
    data = qs.assemble(FAMILIES["grasp-3d"].make(4, 0)).derived("fast", lcp.LemkeInputs)
    arguments = list(_kernel_arguments(data))
    bad = {
        0: (data.J[0], "J must have shape"),
        1: (data.b[:-1], r"b must have shape"),
        3: (data.g[:-1], r"g must have shape"),
        4: (np.array([0, 99]), "is not a contact index"),
        5: (data.base[None], "frictional and base must be one-dimensional"),
    }
    for index, (value, message) in bad.items():
        with pytest.raises(ValueError, match=message):
            lcp._solve_split_lcp_compiled(*arguments[:index], value, *arguments[index + 1 :])
    planar = qs.assemble(FAMILIES["grasp-2d"].make(4, 0)).derived("fast", lcp.LemkeInputs)
    with pytest.raises(ValueError, match="exact cones need 3-D contacts"):
        lcp._solve_split_lcp_compiled(*_kernel_arguments(planar)[:6], True, *_kernel_arguments(planar)[7:])  # exact in 2-D


# --------------------------------------------------------------------------- Newton's method on the exact cones alone, in C


def _newton_starts() -> Iterator[tuple[str, lcp.LemkeInputs, np.ndarray, np.ndarray]]:
    """Starts of Newton's method on the exact 3-D cases: where the fast kernel ended (a ray's last point, or its
    motion), grasp-3d 6 #3's, 8 #0's and 8 #1's rays (from which Newton converges, 8 #0 with the ray's depth, 8 #1
    with quick mode switches too), and random points (from which it mostly fails)."""
    rng = np.random.default_rng(11)
    rays = [
        (f"grasp-3d {size} #{i}", qs.assemble(FAMILIES["grasp-3d"].make(size, i)).derived("fast", lcp.LemkeInputs))
        for size, i in ((6, 3), (8, 0), (8, 1))
    ]
    for name, data in [*_split_lcp_cases(), *rays]:
        if not data.exact:
            continue
        q, c = lcp.solve_split_lcp(*_kernel_arguments(data))[2:4]
        yield name, data, q, c
        yield f"{name}, a random start", data, rng.normal(size=q.shape), np.abs(rng.normal(size=c.shape))


@needs_extension
@pytest.mark.skipif(not HAVE_NUMBA, reason="the reference is the numba kernel")
def test_the_extensions_newton_is_the_numba_kernels() -> None:
    """The same verdict and the same point to 1e-9 relative (the same loops: in practice to the bit), converged or not,
    with every contact that must switch switched after a round, or only the first."""
    verdicts = set()
    for name, data, q, c in _newton_starts():
        depth = max(0.0, -float((data.J[:, 2] @ q - data.b[:, 2]).min()))  # the penetration Lemke's point allows (a ray's)
        every_switch = ((0.0, lcp.NEWTON_ITERATIONS, False), (depth, lcp.NEWTON_ITERATIONS, False), (depth, lcp.QUICK_PATIENCE, False))
        for start_depth, patience, one_switch in (*every_switch, (0.0, lcp.QUICK_PATIENCE, True), (depth, lcp.NEWTON_ITERATIONS, True)):
            arguments = (data.J, data.b, data.mu, data.g, q, c, start_depth, patience, one_switch, lcp.MODE_SPEED, lcp.FRICTION_ALIGNMENT)
            got, want = lcp._newton_compiled(*arguments), lcp._newton(*arguments)
            assert got[0] == want[0], name
            for g, w in ((got[1], want[1]), (got[2], want[2])):
                np.testing.assert_allclose(g, w, rtol=1e-9, atol=1e-9 * max(1.0, float(np.abs(w).max(initial=0.0))), err_msg=name)
            verdicts.add(bool(want[0]))
    assert verdicts == {True, False}


@needs_extension
def test_exact_newton_runs_the_extensions_newton(monkeypatch: pytest.MonkeyPatch) -> None:
    """With the extension built (numba or not), the fast path's Newton starts outside the kernel run its C."""
    calls: list[int] = []
    c_newton = lcp._newton_compiled
    monkeypatch.setattr(lcp, "_newton_compiled", lambda *arguments: calls.append(1) or c_newton(*arguments))
    problem = qs.assemble(FAMILIES["grasp-3d"].make(6, 3))
    status, _, q, c, _, _ = lcp.lemke_motion(problem)
    assert status == RAY and lcp.exact_newton(problem, q, c)[0] and calls == [1]


@needs_extension
def test_the_extensions_newton_checks_its_arrays() -> None:
    data = qs.assemble(FAMILIES["grasp-3d"].make(4, 0)).derived("fast", lcp.LemkeInputs)
    q, c = np.zeros(data.J.shape[2]), np.zeros(data.J.shape[:2])
    tolerances = (0.0, lcp.NEWTON_ITERATIONS, False, lcp.MODE_SPEED, lcp.FRICTION_ALIGNMENT)
    with pytest.raises(ValueError, match=r"J must have shape \(m, 3, n\)"):
        lcp._newton_compiled(data.J[:, 1:], data.b[:, 1:], data.mu, data.g, q, c[:, 1:], *tolerances)
    with pytest.raises(ValueError, match="b must have shape"):
        lcp._newton_compiled(data.J, data.b[:-1], data.mu, data.g, q, c, *tolerances)
    with pytest.raises(ValueError, match="c must have shape"):
        lcp._newton_compiled(data.J, data.b, data.mu, data.g, q, c[:-1], *tolerances)


@needs_extension
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_the_extensions_split_lcp_kernel_ends_on_non_finite_data(value: float) -> None:
    """NaN or inf in the laws: a bounded run with some status (the caller audits every answer), never a hang or a crash."""
    data = qs.assemble(FAMILIES["grasp-3d"].make(4, 0)).derived("fast", lcp.LemkeInputs)
    for field in ("J", "b", "g", "mu"):
        arguments = list(_kernel_arguments(data))
        index = ("J", "b", "mu", "g").index(field)
        spoiled = arguments[index].copy()
        spoiled.flat[1] = value
        arguments[index] = spoiled
        status, stage, q, c, pivots, realignments = lcp._solve_split_lcp_compiled(*arguments)
        assert status in (SOLUTION, RAY, PIVOT_LIMIT, lcp.NOT_CONVERGED) and 0 <= realignments <= lcp.REALIGNMENTS
        assert q.shape == (data.J.shape[2],) and c.shape == data.J.shape[:2]
