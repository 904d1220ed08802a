"""Invariances of the answer (hypothesis): world frame, units, speed scale, a stationary robot.

The base scenes have a unique motion and unique forces: one free body or two,
2-D and 3-D, with fixed, twist-driven and robot-driven movers and applied
wrenches; one of them frictional (sliding and rolling contacts), solved by
the default method (the fast path when it finds an audited motion).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import quasistatic as qs
from catalogue import laws_hold

G = 9.81
ALPHA = math.radians(30.0)
T2 = [math.cos(ALPHA), math.sin(ALPHA)]  # uphill along the 2-D slope
N2 = [-math.sin(ALPHA), math.cos(ALPHA)]  # slope normal


def _along(x: float, y: float) -> list[float]:
    """World point of 2-D slope coordinates (x along T2, y along N2)."""
    return [x * T2[0] + y * N2[0], x * T2[1] + y * N2[1]]


def _c(body: str, other: str, point: list[float], normal: list[float], **extra: Any) -> dict[str, Any]:
    return {"body": body, "other": other, "point": point, "normal": normal, **extra}


def slope_robot_2d() -> dict[str, Any]:
    """Block on a slope with an applied wrench, pushed uphill by a one-joint (prismatic) robot finger."""
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [0.0, -G],
        "friction": "none",
        "bodies": {"block": {"mass": 2.0, "com": _along(0.0, 0.1), "wrench": [0.3, -0.2, 0.05]}},
        "movers": {"slope": {}, "finger": {"robot": "arm"}},
        "robots": {"arm": {"joint_velocities": [0.05]}},
        "contacts": [
            _c("block", "slope", _along(-0.2, 0.0), N2),
            _c("block", "slope", _along(0.2, 0.0), N2),
            _c("block", "finger", _along(-0.2, 0.05), T2, jacobian=[[T2[0]], [T2[1]]]),
        ],
    }


def stack_2d() -> dict[str, Any]:
    """Box B on box A on a slope; a stop perpendicular to the slope pushes both uphill (a twist mover)."""
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [0.0, -G],
        "friction": "none",
        "bodies": {"A": {"mass": 2.0, "com": _along(0.2, 0.1)}, "B": {"mass": 1.0, "com": _along(0.1, 0.3)}},
        "movers": {"slope": {}, "stop": {"twist": [0.1 * T2[0], 0.1 * T2[1], 0.0], "origin": [0.3, -0.1]}},
        "contacts": [
            _c("A", "slope", _along(0.0, 0.0), N2),
            _c("A", "slope", _along(0.4, 0.0), N2),
            _c("A", "stop", _along(0.0, 0.05), T2),
            _c("B", "A", _along(0.0, 0.2), N2),
            _c("B", "A", _along(0.2, 0.2), N2),
            _c("B", "stop", _along(0.0, 0.25), T2),
        ],
    }


def fixture_3d() -> dict[str, Any]:
    """3-2-1 fixture: three floor points, two on a robot-driven pusher wall (x), one on a y wall.

    Gravity leans into all three planes; the pusher (two prismatic joints: x,
    and z along its own face) moves the box in +x while sliding along it; the
    y wall turns about a vertical axis away from its contact point's line.
    """
    jacobian = [[1.0, 0.0], [0.0, 0.0], [0.0, 0.5]]
    return {
        "quasistatic": 1,
        "dimension": 3,
        "gravity": [-2.0, -1.5, -9.81],
        "friction": "none",
        "bodies": {"box": {"mass": 1.5, "com": [0.2, 0.15, 0.1], "wrench": [0.1, 0.2, -0.3, 0.01, -0.02, 0.03]}},
        "movers": {
            "floor": {},
            "ywall": {"twist": [0.0, 0.0, 0.01, 0.0, 0.05, 0.0], "origin": [0.2, 0.0, 0.1]},
            "pusher": {"robot": "arm"},
        },
        "robots": {"arm": {"joint_velocities": [0.05, -0.02]}},
        "contacts": [
            _c("box", "floor", [0.05, 0.05, 0.0], [0.0, 0.0, 1.0]),
            _c("box", "floor", [0.35, 0.05, 0.0], [0.0, 0.0, 1.0]),
            _c("box", "floor", [0.2, 0.25, 0.0], [0.0, 0.0, 1.0]),
            _c("box", "pusher", [0.0, 0.05, 0.1], [1.0, 0.0, 0.0], jacobian=jacobian),
            _c("box", "pusher", [0.0, 0.25, 0.1], [1.0, 0.0, 0.0], jacobian=jacobian),
            _c("box", "ywall", [0.2, 0.0, 0.1], [0.0, 1.0, 0.0]),
        ],
    }


def friction_slope_2d() -> dict[str, Any]:
    """Frictional: a block pushed up a 20 degree slope (mu = 0.5) by a frictionless finger.

    Both slope contacts slide and the finger rolls; three normal forces meet three equations of
    equilibrium, so the forces are unique. (With friction at the finger as well, its tangential force
    would trade against the supports' normal forces: a one-parameter family, forces indeterminate.)
    """
    alpha = math.radians(20.0)
    t, n = [math.cos(alpha), math.sin(alpha)], [-math.sin(alpha), math.cos(alpha)]
    at = lambda x, y: [x * t[0] + y * n[0], x * t[1] + y * n[1]]  # noqa: E731
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [0.0, -G],
        "bodies": {"block": {"mass": 1.0, "com": at(0.0, 0.05), "wrench": [0.3, -0.2, 0.01]}},
        "movers": {"slope": {}, "finger": {"twist": [0.01 * t[0], 0.01 * t[1], 0.0]}},
        "contacts": [
            _c("block", "slope", at(-0.1, 0.0), n, mu=0.5),
            _c("block", "slope", at(0.1, 0.0), n, mu=0.5),
            _c("block", "finger", at(-0.1, 0.03), t),
        ],
    }


BASES: dict[str, Callable[[], dict[str, Any]]] = {
    "friction-slope-2d": friction_slope_2d,
    "slope-robot-2d": slope_robot_2d,
    "stack-2d": stack_2d,
    "fixture-3d": fixture_3d,
}


FRICTIONAL = {"friction-slope-2d"}


def solve(data: dict[str, Any]) -> qs.Solution:
    return qs.solve(qs.load_scene(data))


def twists(sol: qs.Solution) -> dict[str, np.ndarray]:
    return {name: np.asarray(t, dtype=float) for name, t in sol.twists.items()}


def forces(sol: qs.Solution) -> np.ndarray:
    return np.array([c.force for c in sol.contacts], dtype=float)


def normal_forces(sol: qs.Solution) -> np.ndarray:
    return np.array([c.normal_force for c in sol.contacts])


def close(actual: Any, expected: Any, scale: float) -> None:
    """Equal to 1e-6 relative, or 1e-8 of the quantity's own scale."""
    np.testing.assert_allclose(np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), rtol=1e-6, atol=1e-8 * scale)


