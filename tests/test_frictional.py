"""Hand-derived frictional cases, run over every frictional method and friction model.

Each case states its statics in the docstring; expected numbers come from those
derivations, never from the library. g = 9.81 m/s^2, angles counter-clockwise.
The fast path finds one motion and proves nothing, so it is checked only where
the certified answer is a unique motion; ``auto`` must agree with the certified
path on every status.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from pytest import approx

import quasistatic as qs
from quasistatic.solvers import BACKENDS

G = 9.81
SOLVING = ["scip", "auto", *(["fast"] if "fast" in BACKENDS else [])]
CERTIFYING = ["scip", "auto"]


def floats(array: Any) -> list[float]:
    return [float(x) for x in np.asarray(array, dtype=float).ravel()]


def scene(dimension: int, bodies: dict, movers: dict, contacts: list, **extra: Any) -> qs.Scene:
    gravity = [0.0, -G] if dimension == 2 else [0.0, 0.0, -G]
    data = {"quasistatic": 1, "dimension": dimension, "gravity": gravity, "bodies": bodies, "movers": movers, "contacts": contacts}
    return qs.load_scene({**data, **extra})


def contact(body: str, other: str, point: Any, normal: Any, mu: float = 0.0) -> dict[str, Any]:
    return {"body": body, "other": other, "point": floats(point), "normal": floats(normal), "mu": mu}


def check_motion(motion: qs.Motion | qs.Solution, twist: Any, modes: list[str], body: str = "block") -> None:
    assert floats(motion.twists[body]) == approx(floats(twist), abs=1e-7)
    assert [c.mode for c in motion.contacts] == modes
    assert motion.audit is not None and motion.audit.passed, motion.audit


def in_cones(sol: qs.Solution) -> None:
    """No reported force leaves its exact friction cone (checked from the world-frame force)."""
    for motion in sol.solutions or (sol,):
        for result, data in zip(motion.contacts, sol_scene(sol).contacts, strict=True):
            n = np.asarray(data.normal)
            tangential = result.force - (result.force @ n) * n
            assert result.normal_force >= -1e-9
            assert np.linalg.norm(tangential) <= data.mu * result.normal_force * (1 + 1e-9) + 1e-9


_SCENES: dict[int, qs.Scene] = {}


def sol_scene(sol: qs.Solution) -> qs.Scene:
    return _SCENES[id(sol)]


def run(s: qs.Scene, method: str, **options: Any) -> qs.Solution:
    sol = qs.solve(s, method=method, **options)
    _SCENES[id(sol)] = s
    if sol.ok:
        in_cones(sol)
    return sol


# --------------------------------------------------------------------------- a block on a slope

W, H, M, MU = 0.2, 0.1, 1.0, 0.5


def slope(alpha_deg: float, push: float | None = None, w: float = W, h: float = H, mu: float = MU) -> qs.Scene:
    """Block (w x h, mass M) on a fixed slope at alpha, two corner contacts, friction mu.

    With ``push`` (m/s along the slope, + uphill), a frictionless pusher touches
    the face that leads the motion, 0.02 above the slope.
    """
    a = math.radians(alpha_deg)
    t, n = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
    contacts = [contact("block", "slope", -w / 2 * t, n, mu), contact("block", "slope", w / 2 * t, n, mu)]
    movers: dict[str, Any] = {"slope": None}
    if push is not None:
        side = -1.0 if push > 0 else 1.0
        contacts.append(contact("block", "pusher", side * w / 2 * t + 0.02 * n, -side * t))
        movers["pusher"] = {"twist": [*floats(push * t), 0.0]}
    return scene(2, {"block": {"mass": M, "com": floats(h / 2 * n)}}, movers, contacts)


@pytest.mark.parametrize("method", SOLVING)
def test_block_at_rest_below_its_friction_angle(method: str) -> None:
    """alpha = 20 deg < atan(0.5) = 26.6 deg. Slope frame (x uphill): total friction
    M g sin a = 3.355 N uphill, total normal M g cos a = 9.218 N; moments about the com
    (corners at x = -+w/2, y = -h/2): (N2 - N1) w/2 + F h/2 = 0 with F = M g sin a,
    so N1 - N2 = F h / w = 1.678 N: N1 = 5.448 N (downhill), N2 = 3.770 N. Both rolling."""
    sol = run(slope(20.0), method)
    assert sol.status == "solved", sol.message
    check_motion(sol, [0, 0, 0], ["rolling", "rolling"])
    a = math.radians(20.0)
    assert [c.normal_force for c in sol.contacts] == approx([5.448, 3.770], abs=1e-3)
    t = np.array([math.cos(a), math.sin(a)])
    assert sum(float(c.force @ t) for c in sol.contacts) == approx(M * G * math.sin(a))


@pytest.mark.parametrize("method", CERTIFYING)
@pytest.mark.parametrize(("alpha", "w", "h", "mu"), [(30.0, W, H, MU), (30.0, 0.1, 0.2, 0.8)])
def test_block_beyond_the_friction_or_tipping_angle_is_unstable(method: str, alpha: float, w: float, h: float, mu: float) -> None:
    """At rest iff tan a <= min(mu, w/h): tan 30 deg = 0.577 > mu = 0.5 (slides); the tall block
    (w/h = 0.5 < tan 30 deg < mu = 0.8) tips. Either way no equilibrium exists."""
    assert run(slope(alpha, w=w, h=h, mu=mu), method).status == "unstable"


@pytest.mark.parametrize("method", SOLVING)
@pytest.mark.parametrize(("speed", "force"), [(0.01, M * G * (math.sin(0.349066) + MU * math.cos(0.349066))), (-0.01, None)])
def test_pushing_a_block_up_and_down_a_slope(method: str, speed: float, force: float | None) -> None:
    """alpha = 20 deg, pusher at 0.01 m/s along the slope. The block translates with the pusher,
    both supports slide; along the slope P -+ M g sin a -+ mu M g cos a = 0:
    up P = M g (sin a + mu cos a) = 7.964 N; down P = M g (mu cos a - sin a) = 1.254 N."""
    a = math.radians(20.0)
    sol = run(slope(20.0, push=speed), method)
    assert sol.status == "solved", sol.message
    check_motion(sol, [speed * math.cos(a), speed * math.sin(a), 0.0], ["sliding", "sliding", "rolling"])
    expected = force if force is not None else M * G * (MU * math.cos(a) - math.sin(a))
    assert sol.contacts[2].normal_force == approx(expected, rel=1e-6)
    assert sol.power.dissipation > 0  # type: ignore[union-attr]


# --------------------------------------------------------------------------- a box pushed low or high

BW, BH, BM, BMU, V = 0.2, 0.4, 2.0, 0.5, 0.01


def pushed_box(h: float) -> qs.Scene:
    return scene(
        2,
        {"block": {"mass": BM, "com": [0.0, BH / 2]}},
        {"floor": None, "pusher": {"twist": [V, 0.0, 0.0]}},
        [
            contact("block", "floor", [-BW / 2, 0.0], [0.0, 1.0], BMU),
            contact("block", "floor", [BW / 2, 0.0], [0.0, 1.0], BMU),
            contact("block", "pusher", [-BW / 2, h], [1.0, 0.0]),
        ],
    )


@pytest.mark.parametrize("method", SOLVING)
def test_box_pushed_low_slides(method: str) -> None:
    """h = 0.15 < w/(2 mu) = 0.2: translation at v, both floor contacts sliding, P = mu m g = 9.81 N;
    moments about the com give N_rear = 2.4525 N, N_front = 17.1675 N."""
    sol = run(pushed_box(0.15), method)
    assert sol.status == "solved", sol.message
    check_motion(sol, [V, 0, 0], ["sliding", "sliding", "rolling"])
    assert [c.normal_force for c in sol.contacts] == approx([2.4525, 17.1675, 9.81], rel=1e-6)


@pytest.mark.parametrize("method", SOLVING)
def test_box_pushed_high_tips_about_its_front_edge(method: str) -> None:
    """h = 0.25 > 0.2: the box turns about its front corner (0.1, 0); the pusher point (-0.1, 0.25)
    must move at v in x: -w * (0.25) = v -> w = -v/h = -0.04 rad/s; com velocity w x (com - corner)
    = (0.008, 0.004); the pusher point moves up at 0.008 along the frictionless pusher (sliding).
    Moments about the corner: P h = m g w/2 -> P = 7.848 N."""
    sol = run(pushed_box(0.25), method)
    assert sol.status == "solved", sol.message
    check_motion(sol, [0.008, 0.004, -0.04], ["separating", "rolling", "sliding"])
    assert sol.contacts[2].normal_force == approx(7.848, rel=1e-6)


# --------------------------------------------------------------------------- two fingers


def grasp(mu: float, dy: float = 0.0) -> qs.Scene:
    """Box (half-width 0.05, 0.5 kg) between two fingers moving up at 0.01 m/s, no squeeze."""
    up = {"twist": [0.0, 0.01, 0.0]}
    return scene(
        2,
        {"block": {"mass": 0.5, "com": [0.0, 0.0]}},
        {"left": up, "right": up},
        [contact("block", "left", [-0.05, -dy / 2], [1.0, 0.0], mu), contact("block", "right", [0.05, dy / 2], [-1.0, 0.0], mu)],
    )


@pytest.mark.parametrize("method", CERTIFYING)
def test_two_finger_lift_with_enough_friction_is_among_the_motions(method: str) -> None:
    """mu = 0.5, level fingers: the lift (both rolling, squeeze N >= m g/(2 mu) = 4.905 N) and the
    slip down (both sliding at exactly N = 4.905 N) both satisfy the laws: ambiguous, listing both."""
    sol = run(grasp(0.5), method, all_solutions=True) if method == "auto" else run(grasp(0.5), method)
    assert sol.status == "ambiguous", sol.message
    kinds = {tuple(c.mode for c in m.contacts) for m in sol.solutions}
    assert ("rolling", "rolling") in kinds and ("sliding", "sliding") in kinds
    lift = next(m for m in sol.solutions if not m.continuum)
    check_motion(lift, [0, 0.01, 0], ["rolling", "rolling"])


@pytest.mark.parametrize("method", CERTIFYING)
@pytest.mark.parametrize(("mu", "dy"), [(0.0, 0.0), (0.3, 0.04)])
def test_two_finger_lift_with_too_little_friction_is_unstable(method: str, mu: float, dy: float) -> None:
    """No friction: nothing carries the weight. Offset dy = 0.04 with mu = 0.3: the grasp line's
    slope dy/(2a) = 0.4 > mu leaves both cones, so no squeeze holds the box (Nguyen)."""
    assert run(grasp(mu, dy), method).status == "unstable"


# --------------------------------------------------------------------------- a finger dragging a box


def test_finger_dragging_a_box_across_a_table_is_one_of_its_motions() -> None:
    """A finger (mu_f = 0.8) on top of a box (0.2 x 0.1, 1 kg) on a table (mu_s = 0.2) moves
    sideways at 0.01 m/s. The rigid squeeze N_f is indeterminate: the finger drags the box
    (finger rolling, supports sliding) iff mu_f N_f >= mu_s (m g + N_f), i.e. N_f >= 3.27 N,
    and the box may also stay while the finger slides over it. Both are listed."""
    s = scene(
        2,
        {"block": {"mass": 1.0, "com": [0.0, 0.05]}},
        {"table": None, "finger": {"twist": [0.01, 0.0, 0.0]}},
        [
            contact("block", "table", [-0.1, 0.0], [0.0, 1.0], 0.2),
            contact("block", "table", [0.1, 0.0], [0.0, 1.0], 0.2),
            contact("block", "finger", [0.0, 0.1], [0.0, -1.0], 0.8),
        ],
    )
    sol = run(s, "scip")
    assert sol.status == "ambiguous", sol.message
    dragged = [m for m in sol.solutions if [c.mode for c in m.contacts] == ["sliding", "sliding", "rolling"]]
    assert dragged, [[c.mode for c in m.contacts] for m in sol.solutions]
    check_motion(dragged[0], [0.01, 0, 0], ["sliding", "sliding", "rolling"])
    assert dragged[0].contacts[2].normal_force >= 0.2 * 9.81 / 0.6 * (1 - 1e-6)
    at_rest = [m for m in sol.solutions if not m.continuum and np.allclose(m.twists["block"], 0.0)]
    assert at_rest and [c.mode for c in at_rest[0].contacts] == ["rolling", "rolling", "sliding"]


# --------------------------------------------------------------------------- 3-D: slip off every axis


def puck(friction: str, angle_deg: float = 30.0) -> qs.Scene:
    """A puck (1 kg, com 0.05 above the table) on four support points, mu = 0.5, pushed through its
    centre by a frictionless finger moving at 0.01 m/s along d = (cos 30, sin 30, 0)."""
    a = math.radians(angle_deg)
    d = np.array([math.cos(a), math.sin(a), 0.0])
    supports = [[0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [-0.05, 0.0, 0.0], [0.0, -0.05, 0.0]]
    return scene(
        3,
        {"block": {"mass": 1.0, "com": [0.0, 0.0, 0.05]}},
        {"table": None, "finger": {"twist": [*floats(0.01 * d), 0.0, 0.0, 0.0]}},
        [*(contact("block", "table", p, [0, 0, 1], 0.5) for p in supports), contact("block", "finger", [*(-0.05 * d[:2]), 0.05], d)],
        friction=friction,
    )


@pytest.mark.parametrize("method", SOLVING)
def test_3d_slip_off_every_axis_is_exact(method: str) -> None:
    """Exact cones: every support's friction opposes the slip, so the net friction opposes the
    puck's velocity; the frictionless finger pushes along d; balance forces the velocity along d.
    Translation at 0.01 m/s along d, supports sliding, finger force mu m g = 4.905 N along d."""
    sol = run(puck("exact"), method)
    assert sol.status == "solved", sol.message
    d = np.array([math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0])
    check_motion(sol, [*(0.01 * d), 0, 0, 0], ["sliding"] * 4 + ["rolling"])
    assert sol.contacts[4].normal_force == approx(0.5 * 9.81, rel=1e-6)
    for c in sol.contacts[:4]:  # maximum dissipation: friction exactly opposite the slip, on the cone
        tangential = c.force[:2]
        assert tangential[0] * d[1] - tangential[1] * d[0] == approx(0.0, abs=1e-9)
        assert np.linalg.norm(tangential) == approx(0.5 * c.normal_force, rel=1e-6, abs=1e-9)


def test_3d_pyramid_friction_is_said_and_differs_off_axis() -> None:
    """With a 4-edge pyramid (edges along x and y) the friction of a slip at 30 deg sits at a corner
    of the square: the model is anisotropic, so the puck no longer moves exactly along d; the answer
    names its friction model."""
    sol = run(puck("pyramid:4"), "scip")
    assert sol.friction == "pyramid:4"
    exact = run(puck("exact"), "scip")
    assert exact.friction == "exact"
    if sol.status == "solved":
        assert not np.allclose(sol.twists["block"], exact.twists["block"], atol=1e-6)


def test_time_limit_bounds_the_whole_certified_solve_and_claims_nothing() -> None:
    """A search stopped by the time limit reports failed, never a uniqueness or ambiguity it did not prove."""
    problem = qs.assemble(puck("exact"))
    stopped = qs.solve(problem, method="scip", time_limit=1e-6)
    assert stopped.status == "failed"
    assert "time limit" in stopped.message


def test_one_motion_from_an_incomplete_search_is_not_solved() -> None:
    """One motion found before the time limit: reported, audited, but failed (uniqueness unproven), not ambiguous."""
    from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
    from quasistatic.solvers import Options
    from quasistatic.solvers.certify.search import enumerate_motions, summarise

    problem = qs.assemble(slope(20.0, push=0.01))
    form = polyhedral_form(problem, aligned_edges(problem, problem.friction.edges))
    motions, complete = enumerate_motions(form, Options())
    assert complete and len(motions) == 1
    assert summarise(form, motions, complete, Options()).status == "solved"
    partial = summarise(form, motions, False, Options())
    assert partial.status == "failed" and "unique" in partial.message and len(partial.motions) == 1


def wedge(mu_floor: float, mu_finger: float, dimension: int = 3) -> qs.Scene:
    """A 1 kg box (0.1 m) on a floor, pushed low on its rear face by a finger moving forward and down
    at (0.01, -0.01) m/s. The finger must slide down the face, so its friction mu_f N pushes the box
    down; the floor's friction mu (m g + mu_f N) must not exceed N: the box slides iff mu mu_f < 1,
    else friction wedges it (jammed). In 3-D the planar scene is extruded, contacts at z = +-0.05."""
    from quasistatic.tools.validation import extrude

    data = {
        "quasistatic": 1,
        "dimension": 2,
        "bodies": {"box": {"mass": 1.0, "com": [0.0, 0.05]}},
        "movers": {"floor": {}, "finger": {"twist": [0.01, -0.01, 0.0]}},
        "contacts": [
            contact("box", "floor", [-0.05, 0.0], [0.0, 1.0], mu_floor),
            contact("box", "floor", [0.05, 0.0], [0.0, 1.0], mu_floor),
            contact("box", "finger", [-0.05, 0.02], [1.0, 0.0], mu_finger),
        ],
    }
    return qs.load_scene(extrude(data, 0.1) if dimension == 3 else data)


@pytest.mark.parametrize("dimension", [2, 3])
def test_friction_wedge_is_jammed_and_proven_for_exact_cones(dimension: int) -> None:
    """mu mu_f = 1.2 > 1: wedged. In 3-D the pyramid's jam proves nothing for the circle: the verdict
    must come with the sector relaxation's certificate."""
    sol = qs.solve(wedge(1.2, 1.0, dimension), method="scip")
    assert sol.status == "jammed", sol.message
    if dimension == 3:
        assert "slip sectors" in sol.details["certificate"]


