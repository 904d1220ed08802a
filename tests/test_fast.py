"""The fast path: Lemke's method (unit tests on textbook LCPs) and the ``fast`` backend.

The backend finds one motion and proves nothing: wherever the certified search
says ``solved`` it must give the same twist (or report ``failed``), and it
must never report a motion where no motion exists. Expected twists of the
off-axis push are derived in its docstring, not taken from the library.
"""

from __future__ import annotations

import itertools
import math
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from catalogue import BY_NAME, describe, laws_hold, matches, same, scale_of
from quasistatic.solvers import Options
from quasistatic.solvers.fast import solve_fast
from quasistatic.solvers.numerics import lemke as lemke_module
from quasistatic.solvers.numerics.lemke import PIVOT_LIMIT, RAY, SOLUTION, lemke
from quasistatic.tools.validation import load_cases, scene_data

ROOT = Path(__file__).resolve().parents[1]
G = 9.81
TOL = 1e-11

# --------------------------------------------------------------------------- Lemke's method

LEMKE_VARIANTS = [
    pytest.param(lemke, id="compiled"),  # with numba: the extension's C (or numba's kernel) called from compiled code
    pytest.param(lemke_module.numba_lemke, id="numba-kernel"),
    pytest.param(getattr(lemke_module.numba_lemke, "py_func", lemke_module.numba_lemke), id="python"),
    pytest.param(lemke_module._lemke_numpy, id="numpy-twin"),  # what runs without numba or a C compiler
]


def _solve_lcp(solver: Any, M: np.ndarray, q: np.ndarray, max_pivots: int = 1000) -> tuple[int, np.ndarray, int]:
    status, z, pivots, _ = solver(np.asarray(M, float), np.asarray(q, float), np.ones(len(q)), max_pivots, TOL, 0)
    return int(status), z, int(pivots)


def _is_solution(M: np.ndarray, q: np.ndarray, z: np.ndarray, tol: float = 1e-9) -> bool:
    w = M @ z + q
    return bool(z.min() >= -tol and w.min() >= -tol and abs(z @ w) <= tol)