def magnitude(values: Any) -> float:
    return float(np.max(np.abs(np.asarray(values, dtype=float)), initial=0.0)) or 1.0


@pytest.fixture(scope="module")
def reference() -> dict[str, qs.Solution]:
    return {name: solve(build()) for name, build in BASES.items()}


@pytest.mark.parametrize("name", list(BASES))
def test_base_scene_is_solved_with_unique_forces(name: str, reference: dict[str, qs.Solution]) -> None:
    sol = reference[name]
    assert sol.status == "solved", sol.message
    assert not sol.forces_indeterminate
    assert sol.audit is not None and sol.audit.passed
    laws_hold(qs.load_scene(BASES[name]()), sol.motion)  # the reference obeys the laws, checked from the scene alone
    assert np.all(normal_forces(sol) > 0.1)  # every contact loaded: the answer is not near a mode switch
    assert any(np.any(np.abs(t) > 1e-3) for t in twists(sol).values())  # it moves


# --------------------------------------------------------------------------- rigid change of world frame


def rotation_2d(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def rotation_3d(quaternion: list[float]) -> np.ndarray:
    w, x, y, z = np.asarray(quaternion) / np.linalg.norm(quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rotate_twist(R: np.ndarray, twist: Any) -> np.ndarray:
    """[v, omega] in the new frame: v rotated; omega rotated in 3-D, unchanged (a z scalar) in 2-D."""
    twist = np.asarray(twist, dtype=float)
    d = R.shape[0]
    return np.r_[R @ twist[:d], R @ twist[d:] if d == 3 else twist[d:]]


def transform_rigid(data: dict[str, Any], R: np.ndarray, p: np.ndarray) -> dict[str, Any]:
    """The same scene seen from a frame rotated by R and shifted by p: x -> R x + p."""
    out = copy.deepcopy(data)
    d = R.shape[0]

    def place(x: Any) -> list[float]:
        return (R @ np.asarray(x, dtype=float) + p).tolist()

    out["gravity"] = (R @ np.asarray(data["gravity"])).tolist()
    for body in out["bodies"].values():
        body["com"] = place(body["com"])
        if "wrench" in body:
            body["wrench"] = rotate_twist(R, body["wrench"]).tolist()  # force rotates; moment like omega
    for mover in out["movers"].values():
        if mover and "twist" in mover:
            mover["twist"] = rotate_twist(R, mover["twist"]).tolist()
            mover["origin"] = place(mover.get("origin", np.zeros(d)))
    for contact in out["contacts"]:
        contact["point"] = place(contact["point"])
        contact["normal"] = (R @ np.asarray(contact["normal"])).tolist()
        if "jacobian" in contact:
            contact["jacobian"] = (R @ np.asarray(contact["jacobian"])).tolist()
    return out


@st.composite
def frames(draw: st.DrawFn, dimension: int) -> tuple[np.ndarray, np.ndarray]:
    if dimension == 2:
        R = rotation_2d(draw(st.floats(min_value=-math.pi, max_value=math.pi)))
    else:
        q = draw(st.lists(st.floats(min_value=-1.0, max_value=1.0), min_size=4, max_size=4).filter(lambda v: np.linalg.norm(v) > 0.1))
        R = rotation_3d(q)
    p = np.array(draw(st.lists(st.floats(min_value=-20.0, max_value=20.0), min_size=dimension, max_size=dimension)))
    return R, p


@st.composite
def scene_and_frame(draw: st.DrawFn) -> tuple[str, np.ndarray, np.ndarray]:
    name = draw(st.sampled_from(list(BASES)))
    R, p = draw(frames(BASES[name]()["dimension"]))
    return name, R, p


def test_rotation_helpers_are_rotations() -> None:
    R = rotation_3d([0.3, -0.2, 0.9, 0.1])
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0)
    # omega x r rotates as R omega x R r: the twist rule used above.
    omega, r = np.array([0.1, -0.4, 0.3]), np.array([1.0, 2.0, -0.5])
    np.testing.assert_allclose(np.cross(R @ omega, R @ r), R @ np.cross(omega, r), atol=1e-14)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene_and_frame())