@pytest.mark.parametrize("dimension", [2, 3])
def test_friction_below_the_wedge_slides(dimension: int) -> None:
    """mu mu_f = 0.9 < 1: the box slides forward at the finger's 0.01 m/s, the finger slides down its
    face, the pusher force N = mu m g / (1 - mu mu_f) = 88.29 N."""
    sol = qs.solve(wedge(0.9, 1.0, dimension), method="scip")
    assert sol.status == "solved", sol.message
    assert sol.twists["box"][0] == approx(0.01, abs=1e-9)
    finger = [c for c in sol.contacts if c.other == "finger"]
    assert sum(c.normal_force for c in finger) == approx(0.9 * G / (1 - 0.9), rel=1e-6)
    assert {c.mode for c in finger} == {"sliding"}


def test_sector_relaxation_never_excludes_an_exact_motion() -> None:
    """The wedge proof is sound only if every exact motion satisfies the relaxation: for scenes with
    an audited exact motion, the relaxation (with that motion's modes prescribed) is never infeasible."""
    from quasistatic.solvers import Options
    from quasistatic.solvers.certify.wedge import _relaxation

    for built in (wedge(0.9, 1.0), puck("exact")):
        problem = qs.assemble(built)
        sol = qs.solve(problem, method="scip")
        assert sol.status == "solved"
        for count in (8, 16):
            sectors = [2.0 * np.pi * np.arange(count + 1) / count for _ in range(problem.n_contacts)]
            for modes in (None, sol.modes):
                assert _relaxation(problem, Options(time_limit=20.0).start_clock(), sectors, modes)[0] == "feasible"


