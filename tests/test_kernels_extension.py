"""The compiled extension ``quasistatic._kernels``: the audit's laws and the frictionless LP's analysis in C.

Both run wherever numba is missing (the default install), in place of the numba
kernels ``check/audit.py::_laws_2d`` / ``_laws_3d`` and ``solvers/lp.py::_analyse``.
They do the kernels' arithmetic in the kernels' order, so on this machine's
compiler and numba they give the same bits; the tests hold them to that (and the
rank verdicts, masks and statuses exactly) on random and bench-family inputs,
with no contacts, separating, sliding and still contacts, pyramids, NaN and inf,
and check that bad shapes, dtypes, buffers and links raise ``ValueError``. The
reference is the compiled numba kernel, so these tests need numba.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
import test_contract
import test_fast
from quasistatic import compiled
from quasistatic.check import audit
from quasistatic.solvers import lp
from quasistatic.tolerances import FORCE_RANK, JACOBI_ORTHOGONAL, MODE_SPEED, MOTION_RANK, ZERO
from quasistatic.tools.bench.families import FAMILIES, grasp_3d
from random_scenes import random_scene

ROOT = Path(__file__).resolve().parents[1]
NO_EXTENSION = "QUASISTATIC_NO_EXTENSION"  # set to 1 where an install without a C compiler is intended

needs_kernels = pytest.mark.skipif(not compiled.HAVE_KERNELS, reason=f"built without the C extensions ({NO_EXTENSION} set)")


def test_the_kernels_extension_was_built() -> None:
    """``pip install .`` builds ``quasistatic._kernels`` wherever it builds ``quasistatic._lemke``; a silent failure fails here."""
    if os.environ.get(NO_EXTENSION) == "1":
        pytest.skip(f"{NO_EXTENSION}=1: an install without the C extensions is intended")
    assert compiled.HAVE_KERNELS, "quasistatic._kernels did not build: is there a C compiler and the Python headers?"


# --------------------------------------------------------------------------- the audit's laws


def _scenes() -> Iterator[qs.Scene]:
    """Planar and spatial scenes: mover contacts, contacts between free bodies (the piles), exact cones, pyramids, none."""
    for family, size in (("grasp-2d", 4), ("grasp-2d-nf", 8), ("pile", 10), ("grasp-3d", 6), ("grasp-3d-nf", 8), ("box-push", 16)):
        yield FAMILIES[family].make(size, 1)
    yield FAMILIES["pile-nf"].make(10, 0)
    yield grasp_3d(6, 1, friction="pyramid:4")


def _kernel(dimension: int) -> Callable[..., tuple[np.ndarray, ...]]:
    numba = pytest.importorskip("numba")
    kernel = audit._laws_2d if dimension == 2 else audit._laws_3d
    assert isinstance(kernel, numba.core.registry.CPUDispatcher)
    return kernel


def _assert_same_bits(got: tuple[np.ndarray, ...], want: tuple[np.ndarray, ...]) -> None:
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)  # NaN where NaN, every other entry the same double


def _motions(scene: qs.Scene, rng: np.random.Generator) -> Iterator[tuple[np.ndarray, np.ndarray, float]]:
    """Rest, random twists and forces (a third of the forces zero: separating), slide speeds that make some contacts
    slide and others stay still, and the rest twist with forces only."""
    k, m, d = scene.twist_size, len(scene.contacts), scene.dimension
    yield np.zeros((len(scene.bodies), k)), np.zeros((m, d)), 0.5
    for trial in range(8):
        T = rng.normal(size=(len(scene.bodies), k)) * 10.0 ** rng.uniform(-3, 1)
        forces = rng.normal(size=(m, d)) * 10.0 ** rng.uniform(-2, 2)
        forces[trial % 3 :: 3] = 0.0
        yield T, forces, (0.0, 0.5, np.inf)[trial % 3]


@needs_kernels
def test_audit_laws_give_the_numba_kernels_bits() -> None:
    rng = np.random.default_rng(23)
    for scene in _scenes():
        geometry = audit.AuditGeometry.of(scene)
        links, contacts, loads, facets, directions = geometry.arrays
        for T, forces, slide_speed in _motions(scene, rng):
            args = (links, contacts, loads, T, forces, facets, directions, geometry.facet_scale, slide_speed)
            _assert_same_bits(compiled.audit_laws(*args), _kernel(scene.dimension)(*args))


@needs_kernels
def test_audit_laws_without_contacts_and_on_values_that_are_not_finite() -> None:
    """No contacts: the loads' balance alone; NaN or inf in a twist, a force or the scene's data: the same bits
    as the kernel, and a check sum that is not finite (so the audit fails)."""
    for scene in (FAMILIES["grasp-2d"].make(4, 0), FAMILIES["grasp-3d"].make(4, 0)):
        links, contacts, loads, facets, directions = audit.AuditGeometry.of(scene).arrays
        k, d = scene.twist_size, scene.dimension
        T = np.full((len(scene.bodies), k), 0.1)
        none = (links[:0], contacts[:0], loads, T, np.zeros((0, d)), facets, directions, 1.0, 0.5)
        _assert_same_bits(compiled.audit_laws(*none), _kernel(d)(*none))
        for bad in (np.nan, np.inf, -np.inf):
            for where in ("twist", "force", "contacts"):
                T, forces, rows = np.full((len(scene.bodies), k), 0.1), np.ones((len(links), d)), contacts.copy()
                {"twist": T, "force": forces, "contacts": rows}[where][-1, 1] = bad
                args = (links, rows, loads, T, forces, facets, directions, 1.0, 0.5)
                got = compiled.audit_laws(*args)
                _assert_same_bits(got, _kernel(d)(*args))
                if where != "contacts":  # a scene's data are validated when it is made; a motion's are checked here
                    assert not np.isfinite(got[0][audit._CHECK]), (bad, where)


def _audit_arguments() -> list[object]:
    scene = FAMILIES["grasp-3d"].make(4, 0)
    links, contacts, loads, facets, directions = audit.AuditGeometry.of(scene).arrays
    return [links, contacts, loads, np.zeros((1, 6)), np.ones((len(links), 3)), facets, directions, 1.0, 0.5]


@needs_kernels
@pytest.mark.parametrize(
    "position, bad, message",
    [
        (3, np.zeros((1, 4)), "T must have shape"),
        (3, np.zeros(6), "T must have 2 dimensions"),
        (1, np.zeros((4, 11)), "contacts must have 2 dimensions"),
        (4, np.ones((4, 2)), "f must have 2 dimensions"),
        (4, np.ones((3, 3)), "f must have 2 dimensions"),
        (2, np.zeros((2, 6)), "loads must have 2 dimensions"),
        (0, np.array([[0, -1], [1, -1], [0, -1], [0, -1]]), r"links\[1\] = \(1, -1\) names a body outside"),
        (0, np.array([[0, -2], [0, -1], [0, -1], [0, -1]]), r"links\[0\] = \(0, -2\)"),
        (0, np.zeros((4, 2)), "links must be a C-contiguous int64 array"),
        (1, np.zeros((19, 4)).T, "contacts must be a C-contiguous float64 array"),
        (5, np.zeros((2, 2)), "directions must have 2 dimensions"),
    ],
)
def test_audit_laws_reject_bad_arguments(position: int, bad: np.ndarray, message: str) -> None:
    """Shapes that disagree, a link outside the bodies, a wrong dtype, a strided array: ValueError, never a crash."""
    args = _audit_arguments()
    args[position] = bad
    with pytest.raises(ValueError, match=message):
        compiled.kernels.audit_laws(*args, np.empty(11), np.empty((4, 3)), np.empty((4, 3)), np.empty((4, 3)))


@needs_kernels
def test_audit_laws_reject_outputs_that_cannot_be_filled() -> None:
    args = _audit_arguments()
    read_only = np.empty((4, 3))
    read_only.setflags(write=False)
    for outputs, message in (
        ((np.empty(10), np.empty((4, 3)), np.empty((4, 3)), np.empty((4, 3))), "sums must have 1 dimensions"),
        ((np.empty(11), read_only, np.empty((4, 3)), np.empty((4, 3))), "u must be a C-contiguous, writable float64"),
        ((np.empty(11), np.empty((4, 3)), np.empty((4, 2)), np.empty((4, 3))), "slips must have 2 dimensions"),
        ((np.empty(11), np.empty((4, 3)), np.empty((4, 3)), np.empty((4, 3), np.float32)), "normal must be a C-contiguous float64"),
    ):
        with pytest.raises(ValueError, match=message):
            compiled.kernels.audit_laws(*args, *outputs)
    with pytest.raises(TypeError, match="takes 13 arguments"):
        compiled.kernels.audit_laws(*args)


@pytest.fixture
def compiled_audit(monkeypatch: pytest.MonkeyPatch) -> None:
    """The audit as the default install runs it: its laws by the C extension, whether numba is installed or not."""
    if not compiled.HAVE_KERNELS:
        pytest.skip(f"built without the C extensions ({NO_EXTENSION} set)")
    monkeypatch.setattr(audit, "HAVE_NUMBA", False)
    assert audit._array_kernel(3, 4) is compiled.audit_laws


def test_the_audit_through_the_extension_fails_broken_motions(compiled_audit: None) -> None:
    """The audit's tests of broken motions, run through the C kernel: friction turned off the slip, NaN twists and forces."""
    test_contract.test_audit_measures_friction_direction_linearly()
    test_fast.test_audit_rejects_non_finite_motions()