def test_rigid_change_of_frame(reference: dict[str, qs.Solution], case: tuple[str, np.ndarray, np.ndarray]) -> None:
    """Status unchanged, twists rotated, force vectors rotated, normal forces and powers equal."""
    name, R, p = case
    before = reference[name]
    after = solve(transform_rigid(BASES[name](), R, p))
    assert after.status == before.status, after.message
    assert after.audit is not None and after.audit.passed
    assert after.modes == before.modes
    for body, twist in twists(before).items():
        close(twists(after)[body], rotate_twist(R, twist), magnitude(twist))
    f_scale = magnitude(forces(before))
    close(normal_forces(after), normal_forces(before), f_scale)
    close(forces(after), forces(before) @ R.T, f_scale)
    close(after.power.input, before.power.input, magnitude(before.power.input))


# --------------------------------------------------------------------------- units


def transform_units(data: dict[str, Any], s_l: float, s_m: float, s_t: float) -> dict[str, Any]:
    """The same scene in other units: lengths x s_l, masses x s_m, times x s_t.

    Velocity s_l/s_t, angular velocity 1/s_t, acceleration s_l/s_t^2, force
    s_m s_l/s_t^2, moment s_m s_l^2/s_t^2. Joints are prismatic (length/time),
    so the jacobians are dimensionless and unchanged.
    """
    out = copy.deepcopy(data)
    d = data["dimension"]
    force, moment, speed, spin = s_m * s_l / s_t**2, s_m * s_l**2 / s_t**2, s_l / s_t, 1.0 / s_t
    out["gravity"] = [x * s_l / s_t**2 for x in data["gravity"]]
    for body in out["bodies"].values():
        body["mass"] *= s_m
        body["com"] = [x * s_l for x in body["com"]]
        if "wrench" in body:
            body["wrench"] = [x * force for x in body["wrench"][:d]] + [x * moment for x in body["wrench"][d:]]
    for mover in out["movers"].values():
        if mover and "twist" in mover:
            mover["twist"] = [x * speed for x in mover["twist"][:d]] + [x * spin for x in mover["twist"][d:]]
        if mover and "origin" in mover:
            mover["origin"] = [x * s_l for x in mover["origin"]]
    for robot in out.get("robots", {}).values():
        robot["joint_velocities"] = [x * speed for x in robot["joint_velocities"]]
    for contact in out["contacts"]:
        contact["point"] = [x * s_l for x in contact["point"]]
    return out