def test_exact_cone_mode_specified_solve() -> None:
    """Prescribed modes with exact 3-D cones: the motion with those modes (even where the 8-edge
    pyramid bends the slip off them), or a proven jammed."""
    exact = puck("exact")
    sliding = qs.solve(exact, modes=["sliding"] * 4 + ["rolling"])
    assert sliding.status == "solved", sliding.message
    d = np.array([math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0])
    check_motion(sliding, [*(0.01 * d), 0, 0, 0], ["sliding"] * 4 + ["rolling"])
    for modes in ([None] * 4 + ["separating"], ["rolling"] * 4 + [None]):  # the finger pushes in; supports cannot hold
        held = qs.solve(exact, modes=modes)
        assert held.status == "jammed", (modes, held.message)
        assert "slip sectors" in held.details["certificate"]


@pytest.mark.slow
def test_exact_motions_prove_ambiguity_when_another_does_not_refine() -> None:
    """A random 6-contact 3-D grasp (benchmark family) whose 8-edge pyramid has many motions, one of which has
    no exact motion next to it: the exact ones that do refine still prove ``ambiguous`` (list incomplete)."""
    from quasistatic.tools.bench.families import grasp_3d

    sol = qs.solve(grasp_3d(6, 1), method="scip", time_limit=30.0)
    assert sol.status == "ambiguous", sol.message
    assert len(sol.solutions) >= 2 and all(m.audit.passed for m in sol.solutions)
    assert "incomplete" in sol.message or "incomplete" in sol.details.get("exact_cone", "")
