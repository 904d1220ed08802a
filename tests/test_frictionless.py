"""Frictionless cases with answers derived by hand from statics and the minimum-power principle.

Each test derives the expected twist, forces and modes in its docstring; the
numbers asserted are those closed-form expressions, never the library's output.
Every case runs over each method that handles frictionless contacts.

Conventions: the contact normal points into ``body``, the force acts on
``body``; twists are ``[vx, vy, wz]`` (2-D) or ``[v, omega]`` (3-D) of the com.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import quasistatic as qs

G = 9.81
REL, ABS = 1e-6, 1e-9


@pytest.fixture(params=["auto", "lp"])
def method(request: pytest.FixtureRequest) -> str:
    return str(request.param)


def approx(expected: Any, abs: float = ABS) -> Any:  # noqa: A002 - mirrors pytest.approx
    if isinstance(expected, np.ndarray):
        expected = expected.tolist()
    return pytest.approx(expected, rel=REL, abs=abs)


def floats(array: Any) -> list[float]:
    return [float(x) for x in np.asarray(array).ravel()]


def solve(data: dict[str, Any], method: str) -> qs.Solution:
    return qs.solve(qs.load_scene(data), method=method)


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


def test_block_on_slope_held_by_a_stationary_finger(method: str) -> None:
    """At rest: twist 0, forces (N1, N2, F) of ``slope_forces``, all contacts rolling.

    The three contact wrenches are independent (a 3 x 3 nonsingular system) and
    all three forces are positive, so the velocity LP has a unique optimum with
    every constraint active: Jn q = 0 -> q = 0.
    """
    sol = solve(slope_scene(), method)
    check_solved(sol)
    assert floats(sol.twists["block"]) == approx([0.0, 0.0, 0.0])
    n1, n2, f = slope_forces()
    check_force(sol.contacts[0], N, n1)
    check_force(sol.contacts[1], N, n2)
    check_force(sol.contacts[2], T, f)
    assert sol.modes == ("rolling", "rolling", "rolling")
    assert sol.power.input == approx(0.0) and sol.power.gravity == approx(0.0)


def test_finger_pushes_block_up_the_slope(method: str) -> None:
    """The finger moves uphill at s: the block translates with it, the forces are unchanged.

    Kinematics: slope contacts n.(v + w x r) >= 0 and finger t.(v + w x r) >= s.
    All three stay active (their multipliers are the positive forces of the
    static case: the equilibrium equations do not depend on velocities), so
    v.N = 0 at both slope points -> w = 0, v.N = 0; and v.T = s. Twist (s T, 0).
    Modes: slope contacts slide (slip s T), the finger rolls.
    Power: input F s = M g s sin(a) = rate of potential energy M g v_y.
    """
    s = 0.05
    sol = solve(slope_scene(s), method)
    check_solved(sol)
    assert floats(sol.twists["block"]) == approx([*floats(s * T), 0.0])
    n1, n2, f = slope_forces()
    check_force(sol.contacts[0], N, n1)
    check_force(sol.contacts[1], N, n2)
    check_force(sol.contacts[2], T, f)
    assert sol.modes == ("sliding", "sliding", "rolling")
    for c in sol.contacts[:2]:
        assert floats(c.slip) == approx(floats(s * T))
        assert c.normal_velocity == approx(0.0)
    assert floats(sol.contacts[2].slip) == approx([0.0, 0.0])
    potential_rate = M * G * s * math.sin(ALPHA)
    assert sol.power.input == approx(f * s)
    assert sol.power.input == approx(potential_rate)
    assert sol.power.gravity == approx(potential_rate)


def test_friction_none_ignores_mu(method: str) -> None:
    """``friction: none`` drops friction on purpose: the same answer as mu = 0."""
    s = 0.05
    sol = solve(slope_scene(s, mu=0.8, friction="none"), method)
    check_solved(sol)
    assert sol.friction == "none"
    assert floats(sol.twists["block"]) == approx([*floats(s * T), 0.0])
    assert normal_forces(sol) == approx(list(slope_forces()))


def test_block_on_a_frictionless_slope_without_finger_is_unstable(method: str) -> None:
    """Without the finger nothing balances M g sin(a) along the slope: it slides away.

    The twist d = (-T, 0) keeps both slope contacts closed (N.d = 0) and does
    positive work M g sin(a) > 0: the minimum-power LP is unbounded.
    """
    data = slope_scene()
    data["contacts"] = data["contacts"][:2]
    sol = solve(data, method)
    assert sol.status == "unstable", sol.message
    assert sol.motion is None and not sol.ok


def test_unsupported_block_is_unstable(method: str) -> None:
    """No contact at all: the block falls (d = (0, -1, 0) does work M g)."""
    data = base(bodies={"box": {"mass": 1.0, "com": [0.0, 0.5]}}, contacts=[])
    sol = solve(data, method)
    assert sol.status == "unstable", sol.message
    assert sol.motion is None


def test_block_on_one_fingertip_off_its_com_is_unstable(method: str) -> None:
    """One fingertip under the block, 0.1 left of the com: the block tips over.

    Rotating clockwise about the fingertip (w < 0) keeps the contact closed
    (point velocity 0) and lowers the com: v_y = w (x_com - x_tip) ... < 0.
    No quasi-static equilibrium: a single vertical force cannot balance the
    weight's moment about the tip.
    """
    data = base(
        bodies={"box": {"mass": 1.0, "com": [0.2, 0.1]}},
        movers={"finger": {}},
        contacts=[contact("box", "finger", [0.1, 0.0], [0.0, 1.0])],
    )
    sol = solve(data, method)
    assert sol.status == "unstable", sol.message


# --------------------------------------------------------------------------- jammed

BOX_W, BOX_H, BOX_M = 0.4, 0.2, 2.0


def box_on_table(*extra_contacts: dict[str, Any], movers: dict[str, Any] | None = None) -> dict[str, Any]:
    """A BOX_W x BOX_H box, com at (BOX_W/2, BOX_H/2), on a fixed table at its two bottom corners."""
    return base(
        bodies={"box": {"mass": BOX_M, "com": [BOX_W / 2, BOX_H / 2]}},
        movers={"table": {}, **(movers or {})},
        contacts=[
            contact("box", "table", [0.0, 0.0], [0.0, 1.0]),
            contact("box", "table", [BOX_W, 0.0], [0.0, 1.0]),
            *extra_contacts,
        ],
    )


def test_pushing_into_a_wall_is_jammed(method: str) -> None:
    """A fixed wall on the left face, a finger on the right face moving left, both at mid-height.

    Wall:   u_n = (+1, 0).(v_point) = vx >= 0 (rotation adds nothing at com height).
    Finger: u_n = (-1, 0).(v_point - (-s, 0)) = -vx - s >= 0 -> vx <= -s < 0.
    Contradiction: no admissible motion, the robot's command is jammed. The
    Farkas multipliers y = (0, 0, 1, 1) (wall + finger rows sum to 0 . q >= s) prove it.
    """
    s = 0.1
    data = box_on_table(
        contact("box", "wall", [0.0, BOX_H / 2], [1.0, 0.0]),
        contact("box", "finger", [BOX_W, BOX_H / 2], [-1.0, 0.0]),
        movers={"wall": {}, "finger": {"twist": [-s, 0.0, 0.0]}},
    )
    sol = solve(data, method)
    assert sol.status == "jammed", sol.message
    assert sol.motion is None and not sol.ok


def test_finger_pushing_a_box_off_centre_against_a_wall_tips_it(method: str) -> None:
    """Not jammed when the wall and finger act at different heights: the box can tip.

    Wall at (0, 0.05) on the left face, finger at (BOX_W, 0.15) on the right
    face moving left at s. Tipping about the bottom-left corner (w > 0 lifts
    the right corner) moves the finger point left at w (0.15 - 0) ... the
    motion exists, so the answer is not ``jammed`` (its exact form is
    checked by the audit).
    """
    s = 0.1
    data = box_on_table(
        contact("box", "wall", [0.0, 0.05], [1.0, 0.0]),
        contact("box", "finger", [BOX_W, 0.15], [-1.0, 0.0]),
        movers={"wall": {}, "finger": {"twist": [-s, 0.0, 0.0]}},
    )
    sol = solve(data, method)
    assert sol.status != "jammed", sol.message
    assert sol.audit is not None and sol.audit.passed


# --------------------------------------------------------------------------- two fingers lift a box

X1, X2 = 0.1, 0.35  # fingertips under the box (com at x = 0.2)
V1, V2 = 0.1, 0.3  # their upward speeds
R1, R2 = X1 - BOX_W / 2, X2 - BOX_W / 2  # -0.1, +0.15: the com is between them


def two_finger_lift(pins: bool) -> dict[str, Any]:
    """Box lifted by two fingertips under it; optionally two fixed pins at its mid-height, left and right."""
    contacts = [
        contact("box", "f1", [X1, 0.0], [0.0, 1.0]),
        contact("box", "f2", [X2, 0.0], [0.0, 1.0]),
    ]
    if pins:
        contacts += [
            contact("box", "pins", [0.0, BOX_H / 2], [1.0, 0.0]),
            contact("box", "pins", [BOX_W, BOX_H / 2], [-1.0, 0.0]),
        ]
    return base(
        bodies={"box": {"mass": BOX_M, "com": [BOX_W / 2, BOX_H / 2]}},
        movers={"f1": {"twist": [0.0, V1, 0.0]}, "f2": {"twist": [0.0, V2, 0.0]}, "pins": {}},
        contacts=contacts,
    )


def two_finger_answer() -> tuple[float, float, float, float]:
    """(vy, wz, N1, N2) of the minimum-power lift.

    Minimise the potential rate M g vy subject to vy + wz r_i >= v_i (r_i = x_i - x_com).
    With r1 < 0 < r2, lowering vy while keeping finger 2 closed needs wz as large
    as finger 1 allows, so both stay closed (the box tilts):
        wz = (v2 - v1) / (r2 - r1) = 0.2 / 0.25 = 0.8,   vy = v1 - wz r1 = 0.18.
    Forces (dual): N1 + N2 = M g, N1 r1 + N2 r2 = 0 (moment about the com)
        N1 = M g r2 / (r2 - r1) = 0.6 M g,   N2 = -M g r1 / (r2 - r1) = 0.4 M g.
    Both positive: neither finger separates, the faster one does not carry it all.
    Power: N1 v1 + N2 v2 = M g (r2 v1 - r1 v2) / (r2 - r1) = M g vy.
    """
    wz = (V2 - V1) / (R2 - R1)
    vy = V1 - wz * R1
    n1 = BOX_M * G * R2 / (R2 - R1)
    n2 = -BOX_M * G * R1 / (R2 - R1)
    return vy, wz, n1, n2


def test_two_fingers_lift_a_box_free_to_drift_sideways_is_ambiguous(method: str) -> None:
    """Frictionless and all normals vertical: vx costs no power and meets no contact.

    So the answer is an unbounded continuum in vx; vy, wz and the forces are
    those of ``two_finger_answer`` on every motion of it.
    """
    vy, wz, n1, n2 = two_finger_answer()
    sol = solve(two_finger_lift(pins=False), method)
    assert sol.status == "ambiguous", sol.message
    assert len(sol.solutions) == 1 and sol.solutions[0] is sol.motion
    motion = sol.solutions[0]
    assert motion.continuum and motion.unbounded
    assert motion.audit.passed
    assert floats(motion.twists["box"])[1:] == approx([vy, wz])
    assert motion.extreme_twists, "the bounded coordinates have extremes"
    for extreme in motion.extreme_twists:
        assert floats(extreme["box"])[1:] == approx([vy, wz])
    assert normal_forces(sol) == approx([n1, n2])
    assert motion.power.input == approx(BOX_M * G * vy)


def test_two_fingers_lift_a_box_between_pins(method: str) -> None:
    """Two frictionless pins at mid-height on the sides fix vx = 0; the box tilts as it rises.

    Pins at (0, H/2) normal +x and (W, H/2) normal -x: vx >= 0 and vx <= 0
    (rotation moves a point at com height only vertically) -> vx = 0.
    vy, wz, N1, N2 from ``two_finger_answer``. The pins squeeze antagonistically
    with no load to carry: their force is any P = P_left = P_right in [0, inf).
    Slips (body point minus mover point, tangential):
        fingers at y = 0:   (vx - wz (0 - H/2), 0) = (wz H/2, 0)      -> sliding
        left pin at x = 0:  (0, vy + wz (0 - W/2)) = (0, vy - wz W/2)   -> sliding
        right pin at x = W: (0, vy + wz W/2)                           -> sliding
    """
    vy, wz, n1, n2 = two_finger_answer()
    sol = solve(two_finger_lift(pins=True), method)
    check_solved(sol, indeterminate=True)
    assert floats(sol.twists["box"]) == approx([0.0, vy, wz])
    f1, f2, left, right = sol.contacts
    check_force(f1, [0.0, 1.0], n1)
    check_force(f2, [0.0, 1.0], n2)
    assert f1.normal_force_range == approx((n1, n1))
    assert f2.normal_force_range == approx((n2, n2))
    for pin in (left, right):
        lo, hi = pin.normal_force_range
        assert lo == approx(0.0) and hi is None
    assert left.normal_force == approx(right.normal_force)  # x balance, whatever P was reported
    assert sol.modes == ("sliding",) * 4
    assert floats(f1.slip) == approx([wz * BOX_H / 2, 0.0])
    assert floats(f2.slip) == approx([wz * BOX_H / 2, 0.0])
    assert floats(left.slip) == approx([0.0, vy - wz * BOX_W / 2])
    assert floats(right.slip) == approx([0.0, vy + wz * BOX_W / 2])
    assert [c.normal_velocity for c in sol.contacts] == approx([0.0] * 4)
    # Power balance: the fingers' power goes into potential energy.
    potential_rate = BOX_M * G * vy
    assert sol.power.input == approx(n1 * V1 + n2 * V2)
    assert sol.power.input == approx(potential_rate)
    assert sol.power.gravity == approx(potential_rate)


# --------------------------------------------------------------------------- squeeze: indeterminate forces


def test_squeeze_between_two_stationary_fingers_on_a_table(method: str) -> None:
    """Box on a table, squeezed by two stationary fingers at the same height y = 0.12.

    Motion: table contacts give vy -/+ wz W/2 >= 0, i.e. vy >= |wz| W/2; minimum
    power (M g vy) -> vy = 0, wz = 0; the fingers then give vx >= 0 and vx <= 0.
    The box stays at rest, all contacts rolling.
    Forces: x balance P_left = P_right = P; their moments cancel (same line of
    action), so the table's moment balance gives N1 = N2 = M g / 2 exactly,
    while P is any value in [0, inf).
    """
    y = 0.12
    data = box_on_table(
        contact("box", "left", [0.0, y], [1.0, 0.0]),
        contact("box", "right", [BOX_W, y], [-1.0, 0.0]),
        movers={"left": {"twist": [0.0, 0.0, 0.0]}, "right": {"twist": [0.0, 0.0, 0.0]}},
    )
    sol = solve(data, method)
    check_solved(sol, indeterminate=True)
    assert floats(sol.twists["box"]) == approx([0.0, 0.0, 0.0])
    assert sol.modes == ("rolling",) * 4
    table1, table2, left, right = sol.contacts
    half = BOX_M * G / 2
    check_force(table1, [0.0, 1.0], half)
    check_force(table2, [0.0, 1.0], half)
    assert table1.normal_force_range == approx((half, half))
    assert table2.normal_force_range == approx((half, half))
    for finger in (left, right):
        lo, hi = finger.normal_force_range
        assert lo == approx(0.0) and hi is None
    assert left.normal_force == approx(right.normal_force)


def test_squeeze_at_different_heights_has_bounded_ranges(method: str) -> None:
    """As above but the left finger at yL = 0.05 and the right one at yR = 0.15 (D = 0.1).

    x balance: P_left = P_right = P. Moment about the com:
        left  (-W/2, yL - H/2), force (P, 0):  -(yL - H/2) P
        right (+W/2, yR - H/2), force (-P, 0): +(yR - H/2) P
        table N1 at (-W/2, -H/2): -W/2 N1;  N2 at (+W/2, -H/2): +W/2 N2
      -> N1 - N2 = 2 P D / W,  N1 + N2 = M g.
    N2 >= 0 bounds P <= M g W / (2 D) = 39.24 N; so
        P in [0, M g W/(2D)],  N1 in [M g/2, M g],  N2 in [0, M g/2].
    The motion is still rest (same kinematic argument).
    """
    y_left, y_right = 0.05, 0.15
    d = y_right - y_left
    data = box_on_table(
        contact("box", "left", [0.0, y_left], [1.0, 0.0]),
        contact("box", "right", [BOX_W, y_right], [-1.0, 0.0]),
        movers={"left": {}, "right": {}},
    )
    sol = solve(data, method)
    check_solved(sol, indeterminate=True)
    assert floats(sol.twists["box"]) == approx([0.0, 0.0, 0.0])
    weight = BOX_M * G
    p_max = weight * BOX_W / (2 * d)
    table1, table2, left, right = sol.contacts
    assert table1.normal_force_range == approx((weight / 2, weight))
    assert table2.normal_force_range == approx((0.0, weight / 2))
    assert left.normal_force_range == approx((0.0, p_max))
    assert right.normal_force_range == approx((0.0, p_max))
    # Whatever distribution is reported lies on that one-parameter family.
    p = left.normal_force
    assert right.normal_force == approx(p)
    assert table1.normal_force == approx(weight / 2 + p * d / BOX_W)
    assert table2.normal_force == approx(weight / 2 - p * d / BOX_W)


# --------------------------------------------------------------------------- continua of motions


def test_box_between_a_wall_and_a_receding_finger_is_a_bounded_continuum(method: str) -> None:
    """Box on a table, a fixed wall on its left face, a finger on its right face moving right at s.

    Table: vy >= |wz| W/2 and minimum power -> vy = wz = 0.
    Wall: vx >= 0. Finger: (-1, 0).(vx - s, .) >= 0 -> vx <= s.
    Every vx in [0, s] costs the same (zero) power: a bounded continuum whose
    extreme twists are (0, 0, 0) (box stays at the wall) and (s, 0, 0) (box
    follows the finger). Table forces M g / 2 each; no horizontal force.
    """
    s = 0.1
    data = box_on_table(
        contact("box", "wall", [0.0, BOX_H / 2], [1.0, 0.0]),
        contact("box", "finger", [BOX_W, BOX_H / 2], [-1.0, 0.0]),
        movers={"wall": {}, "finger": {"twist": [s, 0.0, 0.0]}},
    )
    sol = solve(data, method)
    assert sol.status == "ambiguous", sol.message
    assert len(sol.solutions) == 1
    motion = sol.solutions[0]
    assert motion.continuum and not motion.unbounded
    assert motion.audit.passed
    extremes = sorted(floats(e["box"]) for e in motion.extreme_twists)
    assert len(extremes) == 2
    assert extremes[0] == approx([0.0, 0.0, 0.0])
    assert extremes[1] == approx([s, 0.0, 0.0])
    vx, vy, wz = floats(motion.twists["box"])
    assert -ABS <= vx <= s + ABS
    assert [vy, wz] == approx([0.0, 0.0])
    assert normal_forces(sol) == approx([BOX_M * G / 2, BOX_M * G / 2, 0.0, 0.0])


def test_box_alone_on_a_table_is_an_unbounded_continuum(method: str) -> None:
    """Nothing resists vx: every vx is a minimum-power motion (vy = wz = 0)."""
    sol = solve(box_on_table(), method)
    assert sol.status == "ambiguous", sol.message
    motion = sol.solutions[0]
    assert motion.continuum and motion.unbounded
    for twist in (motion.twists, *motion.extreme_twists):
        assert floats(twist["box"])[1:] == approx([0.0, 0.0])
    assert normal_forces(sol) == approx([BOX_M * G / 2] * 2)


# --------------------------------------------------------------------------- two free bodies

MA, WA, HA = 2.0, 0.4, 0.2  # bottom box A
MB, WB, HB = 1.0, 0.2, 0.2  # top box B, flush with A's downhill face
YA, YB = 0.05, 0.05  # stop contact heights above each box's bottom face


def local(x: float, y: float) -> list[float]:
    """World point of slope coordinates (x along T, y along N)."""
    return floats(x * T + y * N)


def stack_scene(speed: float) -> dict[str, Any]:
    """Box B on box A on the frictionless slope; a stop (perpendicular plate) holds both downhill faces.

    The stop moves uphill along the slope at ``speed``.
    """
    return base(
        bodies={"A": {"mass": MA, "com": local(WA / 2, HA / 2)}, "B": {"mass": MB, "com": local(WB / 2, HA + HB / 2)}},
        movers={"slope": {}, "stop": {"twist": [*floats(speed * T), 0.0]}},
        contacts=[
            contact("A", "slope", local(0.0, 0.0), N),
            contact("A", "slope", local(WA, 0.0), N),
            contact("A", "stop", local(0.0, YA), T),
            contact("B", "A", local(0.0, HA), N),
            contact("B", "A", local(WB, HA), N),
            contact("B", "stop", local(0.0, HA + YB), T),
        ],
    )


def stack_forces() -> dict[str, float]:
    """Statics in slope coordinates (x along T, y along N), sin/cos of the slope angle a.

    B (com at (WB/2, HA + HB/2)):
        along T: FB = MB g sin a;  along N: NB1 + NB2 = MB g cos a
        moment about B's com: -(YB - HB/2) FB - WB/2 NB1 + WB/2 NB2 = 0
          -> NB2 = (MB g cos a + 2 (YB - HB/2) FB / WB) / 2
    A (com at (WA/2, HA/2)), loaded by -NB1 N at (0, HA) and -NB2 N at (WB, HA):
        along T: FA = MA g sin a;  along N: NA1 + NA2 = (MA + MB) g cos a
        moment about (0, 0): -YA FA + WA NA2 - WB NB2 + gravity's
            (WA/2)(-MA g cos a) - (HA/2)(-MA g sin a) = 0
          -> NA2 = (YA FA + WB NB2 + MA g (WA cos a - HA sin a) / 2) / WA
    """
    sa, ca = math.sin(ALPHA), math.cos(ALPHA)
    fb = MB * G * sa
    nb2 = (MB * G * ca + 2 * (YB - HB / 2) * fb / WB) / 2
    nb1 = MB * G * ca - nb2
    fa = MA * G * sa
    na2 = (YA * fa + WB * nb2 + MA * G * (WA * ca - HA * sa) / 2) / WA
    na1 = (MA + MB) * G * ca - na2
    return {"NA1": na1, "NA2": na2, "FA": fa, "NB1": nb1, "NB2": nb2, "FB": fb}


def test_stack_forces_are_positive() -> None:
    assert min(stack_forces().values()) > 1.0


@pytest.mark.parametrize("speed", [0.0, 0.1])
def test_two_boxes_stacked_on_a_slope_pushed_up_by_a_stop(method: str, speed: float) -> None:
    """Both boxes move with the stop (rest when it rests), forces from ``stack_forces``.

    Six contacts, six twist coordinates, a nonsingular contact matrix and six
    positive forces: every constraint is active, so both twists equal the
    stop's translation s T (A slides on the slope; B rolls on A; both roll on
    the stop). The force on B from A is +NB_i N; A feels -NB_i N (checked by
    A's equilibrium with those reactions). Power: (FA + FB) s = (MA + MB) g s sin a.
    """
    sol = solve(stack_scene(speed), method)
    check_solved(sol)
    expected_twist = [*floats(speed * T), 0.0]
    assert floats(sol.twists["A"]) == approx(expected_twist)
    assert floats(sol.twists["B"]) == approx(expected_twist)
    f = stack_forces()
    a1, a2, a_stop, b1, b2, b_stop = sol.contacts
    check_force(a1, N, f["NA1"])
    check_force(a2, N, f["NA2"])
    check_force(a_stop, T, f["FA"])
    check_force(b1, N, f["NB1"])
    check_force(b2, N, f["NB2"])
    check_force(b_stop, T, f["FB"])
    assert (b1.body, b1.other) == ("B", "A")
    # Newton's third law: A balances its weight, slope, stop and the reactions -force of B's contacts.
    total = MA * np.array([0.0, -G]) + a1.force + a2.force + a_stop.force - b1.force - b2.force
    assert floats(total) == approx([0.0, 0.0], abs=1e-8)
    moving = speed > 0
    assert sol.modes == (("sliding" if moving else "rolling"),) * 2 + ("rolling",) * 4
    rate = (MA + MB) * G * speed * math.sin(ALPHA)
    assert sol.power.input == approx((f["FA"] + f["FB"]) * speed)
    assert sol.power.input == approx(rate)
    assert sol.power.gravity == approx(rate)


# --------------------------------------------------------------------------- 2-D and its 3-D extrusion

DEPTH = 0.3


def slope_scene_3d(speed: float, guides: bool = True) -> dict[str, Any]:
    """``slope_scene`` extruded along z: each contact duplicated at z = -DEPTH/2 and +DEPTH/2.

    Frictionless contacts whose normals all lie in the x-y plane leave vz free
    at no cost; with ``guides`` two fixed plates touch the front and back faces
    at the com (normals +z and -z) and pin vz = 0.
    """
    flat = slope_scene(speed)
    contacts = [{**c, "point": [*c["point"], z], "normal": [*c["normal"], 0.0]} for c in flat["contacts"] for z in (-DEPTH / 2, DEPTH / 2)]
    com = [*flat["bodies"]["block"]["com"], 0.0]
    if guides:
        contacts += [
            contact("block", "guide", [com[0], com[1], -DEPTH / 2], [0.0, 0.0, 1.0]),
            contact("block", "guide", [com[0], com[1], DEPTH / 2], [0.0, 0.0, -1.0]),
        ]
    return base(
        3,
        bodies={"block": {"mass": M, "com": com}},
        movers={"slope": {}, "guide": {}, "finger": {"twist": [*floats(speed * T), 0.0, 0.0, 0.0, 0.0]}},
        contacts=contacts,
    )


@pytest.mark.parametrize("speed", [0.0, 0.05])
def test_3d_extrusion_matches_2d(method: str, speed: float) -> None:
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


def test_3d_extrusion_without_guides_is_ambiguous_in_z(method: str) -> None:
    """Without the guides no contact resists vz and gravity does not care: an unbounded continuum."""
    sol = solve(slope_scene_3d(0.05, guides=False), method)
    assert sol.status == "ambiguous", sol.message
    assert sol.solutions[0].unbounded


# --------------------------------------------------------------------------- robot-driven finger


def test_robot_driven_finger_equals_the_same_twist(method: str) -> None:
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


@pytest.mark.parametrize("x", [1e-267, 1e-3, 5.0, 1e200])
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