def _enumerated_solutions(M: np.ndarray, q: np.ndarray) -> list[np.ndarray]:
    """Every solution of a small nondegenerate LCP, by trying each complementary basis."""
    n = len(q)
    found = []
    for support in itertools.product([False, True], repeat=n):
        S = np.flatnonzero(support)
        z = np.zeros(n)
        if S.size:
            try:
                z[S] = np.linalg.solve(M[np.ix_(S, S)], -q[S])
            except np.linalg.LinAlgError:
                continue
        if _is_solution(M, q, z):
            found.append(z)
    return found


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
def test_lemke_two_by_two_p_matrix(solver: Any) -> None:
    """M = [[2, 1], [1, 2]], q = (-5, -6): both z positive, w = 0, so M z = -q: z = (4/3, 7/3)."""
    status, z, _ = _solve_lcp(solver, [[2.0, 1.0], [1.0, 2.0]], [-5.0, -6.0])
    assert status == SOLUTION
    assert z == pytest.approx([4.0 / 3.0, 7.0 / 3.0], abs=1e-12)


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
def test_lemke_partial_support(solver: Any) -> None:
    """M = I, q = (-1, 2, -3): z_i = max(-q_i, 0) = (1, 0, 3), w = (0, 2, 0)."""
    status, z, _ = _solve_lcp(solver, np.eye(3), [-1.0, 2.0, -3.0])
    assert status == SOLUTION
    assert z == pytest.approx([1.0, 0.0, 3.0], abs=1e-12)


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
def test_lemke_nonnegative_q_needs_no_pivot(solver: Any) -> None:
    status, z, pivots = _solve_lcp(solver, [[0.0, -1.0], [1.0, 0.0]], [0.0, 3.0])
    assert (status, pivots) == (SOLUTION, 0)
    assert z == pytest.approx([0.0, 0.0])


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
def test_lemke_matches_enumeration_on_random_p_matrices(solver: Any) -> None:
    """A P-matrix LCP has exactly one solution: Lemke's must be the one enumeration finds."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        A = rng.normal(size=(5, 5))
        M = A @ A.T + 0.1 * np.eye(5) + (A - A.T)  # positive definite (not symmetric): a P-matrix
        q = rng.normal(size=5)
        status, z, _ = _solve_lcp(solver, M, q)
        (expected,) = _enumerated_solutions(M, q)
        assert status == SOLUTION
        assert z == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
@pytest.mark.parametrize("q", [[-1.0, -1.0, -1.0], [-1.0, 0.0, -1.0], [0.0, -2.0, 0.0]])
def test_lemke_degenerate_ties(solver: Any, q: list[float]) -> None:
    """Tied ratios and zero entries of q (degenerate pivots) on a P-matrix: the unique solution.

    M = [[1, 2, 0], [0, 1, 2], [2, 0, 1]] has principal minors 1, 1, 1, 1, 1, 1 and 9: a P-matrix.
    """
    M = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]])
    status, z, _ = _solve_lcp(solver, M, q)
    assert status == SOLUTION
    assert _is_solution(M, np.array(q), z)


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
@pytest.mark.parametrize(
    ("M", "q"),
    [
        ([[-1.0]], [-1.0]),  # w = -z - 1 < 0 for every z >= 0
        ([[1.0, -1.0], [-1.0, 1.0]], [-1.0, -1.0]),  # w1 + w2 = -2 < 0: infeasible
    ],
)
def test_lemke_ends_on_a_ray_when_no_solution_exists(solver: Any, M: list, q: list) -> None:
    status, _, _ = _solve_lcp(solver, M, q)
    assert status == RAY


def test_lemke_stops_at_its_pivot_limit() -> None:
    rng = np.random.default_rng(3)
    A = rng.normal(size=(8, 8))
    status, _, pivots = _solve_lcp(lemke, A @ A.T + np.eye(8), -np.abs(rng.normal(size=8)) - 1.0, max_pivots=2)
    assert (status, pivots) == (PIVOT_LIMIT, 2)


@pytest.mark.parametrize("solver", LEMKE_VARIANTS)
@pytest.mark.parametrize(("family", "size"), [("grasp-3d", 4), ("grasp-2d", 4)])
def test_lemkes_free_variables_never_leave_and_may_turn_negative(solver: Any, family: str, size: int) -> None:
    """With the split twist's halves free (``free = 2n``), Lemke ends at a point of the mixed LCP: the halves are
    unbounded (some negative here), every other variable solves its complementarity, and equilibrium (the halves'
    rows) holds exactly; every variant takes the same pivots."""
    from quasistatic.solvers.numerics import lcp
    from quasistatic.tools.bench.families import FAMILIES

    scene = FAMILIES[family].make(size, 0)
    M, q = _split_lcp(scene)
    halves = 2 * qs.assemble(scene).derived("fast", lcp.LemkeInputs).J.shape[2]
    status, z, pivots, _ = solver(M, q, np.ones(q.shape[0]), 1000, TOL, halves)
    assert status == SOLUTION and int(pivots) == int(lemke(M, q, np.ones(q.shape[0]), 1000, TOL, halves)[2])
    assert z[:halves].min() < -1e-6  # a free half went negative: it stayed in the basis
    w = M @ z + q
    assert np.abs(w[:halves]).max() <= 1e-9
    assert z[halves:].min() >= -1e-9 and w[halves:].min() >= -1e-9 and abs(z[halves:] @ w[halves:]) <= 1e-9


# --------------------------------------------------------------------------- the backend on scene files


def _frictional_files() -> list[Path]:
    files = sorted((ROOT / "examples").glob("*.yaml")) + sorted((ROOT / "validation" / "scenes").glob("*.yaml"))
    return [f for f in files if not qs.assemble(qs.load_scene(f)).is_frictionless]


def _slow_certified(path: Path) -> bool:
    """3-D exact cones: the certified search takes seconds there."""
    problem = qs.assemble(qs.load_scene(path))
    return problem.dimension == 3 and problem.friction.kind == "exact" and problem.n_contacts > 2


FILES = [pytest.param(f, id=f.name, marks=[pytest.mark.slow] if _slow_certified(f) else []) for f in _frictional_files()]


def _relative_twist_error(problem: qs.Problem, a: qs.Solution, b: qs.Solution) -> float:
    return max(float(np.max(np.abs(a.twists[k] - b.twists[k]))) for k in a.twists) / problem.scales.velocity


@pytest.mark.parametrize("path", FILES)
def test_fast_agrees_with_the_certified_search(path: Path) -> None:
    """Certified ``solved``: the same twist (or ``failed``); jammed/unstable: the same, proven, or ``failed``."""
    problem = qs.assemble(qs.load_scene(path))
    certified = qs.solve(problem, method="scip")
    fast = qs.solve(problem, method="fast")
    assert fast.status in ("solved", "failed", certified.status), fast.message
    if fast.status in ("jammed", "unstable"):  # the complete fallback's proof
        assert fast.certified and "certificate" in fast.details
        return
    if fast.status == "failed":
        assert fast.message.startswith("failed:")
        return
    assert certified.status in ("solved", "ambiguous"), f"fast found a motion where scip says {certified.status}"
    assert fast.audit is not None and fast.audit.passed, fast.audit
    laws_hold(problem.scene, fast.motion)  # checked from the scene alone, not by the library's audit
    assert not fast.certified
    if certified.status == "solved":
        assert _relative_twist_error(problem, certified, fast) <= 1e-6


def _solve_cases() -> list[Any]:
    cases = []
    for case in load_cases(ROOT / "validation"):
        if case.check != "solve" or case.modes is not None:
            continue
        cases.append(pytest.param(case, id=case.id))
    return cases


@pytest.mark.parametrize("case", _solve_cases())
def test_fast_on_the_validation_cases_and_their_3d_extrusions(case: Any) -> None:
    """Against the hand-derived expectations (2-D and extruded 3-D with exact cones): right twist or ``failed``."""
    problem = qs.assemble(qs.load_scene(scene_data(case)))
    fast = qs.solve(problem, method="fast")
    expected = case.expect["status"]
    assert fast.status in ("solved", "failed", expected), fast.message
    if fast.status in ("failed", "jammed", "unstable"):
        return
    assert expected in ("solved", "ambiguous"), f"fast found a motion where the case expects {expected}"
    assert fast.audit is not None and fast.audit.passed, fast.audit
    if expected == "solved" and case.known is not None:
        # A documented disagreement (the Whitney pegs' 3-D twins also slide out of the plane, cases.yaml's known_3d):
        # the fast path's one motion may be that other one, checked from the scene alone.
        assert fast.motion is not None
        laws_hold(problem.scene, fast.motion)
    elif expected == "solved":
        for body, twist in case.expect.get("twists", {}).items():
            want = [twist[0], twist[1], 0.0, 0.0, 0.0, twist[2]] if case.depth is not None else twist
            assert fast.twists[body] == pytest.approx(want, abs=case.tolerance["twist"])


# --------------------------------------------------------------------------- 3-D exact cones, off-axis slip


def _box_data(angle_deg: float, mu: float = 0.5, mass: float = 1.0, speed: float = 0.01) -> dict[str, Any]:
    """A 0.1 m cube (com 0.05 m up) on four table contacts at its bottom corners, pushed through its com.

    A frictionless finger touches it at com height, 0.05 m from the com
    against the push direction d = (cos a, sin a, 0), with normal d, and
    moves at ``speed`` along d.
    """
    a = math.radians(angle_deg)
    d = [math.cos(a), math.sin(a), 0.0]
    corners = [[x, y, 0.0] for x in (-0.05, 0.05) for y in (-0.05, 0.05)]
    contacts = [{"body": "box", "other": "table", "point": p, "normal": [0.0, 0.0, 1.0], "mu": mu} for p in corners]
    contacts.append({"body": "box", "other": "finger", "point": [-0.05 * d[0], -0.05 * d[1], 0.05], "normal": d})
    return {
        "quasistatic": 1,
        "dimension": 3,
        "bodies": {"box": {"mass": mass, "com": [0.0, 0.0, 0.05]}},
        "movers": {"table": None, "finger": {"twist": [speed * d[0], speed * d[1], 0.0, 0.0, 0.0, 0.0]}},
        "contacts": contacts,
    }


@pytest.mark.parametrize("angle", [30.0, 0.0, 71.0])
def test_box_pushed_off_axis_translates_along_the_push(angle: float) -> None:
    """Cube on four corners (mu = 0.5, m = 1 kg) pushed through its com at ``angle`` from x.

    Guess: the box translates with the finger, v = 0.01 d, no rotation. Every
    support slides along d, so with exact cones each friction force is
    -mu N_i d, together -mu m g d (sum N_i = m g). The finger, frictionless,
    pushes along d with P = mu m g = 4.905 N: horizontal balance holds along d
    and across it. Moments: the push acts at com height, each friction force
    at the table, 0.05 m below; the tilting moment is carried by a shift of
    the normal forces towards the front (centre of pressure 0.025 m ahead of
    the com, along d, inside the support square), and the centre of pressure
    lies on the line of d, so the friction forces make no moment about the
    vertical: the yaw balance holds too. The finger contact stays closed and
    every support slides: the guess satisfies the laws, with maximum
    dissipation at every support (friction exactly opposite the slip).
    A pyramid would bend the motion towards its edges.
    """
    mu, m = 0.5, 1.0
    sol = qs.solve(qs.assemble(qs.load_scene(_box_data(angle, mu, m))), method="fast")
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed, sol.audit
    a = math.radians(angle)
    assert sol.twists["box"] == pytest.approx([0.01 * math.cos(a), 0.01 * math.sin(a), 0.0, 0.0, 0.0, 0.0], abs=1e-9)
    assert sol.modes == ("sliding",) * 4 + ("rolling",)
    assert sol.contacts[4].normal_force == pytest.approx(mu * m * G, rel=1e-7)
    assert sum(c.normal_force for c in sol.contacts[:4]) == pytest.approx(m * G, rel=1e-9)
    for contact in sol.contacts[:4]:  # maximum dissipation, exactly: f_t = -mu N slip/|slip|
        tangential = contact.force - contact.normal_force * np.array([0.0, 0.0, 1.0])
        target = -mu * contact.normal_force * contact.slip / np.linalg.norm(contact.slip)
        assert np.linalg.norm(tangential - target) <= 1e-9 * m * G
    assert "exact_cone" in sol.details


def test_pyramid_model_is_solved_as_given() -> None:
    """With ``friction: pyramid:4`` the polyhedral laws are the model: one Lemke solve, no re-alignment."""
    scene = qs.load_scene({**_box_data(30.0), "friction": "pyramid:4"})
    sol = qs.solve(qs.assemble(scene), method="fast")
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed
    assert sol.details["realignments"] == 0 and "exact_cone" not in sol.details


# --------------------------------------------------------------------------- what the backend refuses or reports


def test_prescribed_modes_are_left_to_the_certified_search() -> None:
    problem = qs.assemble(qs.load_scene(ROOT / "validation" / "scenes" / "box_push_low.yaml"))
    result = solve_fast(problem, Options(modes=("sliding", None, None)))
    assert result.status == "failed" and "modes" in result.message


@pytest.mark.parametrize(
    ("name", "expected"),
    [("examples/topple.yaml", "unstable"), ("validation/scenes/jam_closing_fingers.yaml", "jammed")],
)
def test_no_motion_is_proven_by_the_fallback_where_lemke_ends_on_a_ray(name: str, expected: str) -> None:
    """A ray proves nothing; the planar vertex certificate then proves that no motion exists, with its certificate."""
    problem = qs.assemble(qs.load_scene(ROOT / name))
    assert qs.solve(problem, method="scip").status == expected
    fast = qs.solve(problem, method="fast")
    assert fast.status == expected and fast.certified, fast.message
    assert "secondary ray" in fast.details["lemke"] and "vertex certificate" in fast.details["certificate"]


def test_a_wedge_of_exact_cones_is_proven_by_the_sector_relaxation() -> None:
    """grasp-3d 4 #1 is jammed (a wedge); the fallback's 8-edge pyramid proves that only for itself, so the
    exact cones' sector relaxation is proven infeasible before the fast path says ``jammed``."""
    from quasistatic.tools.bench.families import grasp_3d

    problem = qs.assemble(grasp_3d(4, 1))
    fast = qs.solve(problem, method="fast")
    assert fast.status == "jammed" and fast.certified and fast.diagnosis is qs.Diagnosis.WEDGED, fast.message
    assert "slip sectors" in fast.details["certificate"] and "secondary ray" in fast.details["lemke"]
    assert qs.solve(problem, method="scip").status == "jammed"