def test_solutions_audited_through_the_extension_pass_with_the_kernels_residuals(compiled_audit: None) -> None:
    """Every audit number of a solve's answer the same through C as through numba, on the bench rows' scenes."""
    for family, size in (("grasp-2d", 4), ("grasp-3d", 4), ("box-push-nf", 16), ("pile-nf", 10)):
        problem = qs.assemble(FAMILIES[family].make(size, 0))
        solution = qs.solve(problem, certify=False)
        assert solution.motion is not None and solution.audit is not None and solution.audit.passed
        geometry = audit.AuditGeometry.of(problem.scene)
        twists = np.array([solution.twists[name] for name in geometry.names])
        forces = np.array([contact.force for contact in solution.contacts])
        got = audit.audit_arrays(geometry, twists, forces, problem.scales)
        slide_speed = MODE_SPEED * problem.scales.velocity
        evaluation = _kernel(problem.dimension)(
            *geometry.arrays[:3], twists, forces, *geometry.arrays[3:], geometry.facet_scale, slide_speed
        )
        _assert_same_bits((got[2].sums, got[2].velocities, got[2].slips, got[2].normal), evaluation)
        assert got[0] == audit._audit(audit.Evaluation(*evaluation), problem.scales, audit.DEFAULT_TOLERANCE)[0]


