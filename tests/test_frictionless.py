"""Frictionless behaviour the catalogue does not cover: ``friction: none``, no contact, 3-D extrusion, robots, properties.

The hand-derived frictionless cases (the held block on a slope, toppling,
pushing into a wall, two-finger lifts, squeezes, continua, a stack of boxes,
the 3-D held block) live in ``catalogue.py`` and run over every method in
``test_catalogue.py``. Each test here derives the expected twist, forces and
modes in its docstring; the numbers asserted are those closed-form
expressions, never the library's output. The method-parametrised tests run
over every method that certifies frictionless answers (``catalogue.methods``).

Conventions: the contact normal points into ``body``, the force acts on
``body``; twists are ``[vx, vy, wz]`` (2-D) or ``[v, omega]`` (3-D) of the com.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

import quasistatic as qs
from catalogue import Method, held_slope_3d_data, methods

G = 9.81
REL, ABS = 1e-6, 1e-9


@pytest.fixture(params=methods(frictional=False, certifying=True), ids=str)
def method(request: pytest.FixtureRequest) -> Method:
    return request.param  # type: ignore[no-any-return]


def approx(expected: Any, abs: float = ABS) -> Any:  # noqa: A002 - mirrors pytest.approx
    if isinstance(expected, np.ndarray):
        expected = expected.tolist()
    return pytest.approx(expected, rel=REL, abs=abs)


def floats(array: Any) -> list[float]:
    return [float(x) for x in np.asarray(array).ravel()]


def solve(data: dict[str, Any], method: Method) -> qs.Solution:
    return method.solve(qs.load_scene(data))


def normal_forces(sol: qs.Solution) -> list[float]:
    return [c.normal_force for c in sol.contacts]


def check_solved(sol: qs.Solution, *, indeterminate: bool = False) -> None:
    """Solved, audited, power balanced; force ranges only when the forces are indeterminate."""
    assert sol.status == "solved", sol.message
    assert sol.ok
    assert sol.audit is not None and sol.audit.passed, sol.audit
    assert sol.power is not None and sol.power.residual == approx(0.0, abs=1e-9)
    assert sol.power.dissipation == approx(0.0, abs=1e-9)  # frictionless: nothing is lost
    assert sol.forces_indeterminate is indeterminate
    assert sol.solutions == ()
    for contact in sol.contacts:
        assert (contact.normal_force_range is not None) is indeterminate


def check_force(contact: qs.ContactResult, normal: Any, magnitude: float) -> None:
    """Frictionless: the force is ``magnitude`` along the contact normal, nothing tangential."""
    assert contact.normal_force == approx(magnitude)
    assert floats(contact.force) == approx(floats(magnitude * np.asarray(normal, dtype=float)))


def base(dimension: int = 2, **extra: Any) -> dict[str, Any]:
    gravity = [0.0, -G] if dimension == 2 else [0.0, -G, 0.0]
    return {"quasistatic": 1, "dimension": dimension, "gravity": gravity, "friction": "none", **extra}


def contact(body: str, other: str, point: Any, normal: Any, **extra: Any) -> dict[str, Any]:
    return {"body": body, "other": other, "point": floats(point), "normal": floats(normal), **extra}


# --------------------------------------------------------------------------- a block on a slope, held by a finger

ALPHA = math.radians(30.0)
T = np.array([math.cos(ALPHA), math.sin(ALPHA)])  # uphill along the slope
N = np.array([-math.sin(ALPHA), math.cos(ALPHA)])  # slope normal, into the block
W, H, M = 0.4, 0.2, 2.0  # block width along the slope, height, mass
YF = H / 4  # finger height above the slope on the downhill face


def slope_scene(speed: float = 0.0, mu: float = 0.0, friction: str = "none") -> dict[str, Any]:
    """Block on a fixed frictionless slope; a finger on its downhill face moving uphill at ``speed``.

    Block frame: origin at the middle of its bottom face (the world origin),
    x along T, y along N. Slope contacts at x = -W/2 and +W/2, finger at
    (-W/2, YF) with normal +T.
    """
    return base(
        friction=friction,
        bodies={"block": {"mass": M, "com": floats(H / 2 * N)}},
        movers={"slope": {}, "finger": {"twist": [*floats(speed * T), 0.0]}},
        contacts=[
            contact("block", "slope", -W / 2 * T, N, mu=mu),
            contact("block", "slope", W / 2 * T, N, mu=mu),
            contact("block", "finger", -W / 2 * T + YF * N, T, mu=mu),
        ],
    )


def slope_forces() -> tuple[float, float, float]:
    """(N1, N2, F) from statics, in the block frame (x along T, y along N, origin at bottom middle).

    along T:  F - M g sin(a) = 0                      ->  F = M g sin(a)
    along N:  N1 + N2 - M g cos(a) = 0
    moment about the origin (r_x f_y - r_y f_x):
        N1 at (-W/2, 0): -W/2 N1;  N2 at (W/2, 0): +W/2 N2;  F at (-W/2, YF): -YF F
        gravity (-M g sin a, -M g cos a) at (0, H/2): +H/2 M g sin(a)
      -> N2 - N1 = 2 F (YF - H/2) / W
    """
    F = M * G * math.sin(ALPHA)
    difference = 2.0 * F * (YF - H / 2) / W
    total = M * G * math.cos(ALPHA)
    return (total - difference) / 2, (total + difference) / 2, F


def test_slope_forces_are_positive() -> None:
    """The design keeps every contact loaded (else the case would not be unique)."""
    assert min(slope_forces()) > 1.0


def test_friction_none_ignores_mu(method: Method) -> None:
    """``friction: none`` drops friction on purpose: the same answer as mu = 0."""
    s = 0.05
    sol = solve(slope_scene(s, mu=0.8, friction="none"), method)
    check_solved(sol)
    assert sol.friction == "none"
    assert floats(sol.twists["block"]) == approx([*floats(s * T), 0.0])
    for c, normal, force in zip(sol.contacts, (N, N, T), slope_forces(), strict=True):
        check_force(c, normal, force)  # no tangential force although mu = 0.8


# --------------------------------------------------------------------------- 2-D and its 3-D extrusion

DEPTH = 0.3


def slope_scene_3d(speed: float, guides: bool = True) -> dict[str, Any]:
    """``slope_scene`` extruded along z, as the catalogue builds it (each contact at z = -DEPTH/2 and +DEPTH/2).

    Frictionless contacts whose normals all lie in the x-y plane leave vz free
    at no cost; with ``guides`` two fixed plates touch the front and back faces
    at the com (normals +z and -z) and pin vz = 0.
    """
    return held_slope_3d_data(speed, guides)


@pytest.mark.parametrize("speed", [0.0, 0.05])
def test_3d_extrusion_matches_2d(method: Method, speed: float) -> None:
    """The 3-D block moves as the 2-D one: twist (vx, vy, 0, 0, 0, wz); each pair sums to the 2-D force.

    In 3-D the four slope contacts are statically indeterminate: three
    equations (force along N, moments about T and z) for four forces, null
    vector (+1, -1, -1, +1) over (downhill z-, downhill z+, uphill z-, uphill z+).
    So each edge's sum is N1 (downhill) and N2 (uphill) as in 2-D, and with
    N2 < N1 the ranges are downhill [(N1 - N2)/2, (N1 + N2)/2], uphill [0, N2].
    The finger pair is determined: nothing else has a moment about N, so each
    carries F/2. The guides squeeze with any force in [0, inf).
    """
    flat = solve(slope_scene(speed), method)
    deep = solve(slope_scene_3d(speed), method)
    check_solved(flat)
    check_solved(deep, indeterminate=True)
    vx, vy, wz = floats(flat.twists["block"])
    assert floats(deep.twists["block"]) == approx([vx, vy, 0.0, 0.0, 0.0, wz])
    n1, n2, f = slope_forces()
    forces = normal_forces(deep)
    assert forces[0] + forces[1] == approx(n1)
    assert forces[2] + forces[3] == approx(n2)
    assert forces[4] + forces[5] == approx(f)
    pair_sums = [forces[2 * i] + forces[2 * i + 1] for i in range(3)]
    assert pair_sums == approx(normal_forces(flat))
    assert forces[6] == approx(forces[7])
    ranges = [c.normal_force_range for c in deep.contacts]
    assert ranges[0] == approx(((n1 - n2) / 2, (n1 + n2) / 2))
    assert ranges[1] == approx(((n1 - n2) / 2, (n1 + n2) / 2))
    assert ranges[2] == approx((0.0, n2))
    assert ranges[3] == approx((0.0, n2))
    assert ranges[4] == approx((f / 2, f / 2))
    assert ranges[5] == approx((f / 2, f / 2))
    for lo, hi in ranges[6:]:
        assert lo == approx(0.0) and hi is None
    assert [c.mode for c in deep.contacts[:6]] == [m for m in flat.modes for _ in range(2)]
    assert deep.power.input == approx(flat.power.input)
    assert deep.power.gravity == approx(flat.power.gravity)


# --------------------------------------------------------------------------- robot-driven finger


def test_robot_driven_finger_equals_the_same_twist(method: Method) -> None:
    """A one-joint prismatic robot whose joint moves the finger along T (jacobian = T) at rate s.

    The finger point's velocity J qdot = s T is the one of ``slope_scene(s)``,
    so the answer is the same: block twist (s T, 0), forces ``slope_forces``.
    """
    s = 0.05
    data = slope_scene()
    data["movers"]["finger"] = {"robot": "arm"}
    data["robots"] = {"arm": {"joint_velocities": [s]}}
    data["contacts"][2]["jacobian"] = [[T[0]], [T[1]]]
    sol = solve(data, method)
    check_solved(sol)
    assert floats(sol.twists["block"]) == approx([*floats(s * T), 0.0])
    assert normal_forces(sol) == approx(list(slope_forces()))


# --------------------------------------------------------------------------- property: random frictionless scenes


@st.composite
def random_scenes(draw: st.DrawFn) -> dict[str, Any]:
    """One or two bodies, up to six contacts, random mover twists, no friction.

    Points lie on a 0.1 grid and normals come from a finite set of directions
    (multiples of 15 degrees in 2-D, normalised integer vectors in 3-D): exact
    coincidences and parallel normals are frequent, near-degenerate data (a
    normal 1e-9 off an axis) is left to ``test_nearly_axis_normal_unstable_scene`` and
    ``test_nearly_axis_normal_under_a_large_force``.
    """
    dim = draw(st.sampled_from([2, 3]))
    k = 3 if dim == 2 else 6
    grid = st.integers(-10, 10).map(lambda i: i / 10)
    speed = st.integers(-5, 5).map(lambda i: i / 10)

    def point() -> list[float]:
        return draw(st.lists(grid, min_size=dim, max_size=dim))

    def direction() -> list[float]:
        if dim == 2:
            angle = math.radians(15 * draw(st.integers(0, 23)))
            return [math.cos(angle), math.sin(angle)]
        vector = np.array(draw(st.lists(st.integers(-2, 2), min_size=3, max_size=3)), dtype=float)
        if not vector.any():
            vector[2] = 1.0
        return floats(vector / np.linalg.norm(vector))

    names = ["a", "b"][: draw(st.integers(1, 2))]
    bodies = {n: {"mass": draw(st.integers(0, 5).map(float)), "com": point()} for n in names}
    movers = {f"m{i}": {"twist": draw(st.lists(speed, min_size=k, max_size=k))} for i in range(2)}
    contacts = []
    for _ in range(draw(st.integers(0, 6))):
        body = draw(st.sampled_from(names))
        other = draw(st.sampled_from([n for n in [*names, *movers] if n != body]))
        contacts.append(contact(body, other, point(), direction()))
    return base(dim, bodies=bodies, movers=movers, contacts=contacts)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_scenes())
def test_random_frictionless_scene_gives_an_audited_verdict(data: dict[str, Any]) -> None:
    """Any frictionless scene gets a verdict; a motion reported is audited (never ``failed``)."""
    sol = qs.solve(qs.load_scene(data))
    assert sol.status in ("solved", "ambiguous", "jammed", "unstable"), sol.message
    for motion in (sol.motion, *sol.solutions):
        if motion is not None:
            assert motion.audit.passed, motion.audit
            assert motion.power.residual == approx(0.0, abs=1e-6 * max(1.0, abs(motion.power.input)))


def _range_widths(problem: qs.Problem, sol: qs.Solution) -> list[float]:
    """Each closed contact's normal-force range width over ``{c >= 0 : Jn_C^T c = -g}`` (scene-relative), by linprog.

    Written from the force formulation directly (no library code): the forces of
    a unique motion are the equilibrium forces on the contacts it keeps closed.
    """
    from scipy.optimize import linprog

    closed = np.array([c.normal_velocity <= 1e-9 * problem.scales.velocity for c in sol.contacts], dtype=bool)
    A = np.asarray(problem.Jn)[closed].T
    widths = []
    for i in range(int(closed.sum())):
        cost = np.zeros(A.shape[1])
        cost[i] = 1.0
        low = linprog(cost, A_eq=A, b_eq=-np.asarray(problem.g), bounds=(0, None), method="highs")
        high = linprog(-cost, A_eq=A, b_eq=-np.asarray(problem.g), bounds=(0, None), method="highs")
        assert low.status == 0, low.message
        widths.append(math.inf if high.status == 3 else -high.fun - low.fun)
    return widths


@st.composite
def supported_boxes(draw: st.DrawFn) -> dict[str, Any]:
    """A box on a fixed table (2 or 3 to 6 support points on a grid, repeats allowed) between fixed walls,
    under gravity tilted by up to ~12 degrees, maybe touched by a still or retreating finger: mostly at rest,
    with unique or indeterminate forces (or toppling, or free to slide along a wall)."""
    dim = draw(st.sampled_from([2, 3]))
    k = 3 if dim == 2 else 6
    grid = st.integers(-2, 2).map(lambda i: i / 20)  # across the 0.2-wide bottom face
    height = st.integers(1, 3).map(lambda i: i / 40)  # up the 0.1-high side faces

    def spot() -> list[float]:
        return draw(st.lists(grid, min_size=dim - 1, max_size=dim - 1))

    contacts = [contact("box", "table", [*spot(), 0.0], [0.0] * (dim - 1) + [1.0]) for _ in range(draw(st.integers(dim, 6)))]
    for axis in range(dim - 1):
        for side in (-1.0, 1.0):
            for _ in range(draw(st.integers(dim - 1 if side > 0 else 0, 2))):  # one side may be open
                point = [*spot(), draw(height)]
                point[axis] = side * 0.1
                inward = [0.0] * dim
                inward[axis] = -side
                contacts.append(contact("box", "walls", point, inward))
    movers: dict[str, Any] = {"table": {}, "walls": {}}
    if draw(st.booleans()):
        push = [0.0] * k
        push[0] = -draw(st.integers(0, 2)) / 100  # still or retreating: pushing into the walls would jam
        movers["finger"] = {"twist": push}
        contacts.append(contact("box", "finger", [-0.1] + [0.0] * (dim - 2) + [0.05], [1.0] + [0.0] * (dim - 1)))
    tilt = draw(st.lists(st.integers(-2, 2), min_size=dim - 1, max_size=dim - 1))
    com = [*spot(), 0.05]
    return base(dim, gravity=[*map(float, tilt), -G], bodies={"box": {"mass": 1.0, "com": com}}, movers=movers, contacts=contacts)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(st.one_of(supported_boxes(), random_scenes()))
def test_forces_indeterminate_exactly_when_some_range_is_wide(data: dict[str, Any]) -> None:
    """The LP path decides ``forces_indeterminate`` by a rank test, without the ranges (they are worked out
    when read); it must say True exactly when some normal-force range has positive width."""
    problem = qs.assemble(qs.load_scene(data))
    sol = qs.solve(problem, method="lp")
    assume(sol.status == "solved")
    wide = any(w > 1e-7 for w in _range_widths(problem, sol))
    event(f"forces indeterminate: {wide}")
    assert sol.forces_indeterminate is wide
    ranges = [c.normal_force_range for c in sol.contacts]  # read: worked out now
    if wide:
        known = [r for r in ranges if r is not None]
        assert len(known) == len(ranges)
        assert any(hi is None or hi - lo > 1e-7 * problem.scales.force for lo, hi in known)
    else:
        assert all(r is None for r in ranges)


def test_nearly_axis_normal_unstable_scene() -> None:
    """Massless ``a`` caged on heavy ``b`` (normals +y, -x, ~-y), ``a`` on a fixed ramp (1, -1)/sqrt 2.

    Both bodies falling together (twists (0, -1, 0) each) keeps every contact
    closed or opening and lets gravity do work: unstable. Found by
    ``test_random_frictionless_scene_gives_an_audited_verdict`` with real-valued
    normals; the 2e-9 tilt used to fail the certificate check (checked to 1e-9, HiGHS meets 1e-7).
    """
    r = 1 / math.sqrt(2)
    data = base(
        bodies={"a": {"mass": 0.0, "com": [0.0, 0.0]}, "b": {"mass": 1.0, "com": [0.0, 0.0]}},
        movers={"ramp": {}},
        contacts=[
            contact("a", "b", [0.0, 0.0], [0.0, 1.0]),
            contact("a", "b", [0.0, 0.0], [-1.0, 0.0]),
            contact("a", "b", [0.0, 0.0], [2e-9, -1.0]),
            contact("a", "ramp", [0.0, 0.0], [r, -r]),
        ],
    )
    sol = qs.solve(qs.load_scene(data))
    assert sol.status == "unstable", sol.message


def test_prescribed_modes_are_honoured_or_refused() -> None:
    """Box on two frictionless fingertips rising at 0.01 m/s (rolling both) with side walls.

    Prescribing 'separating' at a lifting fingertip leaves no motion (the other
    finger cannot lift the box alone without tipping it into a wall): the
    answer must then be `jammed`, never the unprescribed motion.
    """
    scene = qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 2,
            "bodies": {"box": {"mass": 0.5, "com": [0.0, 0.05]}},
            "movers": {"f": {"twist": [0.0, 0.01, 0.0]}, "wall": {}},
            "contacts": [
                {"body": "box", "other": "f", "point": [-0.04, 0.0], "normal": [0.0, 1.0]},
                {"body": "box", "other": "f", "point": [0.04, 0.0], "normal": [0.0, 1.0]},
                {"body": "box", "other": "wall", "point": [-0.05, 0.05], "normal": [1.0, 0.0]},
                {"body": "box", "other": "wall", "point": [0.05, 0.05], "normal": [-1.0, 0.0]},
            ],
        }
    )
    free = qs.solve(scene)
    assert free.status == "solved"
    assert free.modes[:2] == ("rolling", "rolling")
    rolling = qs.solve(scene, modes=["rolling", "rolling", None, None])
    assert rolling.status == "solved"
    assert rolling.twists["box"] == pytest.approx([0.0, 0.01, 0.0], abs=1e-9)
    lifted_off = qs.solve(scene, modes=["separating", None, None, None])
    assert lifted_off.status == "jammed"
    with pytest.raises(ValueError, match="modes"):
        qs.solve(scene, method="lp", modes=["rolling"] * 4)


@pytest.mark.parametrize(
    "tilt",
    # HiGHS drops matrix entries below small_matrix_value: the backend lowers it to 1e-12, so these are kept.
    [0.0, 1e-13, 3e-11, 1e-10, 1e-9, 3e-9, 1e-6],
)
def test_nearly_axis_normal_under_a_large_force(tilt: float) -> None:
    """Block (com (1, 1), mass 1) pinned at the origin by a fixed corner, turned by a turntable.

    Contacts: at O = (0, 0) normals (1, tilt) ~ +x and (0, 1), both fixed; at
    P = (0, y), y = 1/256, normal -x from a turntable spinning at w = 0.5 about
    the world origin (its point at P moves at w x P = (-w y, 0)).
    Statics, with n0 = (1, tilt) / sqrt(1 + tilt^2) = (c, tilt c):
        moment about O: y F2 - m g (1) = 0  -> F2 = m g / y = 256 m g
        x: F0 c - F2 = 0                     -> F0 = F2 / c
        y: F0 tilt c + F1 - m g = 0          -> F1 = m g - tilt F2
    All three forces are positive and the 3 x 3 system is nonsingular, so every
    contact is active: O does not move, and P moves at -w y in x, which makes
    the block turn with the turntable: wz = w, v_com = w x (1, 1) = (-w, w).
    """
    w, y = 0.5, 1 / 256
    data = base(
        bodies={"a": {"mass": 1.0, "com": [1.0, 1.0]}},
        movers={"fixed": {}, "turntable": {"twist": [0.0, 0.0, w]}},
        contacts=[
            contact("a", "fixed", [0.0, 0.0], [1.0, tilt]),
            contact("a", "fixed", [0.0, 0.0], [0.0, 1.0]),
            contact("a", "turntable", [0.0, y], [-1.0, 0.0]),
        ],
    )
    sol = qs.solve(qs.load_scene(data))
    check_solved(sol)
    assert floats(sol.twists["a"]) == approx([-w, w, w], abs=1e-6)
    f2 = G / y
    assert normal_forces(sol) == approx([f2 * math.hypot(1.0, tilt), G - tilt * f2, f2], abs=1e-6)


@pytest.mark.parametrize("x", [1e-267, 1e-3, 5.0, 1e30])  # 1e30: the largest magnitude a scene may hold
def test_single_point_scene_at_any_distance_from_the_origin(x: float) -> None:
    """Com and contact coincide at (x, x): only the distance from the origin sets a length scale.

    Supported from below, the weight passes through the contact: the body may turn about it
    at any rate, a frictionless continuum (ambiguous). Touched from the side, nothing holds
    the weight: unstable. Extreme coordinates must not underflow the scales into NaN.
    """
    data = base(
        bodies={"a": {"mass": 1.0, "com": [x, x]}},
        movers={"fixed": {}},
        contacts=[contact("a", "fixed", [x, x], [0.0, 1.0])],
    )
    assert qs.solve(qs.load_scene(data)).status == "ambiguous"
    data["contacts"][0]["normal"] = [1.0, 0.0]
    assert qs.solve(qs.load_scene(data)).status == "unstable"


def test_rank_tests_of_rank_deficient_normals_give_the_svds_singular_values_without_overflow() -> None:
    """The LP's rank test (one-sided Jacobi rotations) on a box's four table points (random scene 3-D 65, frictionless:
    rank 3 in 4 x 6) and on random matrices of rank 2 to 4: a column rotated to nearly zero made the rotation's
    ``zeta ** 2`` overflow (a numpy warning on random frictionless scenes without numba)."""
    from quasistatic.solvers import lp

    kernel = getattr(lp._singular_values, "py_func", lp._singular_values)  # the plain-Python kernel, as without numba
    a, b = 0.7143988317914549, 0.6840701033419289
    table = np.array([[0.0, 0.0, 1.0, x, y, 0.0] for x, y in ((-a, b), (a, b), (-a, -b), (a, -b))])
    rng = np.random.default_rng(7)
    matrices = [table] + [rng.normal(size=(4, r)) @ rng.normal(size=(r, 6)) for r in (2, 3, 4) for _ in range(30)]
    for A in matrices:
        with np.errstate(over="raise", divide="raise", invalid="raise"):  # underflow is round-off, as numpy holds
            got = np.sort(kernel(A))[::-1]
        want = np.linalg.svd(A, compute_uv=False)
        np.testing.assert_allclose(got[:4], want, atol=1e-12 * want[0])


def test_random_frictionless_scenes_solve_without_numba_and_without_a_warning() -> None:
    """Random 3-D frictionless scenes 65, 109 and 141 printed "overflow encountered in scalar multiply" from the LP's
    rank test when numba was missing (what plain ``pip install`` gives): run with warnings as errors."""
    code = textwrap.dedent(
        """
        import sys
        sys.modules["numba"] = None  # import numba now raises ImportError
        sys.path.insert(0, "tests")
        import quasistatic as qs
        from random_scenes import random_scene
        for seed in (65, 109, 141):
            solution = qs.solve(random_scene(3, seed, friction="none"))
            print(seed, solution.status)
        """
    )
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, "-W", "error", "-c", code], capture_output=True, text=True, timeout=300, cwd=root)
    assert out.returncode == 0 and out.stderr == "", out.stderr[-2000:]
    statuses = [line.split()[1] for line in out.stdout.splitlines()]
    assert len(statuses) == 3 and "failed" not in statuses, out.stdout