def check_units(name: str, before: qs.Solution, s_l: float, s_m: float, s_t: float) -> None:
    after = solve(transform_units(BASES[name](), s_l, s_m, s_t))
    assert after.status == before.status, after.message
    assert after.audit is not None and after.audit.passed
    assert after.modes == before.modes
    d = BASES[name]()["dimension"]
    for body, twist in twists(before).items():
        expected = np.r_[twist[:d] * s_l / s_t, twist[d:] / s_t]
        close(twists(after)[body], expected, magnitude(expected))
    force = s_m * s_l / s_t**2
    close(forces(after), forces(before) * force, magnitude(forces(before)) * force)
    power = force * s_l / s_t
    close(after.power.input, before.power.input * power, magnitude(before.power.input) * power)


@pytest.mark.parametrize("name", list(BASES))
def test_millimetres_and_grams(name: str, reference: dict[str, qs.Solution]) -> None:
    """m, kg, s -> mm, g, s: twists' linear part x 1000, angular unchanged, forces (g mm/s^2) x 1e6."""
    check_units(name, reference[name], 1000.0, 1000.0, 1.0)


_SCALE = st.floats(min_value=-3.0, max_value=3.0).map(lambda e: 10.0**e)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(list(BASES)), _SCALE, _SCALE, _SCALE)
def test_change_of_units(reference: dict[str, qs.Solution], name: str, s_l: float, s_m: float, s_t: float) -> None:
    check_units(name, reference[name], s_l, s_m, s_t)


# --------------------------------------------------------------------------- robot speed


def scale_mover_velocities(data: dict[str, Any], s: float) -> dict[str, Any]:
    """Every prescribed velocity (mover twists and joint velocities) times s."""
    out = copy.deepcopy(data)
    for mover in out["movers"].values():
        if mover and "twist" in mover:
            mover["twist"] = [x * s for x in mover["twist"]]
    for robot in out.get("robots", {}).values():
        robot["joint_velocities"] = [x * s for x in robot["joint_velocities"]]
    return out


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(list(BASES)), st.floats(min_value=-3.0, max_value=3.0).map(lambda e: 10.0**e))
def test_scaling_the_robot_speed_scales_the_motion_not_the_forces(reference: dict[str, qs.Solution], name: str, s: float) -> None:
    """Quasi-statics has no time scale: twists x s, forces unchanged, powers x s."""
    before = reference[name]
    after = solve(scale_mover_velocities(BASES[name](), s))
    assert after.status == before.status, after.message
    assert after.audit is not None and after.audit.passed
    assert after.modes == before.modes
    for body, twist in twists(before).items():
        close(twists(after)[body], twist * s, magnitude(twist) * s)
    close(forces(after), forces(before), magnitude(forces(before)))
    close(after.power.input, before.power.input * s, magnitude(before.power.input) * s)


# --------------------------------------------------------------------------- a stationary robot


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene_and_frame())
def test_stationary_robot_leaves_a_supported_object_at_rest(
    reference: dict[str, qs.Solution], case: tuple[str, np.ndarray, np.ndarray]
) -> None:
    """All movers fixed, in any world frame: every twist is zero, every contact rolls.

    In the frictionless scenes every contact stays loaded when the robot
    moves, so the forces at rest are those of the moving case (statics does
    not see speed). With friction they are not: at rest the friction forces
    are static and the normal forces need not be those of the sliding case.
    """
    name, R, p = case
    data = transform_rigid(scale_mover_velocities(BASES[name](), 0.0), R, p)
    sol = solve(data)
    assert sol.status == "solved", sol.message
    assert sol.audit is not None and sol.audit.passed
    for twist in twists(sol).values():
        close(twist, np.zeros_like(twist), 1.0)
    assert set(sol.modes) == {"rolling"}
    before = reference[name]
    if name not in FRICTIONAL:
        close(normal_forces(sol), normal_forces(before), magnitude(forces(before)))
    assert sol.power.input == pytest.approx(0.0, abs=1e-9)
    assert sol.power.gravity == pytest.approx(0.0, abs=1e-9)