# --------------------------------------------------------------------------- the frictionless LP's analysis


def _analysis_kernel() -> Callable[..., tuple]:
    numba = pytest.importorskip("numba")
    assert isinstance(lp._analyse, numba.core.registry.CPUDispatcher)
    return lp._analyse


def _rank_deficient(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    rank = int(rng.integers(0, min(rows, cols) + 1))
    return rng.normal(size=(rows, rank)) @ rng.normal(size=(rank, cols)) if rank else np.zeros((rows, cols))


def _pairs(rng: np.random.Generator) -> Iterator[tuple[np.ndarray, ...]]:
    """Primal-dual pairs: exactly complementary ones on rank-deficient normals (ties at zero slack and force),
    perturbed ones, more closed contacts than twist entries, and matrices wider than ``JACOBI_MAX``."""
    for trial in range(240):
        m, n = int(rng.integers(1, 14)), int(rng.integers(1, 8))
        if trial % 40 == 0:  # wider than Jacobi rotations take: the sparse test decides
            m = n = lp.JACOBI_MAX + 2
        Jn = _rank_deficient(rng, m, n) if trial % 2 else rng.normal(size=(m, n))
        Jn *= 10.0 ** rng.uniform(-3, 2)
        q = rng.normal(size=n)
        state = rng.integers(0, 3, size=m) if trial % 40 else np.ones(m, int)  # 0: open, 1: closed and loaded, 2: closed, unloaded
        slack = np.where(state == 0, rng.uniform(0.1, 1.0, m), 0.0)
        forces = np.where(state == 1, rng.uniform(0.1, 1.0, m), 0.0)
        bn, g = Jn @ q - slack, -Jn.T @ forces
        if trial % 3 == 0:
            forces = forces + rng.normal(scale=1e-3, size=m)
        yield Jn, bn, g, q, forces


def _assert_same_analysis(got: tuple, want: tuple) -> None:
    assert got[0] == want[0] or (np.isnan(got[0]) and np.isnan(want[0]))
    np.testing.assert_array_equal(got[1], want[1])
    for a, b in zip(got[2:5], want[2:5], strict=True):
        assert a.dtype == np.bool_
        np.testing.assert_array_equal(a, b)
    assert got[5:] == tuple(int(x) for x in want[5:])


@needs_kernels
def test_analysis_gives_the_numba_kernels_bits_and_verdicts() -> None:
    rng = np.random.default_rng(29)
    verdicts = set()
    for Jn, bn, g, q, forces in _pairs(rng):
        args = (Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        got = lp._analyse_compiled(*args)
        _assert_same_analysis(got, _analysis_kernel()(*args))
        verdicts.add(got[5:])
    assert {(0, 0), (1, 1), (0, 1), (1, 0), (-1, -1)} <= verdicts, verdicts  # every verdict met, and the too-large test


@needs_kernels
def test_analysis_of_non_finite_pairs_no_contacts_and_no_twist() -> None:
    """Not finite: an infinite residual and no rank claimed; no contacts: forces unique; no twist entries."""
    Jn, bn, g = np.eye(3), np.zeros(3), np.zeros(3)
    for q, forces in ((np.array([np.nan, 0.0, 0.0]), np.zeros(3)), (np.zeros(3), np.array([0.0, np.inf, 0.0]))):
        got = lp._analyse_compiled(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK)
        assert got[0] == np.inf and got[5:] == (0, 0)
        _assert_same_analysis(got, _analysis_kernel()(Jn, bn, g, q, forces, ZERO, MOTION_RANK, FORCE_RANK))
    for empty in (
        (np.zeros((0, 3)), np.zeros(0), np.array([0.0, 0.0, -1.0]), np.zeros(3), np.zeros(0)),
        (np.zeros((2, 0)), np.array([-1.0, 0.0]), np.zeros(0), np.zeros(0), np.array([0.0, 1.0])),
    ):
        args = (*empty, ZERO, MOTION_RANK, FORCE_RANK)
        _assert_same_analysis(lp._analyse_compiled(*args), _analysis_kernel()(*args))


@needs_kernels
def test_analysis_rejects_bad_arguments() -> None:
    """Shapes that disagree, a wrong dtype, a strided or read-only array: ValueError, never a crash."""
    Jn, v3, v2 = np.ones((3, 2)), np.zeros(3), np.zeros(2)
    limits = (ZERO, MOTION_RANK, FORCE_RANK, JACOBI_ORTHOGONAL, lp.JACOBI_MAX)
    masks = tuple(np.empty(3, bool) for _ in range(3))
    read_only = np.empty(3)
    read_only.setflags(write=False)
    for args, message in (
        ((Jn, v3, v3, v2, v3, np.empty(3), *masks), "g must have 1 dimensions"),
        ((Jn, v3, v2, v3, v3, np.empty(3), *masks), "q must have 1 dimensions"),
        ((Jn, v2, v2, v2, v3, np.empty(3), *masks), "bn must have 1 dimensions"),
        ((Jn, v3, v2, v2, v3, np.empty(2), *masks), "slack must have 1 dimensions"),
        ((Jn, v3, v2, v2, v3, read_only, *masks), "slack must be a C-contiguous, writable float64"),
        ((np.ones(3), v3, v2, v2, v3, np.empty(3), *masks), "Jn must have 2 dimensions"),
        ((np.ones((2, 3)).T, v3, v2, v2, v3, np.empty(3), *masks), "Jn must be a C-contiguous float64"),
        ((Jn, v3, v2, v2, v3.astype(np.int64), np.empty(3), *masks), "forces must be a C-contiguous float64"),
        ((Jn, v3, v2, v2, v3, np.empty(3), np.empty(3), *masks[1:]), "support must be a C-contiguous bool"),
    ):
        with pytest.raises(ValueError, match=message):
            compiled.kernels.analyse_frictionless(*args[:5], *limits, *args[5:])


def test_without_numba_the_default_install_runs_the_kernels() -> None:
    """With numba unimportable, the audit's laws, the LP's analysis and the branch and bound's fit and polygon are the
    extension's (or, without it, the twins)."""
    code = textwrap.dedent(
        """
        import sys
        sys.modules["numba"] = None
        import quasistatic as qs
        from quasistatic import compiled
        from quasistatic.check import audit, motion
        from quasistatic.solvers import lp
        from quasistatic.solvers.numerics import nnls, polygon
        from quasistatic.tools.bench.families import FAMILIES
        if compiled.HAVE_KERNELS:
            assert lp._analyse is lp._analyse_compiled and audit._array_kernel(2, 3) is compiled.audit_laws
            assert motion._drop_roundoff is compiled.drop_roundoff
            assert nnls.nonnegative_fit is nnls._nonnegative_fit_compiled
            assert nnls.fit_or_farkas is nnls._fit_or_farkas_compiled
            assert polygon.polygon_vertices is compiled.polygon_vertices
        else:
            assert lp._analyse is lp._analyse_numpy and audit._array_kernel(2, 3) is None
            assert motion._drop_roundoff is motion._drop_roundoff_numpy
            assert nnls.nonnegative_fit is nnls._nonnegative_fit_scipy
            assert nnls.fit_or_farkas is nnls._fit_or_farkas_numpy
            assert polygon.polygon_vertices is polygon._polygon_vertices_numpy
        solution = qs.solve(FAMILIES["grasp-3d-nf"].make(8, 0), method="lp")
        assert solution.status == "solved" and solution.audit.passed, solution.message
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


# --------------------------------------------------------------------------- the conversions on every answer's path


@needs_kernels
def test_to_world_gives_the_numba_kernels_bits() -> None:
    """Physical twists and world forces of the bench scenes' frames, random scene-relative motions, and no contacts."""
    from quasistatic.laws import motion

    numba = pytest.importorskip("numba")
    assert isinstance(motion._to_world_kernel, numba.core.registry.CPUDispatcher)
    rng = np.random.default_rng(31)
    for scene in _scenes():
        problem = qs.assemble(scene)
        layout = motion._layout(problem)
        m, d, k = problem.n_contacts, problem.dimension, layout.units.size
        for rows in (m, 0):
            q, c = rng.normal(size=len(scene.bodies) * k), rng.normal(size=(rows, d))
            frames = layout.frames[:rows]
            want = motion._to_world_kernel(q, c, np.ascontiguousarray(frames), layout.units, 2.5)
            _assert_same_bits(compiled.to_world(q, c, frames, layout.units, 2.5), want)
    with pytest.raises(ValueError, match="multiple of units"):
        compiled.to_world(np.zeros(7), np.zeros((1, 3)), np.zeros((1, 3, 3)), np.ones(6), 1.0)
    with pytest.raises(ValueError, match="frames must have 3 dimensions"):
        compiled.to_world(np.zeros(6), np.zeros((2, 3)), np.zeros((1, 3, 3)), np.ones(6), 1.0)


@needs_kernels
def test_drop_roundoff_refuses_arrays_it_cannot_fill() -> None:
    """Its values are held to the kernel's in ``test_twins.py``; here, what it cannot change in place raises ValueError."""
    with pytest.raises(ValueError, match="roundoff must have 1 dimensions"):
        compiled.drop_roundoff(np.zeros((2, 3)), np.zeros(2))
    with pytest.raises(ValueError, match="values must be a C-contiguous, writable float64"):
        compiled.drop_roundoff(np.zeros((3, 2)).T, np.zeros(3))


# --------------------------------------------------------------------------- assembly


def _assembly_scenes() -> Iterator[qs.Scene]:
    """Every family at a few sizes (piles: contacts between free bodies), random planar and spatial scenes (movers
    that turn), a robot-driven fingertip, and coincident points (the scales' rule for a scene of no extent)."""
    for family in FAMILIES.values():
        for size in (*family.quick_sizes, *family.full_sizes)[:3]:
            if size <= 100:
                yield family.make(size, 1)
    for seed in range(40):
        yield random_scene(2, seed)
        yield random_scene(3, seed)
    yield qs.load_scene(ROOT / "examples" / "robot_tip.yaml")
    for com in ([0.3, -0.2, 0.5], [0.0, 0.0, 0.0]):
        box = qs.Body("box", mass=1.0, com=com)
        yield qs.Scene([box], [qs.Contact("box", "table", com, [0.0, 0.0, 1.0], mu=0.5)], [qs.Mover("table")])


@needs_kernels
def test_assembly_in_c_gives_the_numpy_twins_bits(monkeypatch: pytest.MonkeyPatch) -> None:
    """``assemble`` runs the C kernel, and its problem is ``assemble_numpy``'s to the bit: the laws and the scales."""
    assembly = importlib.import_module("quasistatic.laws.assemble")
    calls = []

    def spy(*args: Any) -> Any:
        calls.append(len(args[0]))
        return compiled.assemble_scene(*args)

    monkeypatch.setattr(assembly, "compiled_assemble", spy)
    scenes = list(_assembly_scenes())
    for scene in scenes:
        got, want = assembly.assemble(scene), assembly.assemble_numpy(scene)
        laws = ("frames", "J", "b", "g", "mu")
        _assert_same_bits(tuple(getattr(got, name) for name in laws), tuple(getattr(want, name) for name in laws))
        np.testing.assert_array_equal(got.scales.origin, want.scales.origin)
        assert (got.scales.length, got.scales.force, got.scales.velocity) == (want.scales.length, want.scales.force, want.scales.velocity)
        for name in ("frames", "J", "b", "g"):  # -0.0 where the twin has -0.0
            assert np.array_equal(np.signbit(getattr(got, name)), np.signbit(getattr(want, name))), name
    assert len(calls) == len(scenes)
    assert scenes[-1].contacts and assembly.assemble(scenes[-1]).scales.length == 1.0  # all at the origin
    assert assembly.assemble(scenes[-2]).scales.length == 0.5  # all at one point: its largest coordinate


@needs_kernels
def test_assembly_kernel_refuses_what_it_cannot_read() -> None:
    """Bad shapes and body indices outside the bodies raise ValueError; nothing is read or written out of bounds."""
    m, d, k = 2, 3, 6
    normals, points, coms = np.tile([0.0, 0.0, 1.0], (m, 1)), np.zeros((m, d)), np.zeros((1, d))
    owners, others = np.zeros(m, dtype=np.int64), np.full(m, -1, dtype=np.int64)
    movers = (np.zeros((m, k)), np.zeros((m, d)), np.zeros((m, d)), np.zeros((m, d)))
    loads = (np.zeros((1, k)), np.ones(1), np.array([0.0, 0.0, -9.81]))
    compiled.assemble_scene(normals, points, coms, owners, others, *movers, *loads, 1e-150)  # well formed
    with pytest.raises(ValueError, match="outside 0..0"):
        compiled.assemble_scene(normals, points, coms, np.array([0, 1]), others, *movers, *loads, 1e-150)
    with pytest.raises(ValueError, match="outside 0..0"):
        compiled.assemble_scene(normals, points, coms, owners, np.array([-1, -2]), *movers, *loads, 1e-150)
    with pytest.raises(ValueError, match="points must have 2 dimensions"):
        compiled.assemble_scene(normals, np.zeros((m + 1, d)), coms, owners, others, *movers, *loads, 1e-150)
    with pytest.raises(ValueError, match="m >= 1"):
        compiled.assemble_scene(np.zeros((0, d)), points[:0], coms, owners[:0], others[:0], *(a[:0] for a in movers), *loads, 1e-150)


@needs_kernels
def test_assembly_kernel_converts_arrays_it_cannot_read_as_they_are() -> None:
    """Views that are not C-contiguous (normals, masses) and int32 links give the contiguous arrays' laws."""
    scene = grasp_3d(4, 0)
    numbers = assembly_numbers(scene)
    want = compiled.assemble_scene(*numbers, scene.gravity, 1e-150)
    wide = np.zeros((len(scene.contacts), 6))
    wide[:, ::2] = numbers[0]  # normals as a strided view
    odd = (wide[:, ::2], *numbers[1:3], numbers[3].astype(np.int32), numbers[4].astype(np.int32), *numbers[5:10])
    got = compiled.assemble_scene(*odd, np.repeat(numbers[10], 2)[::2], scene.gravity, 1e-150)
    _assert_same_bits(got[:5], want[:5])
    assert got[5] == want[5]


def assembly_numbers(scene: qs.Scene) -> tuple[np.ndarray, ...]:
    """The arrays before gravity that ``assemble`` hands the compiled kernel."""
    n = importlib.import_module("quasistatic.laws.assemble").scene_numbers(scene)
    return (n.normals, n.points, n.coms, n.owners, n.others, n.twists, n.origins, n.places, n.driven, n.wrenches, n.masses)


@needs_kernels
def test_stacked_rows_are_numpys_array_of_them(monkeypatch: pytest.MonkeyPatch) -> None:
    """``stack_rows`` copies contiguous float rows in C, gives numpy's array where a row is not one (a strided view,
    another length, integers), and numpy's everywhere when the extension was not built."""
    rows = [np.array([1.5, -0.0, 2.0]), np.arange(3.0), np.linspace(0.0, 1.0, 6)[::2]]
    stacked = compiled.stack_rows(rows, 3)
    np.testing.assert_array_equal(stacked, np.array(rows))
    assert np.signbit(stacked[0, 1]) and stacked.flags.c_contiguous
    assert compiled.stack_rows([], 3).shape == (0, 3)
    out = np.empty((1, 3))
    with pytest.raises(ValueError, match="a row must have 1 dimensions"):
        compiled.kernels.stack_rows([np.ones(2)], out)
    with pytest.raises(ValueError, match="a row must be a C-contiguous float64"):
        compiled.kernels.stack_rows([np.arange(3)], out)
    with pytest.raises(TypeError, match="rows must be a sequence"):
        compiled.kernels.stack_rows(7, out)
    np.testing.assert_array_equal(compiled.stack_rows([np.arange(3)], 3), [[0.0, 1.0, 2.0]])  # integers: numpy's copy
    monkeypatch.setattr(compiled, "kernels", None)
    np.testing.assert_array_equal(compiled.stack_rows(rows, 3), np.array(rows))


@needs_kernels
def test_assembly_reads_a_scene_once_and_keeps_each_problem_its_own() -> None:
    """The second problem of one scene (its numbers kept with the scene) has the first one's bits, its own ``mu``, and
    ``is_frictionless`` as its ``mu`` says, with friction and without."""
    for scene in (*_assembly_scenes(), grasp_3d(4, 0, friction="none")):
        first, second = qs.assemble(scene), qs.assemble(scene)
        laws = ("frames", "J", "b", "g", "mu")
        _assert_same_bits(tuple(getattr(first, name) for name in laws), tuple(getattr(second, name) for name in laws))
        assert second.mu is not first.mu and second.mu.flags.writeable
        assert second.is_frictionless == (not (second.mu > 0.0).any())
    assert qs.assemble(grasp_3d(4, 0, friction="none")).is_frictionless and not qs.assemble(grasp_3d(4, 0)).is_frictionless


def _rows_of(scene: qs.Scene) -> tuple[list[tuple[int, int]], bool]:
    index = {body.name: i for i, body in enumerate(scene.bodies)}
    return [(index[c.body], index.get(c.other, -1)) for c in scene.contacts], scene.friction.kind != "none"


@needs_kernels
def test_audit_rows_in_c_are_the_python_loops_bits() -> None:
    """The audit's contact rows from the C kernel are its Python loop's, double for double (-0.0 too): movers that turn,
    contacts between free bodies, a robot's fingertip, pyramids and ``friction: none``."""
    scenes = [*_assembly_scenes(), grasp_3d(6, 1, friction="pyramid:4"), grasp_3d(4, 0, friction="none"), random_scene(2, 3, "none")]
    for scene in scenes:
        links, frictional = _rows_of(scene)
        got = audit._contact_rows_compiled(scene, links, frictional)
        want = audit._contact_rows_python(scene, links, frictional)
        assert got.shape == want.shape and got.tobytes() == want.tobytes()
    assert any(mover.robot is not None for scene in scenes for mover in scene.movers)  # a row read through a Jacobian


@needs_kernels
def test_audit_rows_refuse_links_outside_the_bodies() -> None:
    m, d = 2, 3
    floats = (np.tile([0.0, 0.0, 1.0], (m, 1)), np.zeros((m, d)), np.zeros((1, d)))
    movers = (np.zeros((m, 6)), np.zeros((m, d)), np.zeros((m, d)), np.zeros(m, dtype=bool), np.ones(m))
    assert compiled.audit_rows(*floats, np.array([[0, -1], [0, -1]]), *movers).shape == (m, 1 + d * (d + 3))
    with pytest.raises(ValueError, match="outside 0..0"):
        compiled.audit_rows(*floats, np.array([[0, -1], [1, -1]]), *movers)
    with pytest.raises(ValueError, match="outside 0..0"):
        compiled.audit_rows(*floats, np.array([[0, -2], [0, -1]]), *movers)
    with pytest.raises(ValueError, match="links must have 2 dimensions"):
        compiled.audit_rows(*floats, np.array([[0, -1]]), *movers)