@pytest.mark.parametrize("name", ["examples/two_finger_lift.yaml", "examples/squeeze.yaml", "examples/box_push_3d.yaml"])
def test_frictionless_scenes(name: str) -> None:
    """No contact has edges (mu = 0): Lemke on normal forces alone; one audited motion."""
    sol = qs.solve(qs.assemble(qs.load_scene(ROOT / name)), method="fast")
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed
    assert set(sol.details) >= {"uniqueness", "method", "pivots", "realignments"}


def test_runs_without_numba() -> None:
    """With numba made unimportable, the kernels run as plain Python and give the hand-derived answers."""
    code = textwrap.dedent(
        f"""
        import sys
        sys.modules["numba"] = None  # import numba now raises ImportError
        import quasistatic as qs
        from quasistatic import jit
        assert not jit.HAVE_NUMBA
        for scene in (qs.load_scene({str(ROOT / "validation" / "scenes" / "box_push_low.yaml")!r}), qs.load_scene({_box_data(30.0)!r})):
            sol = qs.solve(scene, method="fast")
            assert sol.status == "solved" and sol.audit.passed, sol.message
            print(*sol.twists["box"])
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split("\n")
    # The box pushed low (h = 0.15 < w/(2 mu)) translates with the pusher (catalogue ``box-push-low``).
    assert [float(x) for x in lines[0].split()] == pytest.approx([0.01, 0.0, 0.0], abs=1e-12)
    assert [float(x) for x in lines[1].split()] == pytest.approx([0.01 * math.cos(math.pi / 6), 0.005, 0, 0, 0, 0], abs=1e-9)


# --------------------------------------------------------------------------- where Lemke's method cannot answer


def _split_lcp(scene: qs.Scene) -> tuple[np.ndarray, np.ndarray]:
    """The fast path's LCP ``(M, q)`` of a scene (unrotated edges), as its kernel builds it."""
    from quasistatic.solvers.numerics import lcp

    data = qs.assemble(scene).derived("fast", lcp.LemkeInputs)
    Jn, bn, Jt, bt, mu_f = lcp._split_rows(data.J, data.b, data.mu, data.frictional)
    edges = lcp._edges(data.base, np.zeros(data.frictional.shape[0]), scene.dimension - 1)
    return lcp._assemble(Jn, Jt, bn, bt, mu_f, data.g, edges, data.frictional)


def _solution_indices(M: np.ndarray, q: np.ndarray) -> set[int]:
    """``sgn det M_SS`` of every nonsingular complementary basis whose point solves LCP(q, M) (tries all 2^N)."""
    indices = set()
    for support in itertools.product([False, True], repeat=len(q)):
        S = np.flatnonzero(support)
        z = np.zeros(len(q))
        det = 1.0
        if S.size:
            det = float(np.linalg.det(M[np.ix_(S, S)]))
            if abs(det) < 1e-12:
                continue
            z[S] = np.linalg.solve(M[np.ix_(S, S)], -q[S])
        if _is_solution(M, q, z):
            indices.add(int(np.sign(det)))
    return indices


@pytest.mark.parametrize(("instance", "index", "status"), [(0, 1, SOLUTION), (2, -1, RAY), (4, -1, RAY)])
def test_lemke_reaches_only_solutions_of_index_plus_one(instance: int, index: int, status: int) -> None:
    """Why ``fast`` fails on 2-D bench grasps that certainly have a motion (grasp_2d(2, 2) and (2, 4): ``solved``).

    Lemke's path from its primary ray ends at a solution of index +1 (``sgn det M_SS`` of its support ``S``)
    or on a secondary ray, whatever the positive covering vector (the index is a degree, and every ``d > 0``
    gives the primary ray the same orientation). The LCPs of these scenes have solutions, all of index -1:
    Lemke ends on a ray with every covering vector tried. grasp_2d(2, 0), whose solutions have index +1, is solved.
    """
    from quasistatic.tools.bench.families import grasp_2d

    M, q = _split_lcp(grasp_2d(2, instance))
    assert _solution_indices(M, q) == {index}
    rng = np.random.default_rng(instance)
    for d in (np.ones(len(q)), *np.exp(rng.uniform(-2.0, 2.0, (4, len(q))))):
        assert lemke(M, q, d, 1000, TOL, 0)[0] == status


@pytest.mark.parametrize(
    ("family", "size", "instance"),
    [
        ("grasp-3d", 8, 0),
        ("grasp-3d", 8, 1),
        ("grasp-2d", 2, 2),
        ("grasp-2d", 2, 4),
        ("grasp-2d", 2, 5),
        ("grasp-3d", 6, 0),
        ("grasp-2d", 8, 3),
    ],
)
def test_fast_answers_the_bench_grasps_that_have_a_motion(family: str, size: int, instance: int) -> None:
    """Issue 11's target: every bench scene with a motion (the certified search finds one or more) is solved.

    The first five end Lemke's method on a secondary ray (see :func:`test_lemke_reaches_only_solutions_of_index_plus_one`):
    the complete fallback answers them (``tests/test_fast_fallback.py`` checks its motions against SCIP's).
    """
    from quasistatic.tools.bench.families import FAMILIES

    scene = FAMILIES[family].make(size, instance)
    sol = qs.solve(scene, method="fast")
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed


# --------------------------------------------------------------------------- speed work keeps the answers


def _lp_without_lemke(problem: qs.Problem, monkeypatch: pytest.MonkeyPatch) -> qs.Solution:
    """The ``lp`` answer with Lemke's method switched off (HiGHS only), on a fresh copy of the problem."""
    from quasistatic.solvers import lp

    monkeypatch.setattr(lp, "LEMKE_MAX_ROWS", -1)
    try:
        return qs.solve(qs.assemble(problem.scene), method="lp")
    finally:
        monkeypatch.undo()


@pytest.mark.parametrize("seed", range(40))
def test_lp_with_lemke_gives_the_highs_answer(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """The frictionless LP's primal-dual pair from Lemke's method leads to the same verdict as HiGHS's:
    status, twist, and the same normal-force ranges when the forces are indeterminate."""
    from random_scenes import random_scene

    problem = qs.assemble(random_scene(2 + seed % 2, seed, friction="none"))
    fast, reference = qs.solve(problem, method="lp"), _lp_without_lemke(problem, monkeypatch)
    assert fast.status == reference.status
    assert fast.forces_indeterminate == reference.forces_indeterminate
    for motion in (fast.motion, reference.motion):  # both obey the laws, checked from the scene alone
        if motion is not None:
            laws_hold(problem.scene, motion)
    if reference.status == "solved":
        assert fast.audit is not None and fast.audit.passed
        for name, twist in reference.twists.items():
            np.testing.assert_allclose(fast.twists[name], twist, rtol=0, atol=1e-9)
        for mine, theirs in zip(fast.contacts, reference.contacts, strict=True):
            assert mine.mode == theirs.mode
            if theirs.normal_force_range is None:
                assert mine.normal_force_range is None
                assert mine.normal_force == pytest.approx(theirs.normal_force, abs=1e-9)
            else:
                assert mine.normal_force_range is not None
                assert mine.normal_force_range[0] == pytest.approx(theirs.normal_force_range[0], abs=1e-9)


def test_lp_with_lemke_on_the_benchmark_grasps(monkeypatch: pytest.MonkeyPatch) -> None:
    """Frictionless 3-D grasps (8 contacts: solved, one with indeterminate forces; 4: unstable)."""
    from quasistatic.tools.bench.families import grasp_3d

    for size, instance in itertools.product((4, 8), range(8)):
        problem = qs.assemble(grasp_3d(size, instance, friction="none"))
        fast, reference = qs.solve(problem), _lp_without_lemke(problem, monkeypatch)
        assert (fast.status, fast.forces_indeterminate) == (reference.status, reference.forces_indeterminate)
        for motion in (fast.motion, reference.motion):
            if motion is not None:
                laws_hold(problem.scene, motion)
        for name, twist in reference.twists.items():
            np.testing.assert_allclose(fast.twists[name], twist, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", ["box-push-low", "lift-between-pins", "puck-slip-off-axis-3d"])
def test_contacts_read_after_pickling_or_from_workers_are_the_hand_derived_ones(name: str) -> None:
    """A fast-path solution's per-contact results, first read only after the solution was pickled (before or
    after they were read in this process) or sent back by ``solve_many``'s worker processes, are those derived
    by hand for the catalogue case (a box pushed low, a lift between pins with indeterminate pin forces, a
    puck slipping off-axis in 3-D): its twists, modes and normal forces, the JSON's contacts, and the laws
    recomputed from the scene."""
    case = BY_NAME[name]
    (expected,) = case.motions
    unread = qs.solve(case.scene, method="fast")
    read = qs.solve(case.scene, method="fast")
    assert [c.mode for c in read.contacts] == list(expected.modes)
    pickled = [pickle.loads(pickle.dumps(sol)) for sol in (unread, read)]
    batched = qs.solve_many([case.scene, case.scene], method="fast", n_jobs=2, chunks_per_job=1)
    scale = scale_of(expected.normal_forces)
    for sol in (*pickled, *batched, unread):
        assert sol.status == "solved" and sol.motion is not None, sol.message
        assert sol.modes == expected.modes  # before any per-contact result is read
        assert matches(sol.motion, expected, exact=True), describe(sol.motion, expected)
        laws_hold(case.scene, sol.motion)
        data = sol.to_dict()["contacts"]
        assert [c["mode"] for c in data] == list(expected.modes)
        for contact, want in zip(data, expected.normal_forces, strict=True):
            assert want is None or same(contact["normal_force"], want, scale), (contact, want)


_KERNEL_CASES = """
import json, sys
import numpy as np
from quasistatic.check.audit import AuditGeometry, audit_arrays
from quasistatic.model import scene_scales
from quasistatic.tools.bench.families import grasp_2d, grasp_3d

scenes = [grasp_2d(4, 0), grasp_3d(6, 1), grasp_3d(4, 2, friction="pyramid:6"), grasp_3d(8, 0, friction="none")]
rng = np.random.default_rng(7)
out = []
for scene in scenes:
    T = rng.normal(size=(len(scene.bodies), scene.twist_size))
    forces = rng.normal(size=(len(scene.contacts), scene.dimension))
    _, _, e = audit_arrays(AuditGeometry.of(scene), T, forces, scene_scales(scene))
    out.append([a.tolist() for a in (e.sums, e.velocities, e.slips, e.normal)])
print(json.dumps(out))
"""


def test_audit_kernel_compiled_and_plain_python_agree() -> None:
    """The law kernel gives the same sums, velocities and slips compiled by numba, in C (numba made unimportable)
    and as plain Python on lists (the C extension unimportable too)."""
    import json

    runs = []
    no_numba = "import sys; sys.modules['numba'] = None\n"
    for block in ("", no_numba, no_numba + "sys.modules['quasistatic._kernels'] = None\n"):
        out = subprocess.run([sys.executable, "-c", block + _KERNEL_CASES], capture_output=True, text=True, timeout=120, cwd=ROOT)
        assert out.returncode == 0, out.stderr
        runs.append(json.loads(out.stdout))
    for compiled, *others in zip(*runs, strict=True):
        for python in others:
            for a, b in zip(compiled, python, strict=True):
                np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-13, atol=1e-15)


def test_audit_rejects_non_finite_motions() -> None:
    """A NaN anywhere in a motion fails its audit (max() alone would let a NaN through)."""
    from quasistatic.check.audit import audit_motion
    from quasistatic.tools.bench.families import grasp_3d

    problem = qs.assemble(grasp_3d(8, 0, friction="none"))
    solution = qs.solve(problem, method="fast")
    assert solution.motion is not None and solution.audit is not None and solution.audit.passed
    forces = np.array([c.force for c in solution.contacts])
    for where in ("twist", "force"):
        twists = {name: t.copy() for name, t in solution.twists.items()}
        bad = forces.copy()
        if where == "twist":
            next(iter(twists.values()))[4] = np.nan
        else:
            bad[3, 1] = np.nan
        audit, _ = audit_motion(problem.scene, twists, bad, problem.scales)
        assert not audit.passed, where


def test_jacobi_singular_values_match_lapack() -> None:
    """The small-matrix SVD behind the frictionless rank tests gives LAPACK's singular values and ranks."""
    from quasistatic.solvers.lp import _full_rank, _singular_values

    rng = np.random.default_rng(3)
    for trial in range(500):
        k, n = (int(x) for x in rng.integers(1, 10, size=2))
        r = int(rng.integers(0, min(k, n) + 1))
        A = rng.normal(size=(k, r)) @ rng.normal(size=(r, n)) * 10.0 ** rng.uniform(-12, 2) if r else np.zeros((k, n))
        if trial % 5 == 0 and k > 1:
            A[1] = A[0] * (1.0 + 1e-13)  # nearly dependent rows
        ours = np.sort(_singular_values(A))[::-1]
        lapack = np.linalg.svd(A, compute_uv=False)
        np.testing.assert_allclose(ours, lapack, rtol=0, atol=1e-14 * max(1.0, lapack.max()))
        for tol in (1e-9, 1e-10):
            rank = int(np.sum(lapack > tol))
            assert _full_rank(A, tol, rank) == 1
            assert _full_rank(A, tol, rank + 1) == 0
    assert _full_rank(np.zeros((0, 6)), 1e-9, 0) == 1
    assert _full_rank(np.zeros((30, 30)), 1e-9, 0) == -1  # too large for Jacobi rotations: the caller decides


def test_sparse_full_column_rank_matches_lapack() -> None:
    """Large matrices get their full-column-rank test from a sparse LU (no dense SVD): it agrees with LAPACK's
    smallest singular value wherever that is not within a factor 2 of the threshold."""
    from quasistatic.solvers.numerics.rank import DENSE_MAX, full_column_rank

    rng = np.random.default_rng(5)
    for trial in range(60):
        r = int(rng.integers(DENSE_MAX + 1, 160))
        c = int(rng.integers(DENSE_MAX + 1, r + 1))
        A = (rng.random((r, c)) < 0.05) * rng.normal(size=(r, c)) + np.eye(r, c) * rng.uniform(0.0, 1.0)
        if trial % 2:  # a column nearly a multiple of another
            i, j = rng.choice(c, size=2, replace=False)
            A[:, i] = A[:, j] * rng.uniform(0.5, 2.0) + rng.normal(size=r) * 10.0 ** rng.uniform(-13, -6)
        smallest = np.linalg.svd(A, compute_uv=False)[-1]
        for tol in (1e-9, 1e-10):
            if not 0.5 < smallest / tol < 2.0:
                assert full_column_rank(A, tol) is bool(smallest > tol), (trial, smallest, tol)
    assert not full_column_rank(np.zeros((DENSE_MAX + 5, DENSE_MAX + 1)), 1e-9)  # exactly singular, by its pattern
    few_rows = np.zeros((140, DENSE_MAX + 70))
    few_rows[:9] = rng.normal(size=(9, DENSE_MAX + 70))  # rank 9 at most (SuperLU could crash on its K)
    assert not full_column_rank(few_rows, 1e-9)


def test_plain_python_twins_equal_the_compiled_kernels() -> None:
    """Each kernel's whole-array twin (what runs without numba) gives the compiled loops' results to round-off."""
    pytest.importorskip("numba")
    from quasistatic.laws import fixed_modes
    from quasistatic.solvers.numerics import lcp
    from quasistatic.tools.bench.families import grasp_2d, grasp_3d

    rng = np.random.default_rng(11)
    for size in (1, 5, 17):
        A, r = rng.normal(size=(size, size)), rng.normal(size=size)
        (ok, x), (ok_twin, x_twin) = lcp._linear_solve(A, r), lcp._linear_solve_numpy(A, r)
        assert ok and ok_twin
        np.testing.assert_allclose(x_twin, x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(lcp._newton_step_numpy(A, r), lcp._newton_step(A, r), rtol=1e-8, atol=1e-12)
    singular = rng.normal(size=(4, 4))
    singular[3] = singular[0] - 2.0 * singular[1]
    assert not lcp._linear_solve(singular, r[:4])[0] and not lcp._linear_solve_numpy(singular, r[:4])[0]
    for scene in (grasp_2d(4, 1), grasp_3d(6, 1), grasp_3d(8, 0)):
        data = qs.assemble(scene).derived("fast", lcp.LemkeInputs)
        blocks = lcp._split_rows(data.J, data.b, data.mu, data.frictional)
        edges = lcp._edges(data.base, rng.uniform(-1, 1, data.frictional.shape[0]), scene.dimension - 1)
        (Jn, bn, Jt, bt, mu_f), fr = blocks, data.frictional
        for got, want in zip(
            lcp._assemble_numpy(Jn, Jt, bn, bt, mu_f, data.g, edges, fr),
            lcp._assemble(Jn, Jt, bn, bt, mu_f, data.g, edges, fr),
            strict=True,
        ):
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-15)
        for got, want in zip(lcp._split_rows_numpy(data.J, data.b, data.mu, fr), blocks, strict=True):
            np.testing.assert_array_equal(got, want)
        offsets = rng.uniform(-1, 1, fr.shape[0])
        np.testing.assert_allclose(
            lcp._edges_numpy(data.base, offsets, scene.dimension - 1),
            lcp._edges(data.base, offsets, scene.dimension - 1),
            rtol=1e-14,
            atol=1e-15,
        )
        m, _, n = data.J.shape
        z = rng.uniform(0.0, 1.0, 2 * n + m + fr.shape[0] * (edges.shape[1] + 1))
        for got, want in zip(
            lcp._motion_numpy(z, edges, fr, m, scene.dimension, n), lcp._motion(z, edges, fr, m, scene.dimension, n), strict=True
        ):
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-15)
        if scene.dimension == 3:
            q = rng.normal(size=n)
            for i in range(m):
                np.testing.assert_allclose(
                    lcp._contact_speeds_numpy(data.J, data.b, q, i), lcp._contact_speeds(data.J, data.b, q, i), rtol=1e-13, atol=1e-15
                )
        M, q_lcp = lcp._assemble(Jn, Jt, bn, bt, mu_f, data.g, edges, fr)
        for free in (0, 2 * n):  # the textbook path, and the split twist's halves free (the fast path's)
            for got, want in zip(
                lemke_module._lemke_numpy(M, q_lcp, np.ones(q_lcp.shape[0]), 4000, TOL, free),
                lemke(M, q_lcp, np.ones(q_lcp.shape[0]), 4000, TOL, free),
                strict=True,
            ):
                np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)  # the same pivots: status, point, count, basis
        kind = rng.integers(0, 3, m).astype(np.int64)  # separating, rolling and sliding contacts mixed
        column, size = fixed_modes.columns(kind, n, scene.dimension - 1)
        x = rng.normal(size=size)
        for got, want in zip(
            fixed_modes._system_numpy(data.J, data.b, data.mu, data.g, x, kind, column, n),
            fixed_modes.system(data.J, data.b, data.mu, data.g, x, kind, column, n),
            strict=True,
        ):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)
