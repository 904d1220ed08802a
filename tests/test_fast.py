"""The fast path: Lemke's method (unit tests on textbook LCPs) and the ``fast`` backend.

The backend finds one motion and proves nothing: wherever the certified search
says ``solved`` it must give the same twist (or report ``failed``), and it
must never report a motion where no motion exists. Expected twists of the
off-axis push are derived in its docstring, not taken from the library.
"""

from __future__ import annotations

import itertools
import math
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.backends.base import Options
from quasistatic.backends.fast import solve_fast
from quasistatic.backends.lemke import PIVOT_LIMIT, RAY, SOLUTION, lemke
from quasistatic.validation import load_cases, scene_data

ROOT = Path(__file__).resolve().parents[1]
G = 9.81
TOL = 1e-11

# --------------------------------------------------------------------------- Lemke's method

LEMKE_VARIANTS = [pytest.param(lemke, id="compiled"), pytest.param(getattr(lemke, "py_func", lemke), id="python")]


def _solve_lcp(solver: Any, M: np.ndarray, q: np.ndarray, max_pivots: int = 1000) -> tuple[int, np.ndarray, int]:
    status, z, pivots, _ = solver(np.asarray(M, float), np.asarray(q, float), np.ones(len(q)), max_pivots, TOL)
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
    """Certified ``solved``: the same twist (or ``failed``); jammed/unstable: ``failed``; never another status."""
    problem = qs.assemble(qs.load_scene(path))
    certified = qs.solve(problem, method="scip")
    fast = qs.solve(problem, method="fast")
    assert fast.status in ("solved", "failed"), fast.message
    if fast.status == "failed":
        assert fast.message.startswith("failed:")
        return
    assert certified.status in ("solved", "ambiguous"), f"fast found a motion where scip says {certified.status}"
    assert fast.audit is not None and fast.audit.passed, fast.audit
    assert fast.details["uniqueness"] == "not checked"
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
    assert fast.status in ("solved", "failed"), fast.message
    if fast.status == "failed":
        return
    assert expected in ("solved", "ambiguous"), f"fast found a motion where the case expects {expected}"
    assert fast.audit is not None and fast.audit.passed, fast.audit
    if expected == "solved":
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
def test_no_motion_is_reported_as_failed_never_as_a_verdict(name: str, expected: str) -> None:
    problem = qs.assemble(qs.load_scene(ROOT / name))
    assert qs.solve(problem, method="scip").status == expected
    fast = qs.solve(problem, method="fast")
    assert fast.status == "failed" and "secondary ray" in fast.message


@pytest.mark.parametrize("name", ["examples/two_finger_lift.yaml", "examples/squeeze.yaml", "examples/box_push_3d.yaml"])
def test_frictionless_scenes(name: str) -> None:
    """No contact has edges (mu = 0): Lemke on normal forces alone; one audited motion."""
    sol = qs.solve(qs.assemble(qs.load_scene(ROOT / name)), method="fast")
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed
    assert set(sol.details) >= {"uniqueness", "method", "pivots", "realignments"}


def test_runs_without_numba() -> None:
    """With numba made unimportable, the kernels run as plain Python and give the same answer."""
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
    low = qs.solve(qs.load_scene(ROOT / "validation" / "scenes" / "box_push_low.yaml"), method="fast")
    assert [float(x) for x in lines[0].split()] == pytest.approx(list(low.twists["box"]), abs=1e-12)
    assert [float(x) for x in lines[1].split()] == pytest.approx([0.01 * math.cos(math.pi / 6), 0.005, 0, 0, 0, 0], abs=1e-9)
