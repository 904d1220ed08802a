"""The fast path's complete fallback: where Lemke's method ends on a ray, a motion is still found, or none proven.

Lemke's path reaches only solutions of index +1 (``tests/test_fast.py``), so on some scenes it ends on a
secondary ray although motions exist. The fast path then asks a complete method (a motion vertex of the
planar arrangement, else the mode branch and bound stopped at its first motion, then Newton's method on
exact 3-D cones). Its answers are checked here against the certified SCIP search: every motion it gives
passes the audit and is one of SCIP's motions (a listed twist, or a point of a listed continuum); it never
says ``failed`` where SCIP finds a motion; a ``jammed`` or ``unstable`` from it is SCIP's verdict too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import nnls

import quasistatic as qs
from quasistatic import Motion
from quasistatic.laws import RawMotion
from quasistatic.laws.polyhedral import LCPForm, aligned_edges, polyhedral_form
from quasistatic.solvers import fast
from quasistatic.solvers.certify.arrangement import motion_vertex
from quasistatic.solvers.certify.cheap import lemke_point, satisfies_form
from quasistatic.solvers.certify.patterns import PatternVerdict, prove_by_patterns
from quasistatic.solvers.numerics.lcp import NEWTON_ITERATIONS, QUICK_PATIENCE, lemke_depth, lemke_motion
from quasistatic.solvers.numerics.lemke import RAY
from quasistatic.tools.bench.families import FAMILIES
from random_scenes import random_scene

ROOT = Path(__file__).resolve().parents[1]

TWIST_RTOL = 1e-6  # scene-relative twist agreement between methods (as tests/test_crosscheck.py)


def _twist(problem: qs.Problem, twists: dict[str, np.ndarray]) -> np.ndarray:
    """Stacked scene-relative twist."""
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    return np.concatenate([twists[b.name] for b in problem.scene.bodies]) / units


def _free_axes(problem: qs.Problem, motion: Motion) -> list[np.ndarray]:
    """The unit twist directions of an unbounded continuum (``"box v_x +"``: body, component, sign)."""
    components = ("v_x", "v_y", "omega_z") if problem.dimension == 2 else ("v_x", "v_y", "v_z", "omega_x", "omega_y", "omega_z")
    names = [b.name for b in problem.scene.bodies]
    axes = []
    for text in motion.free_directions:
        body, component, sign = text.rsplit(" ", 2)
        axis = np.zeros(len(names) * len(components))
        axis[names.index(body) * len(components) + components.index(component)] = 1.0 if sign == "+" else -1.0
        axes.append(axis)
    return axes


def _in_motion(problem: qs.Problem, twist: np.ndarray, motion: Motion) -> bool:
    """Whether ``twist`` is ``motion``'s, or for a continuum a point of the hull of its extremes plus its free
    directions (a non-negative fit to within the twist tolerance)."""
    scale = max(1.0, float(np.max(np.abs(twist))))
    if not motion.continuum:
        return bool(np.max(np.abs(_twist(problem, motion.twists) - twist)) <= TWIST_RTOL * scale)
    extremes = [_twist(problem, e) for e in motion.extreme_twists] or [_twist(problem, motion.twists)]
    free = _free_axes(problem, motion)
    columns = np.array([np.r_[e, 1.0] for e in extremes] + [np.r_[d, 0.0] for d in free]).T
    _, residual = nnls(columns, np.r_[twist, 1.0])
    return bool(residual <= 10 * TWIST_RTOL * scale)


def _agrees_with_scip(scene: qs.Scene) -> tuple[str, str]:
    """The fast path's status and SCIP's, after checking that the fast path never contradicts SCIP."""
    problem = qs.assemble(scene)
    fast = qs.solve(problem, method="fast")
    scip = qs.solve(problem, method="scip")
    assert scip.status != "failed", scip.message
    if scip.status in ("solved", "ambiguous"):
        assert fast.status == "solved", f"fast: {fast.message}; scip: {scip.message}"
    if fast.status == "solved":
        assert fast.motion is not None and fast.motion.audit.passed and not fast.certified
        motions = scip.solutions or ((scip.motion,) if scip.motion is not None else ())
        twist = _twist(problem, fast.motion.twists)
        assert any(_in_motion(problem, twist, motion) for motion in motions), f"fast's motion is none of scip's: {scip.message}"
    elif fast.status in ("jammed", "unstable"):
        assert fast.status == scip.status and fast.certified, f"fast: {fast.message}; scip: {scip.message}"
    return fast.status, scip.status


# --------------------------------------------------------------------------- the bench grasps Lemke cannot answer

RAY_SCENES = [
    ("grasp-3d", 8, 0, "ambiguous"),
    pytest.param("grasp-3d", 8, 1, "solved", marks=pytest.mark.slow),  # 8 s of SCIP; its fast answer is checked below
    ("grasp-2d", 2, 2, "solved"),
    ("grasp-2d", 2, 4, "solved"),
    ("grasp-2d", 2, 5, "ambiguous"),
]


@pytest.mark.parametrize(("family", "size", "instance", "certified_status"), RAY_SCENES)
def test_fast_answers_the_bench_grasps_where_lemke_ends_on_a_ray(family: str, size: int, instance: int, certified_status: str) -> None:
    """Issue 11's target: these five bench scenes have motions, which Lemke's path cannot reach."""
    scene = FAMILIES[family].make(size, instance)
    problem = qs.assemble(scene)
    assert lemke_motion(problem)[0] == RAY  # the fallback is what answers
    fast, scip = _agrees_with_scip(scene)
    assert (fast, scip) == ("solved", certified_status)
    answer = qs.solve(problem, method="fast")
    assert dict(answer.notes)["method"].startswith(("arrangement vertex", "mode branch and bound", FROM_LEMKE_END))
    assert "secondary ray" in dict(answer.notes)["lemke"]


def test_fast_proves_a_jammed_bench_grasp_jammed() -> None:
    """grasp-2d 4 #1 ends Lemke on a ray and has no motion: the vertex certificate proves it, as SCIP says."""
    scene = FAMILIES["grasp-2d"].make(4, 1)
    answer = qs.solve(scene, method="fast")
    assert answer.status in ("jammed", "unstable") and answer.certified, answer.message
    assert "certificate" in dict(answer.notes)
    assert _agrees_with_scip(scene)[1] == answer.status


# --------------------------------------------------------------------------- property: never failed where SCIP finds a motion


@pytest.mark.parametrize("chunk", range(8))
def test_fast_never_fails_or_contradicts_scip_2d(chunk: int) -> None:
    """200 random planar scenes (25 a chunk): every one with a motion is solved by the fast path, consistently."""
    statuses = [_agrees_with_scip(random_scene(2, 5000 + 25 * chunk + k)) for k in range(25)]
    assert any(scip in ("solved", "ambiguous") for _, scip in statuses)


@pytest.mark.parametrize("chunk", [0, 1, pytest.param(2, marks=pytest.mark.slow), pytest.param(3, marks=pytest.mark.slow)])
def test_fast_never_fails_or_contradicts_scip_3d(chunk: int) -> None:
    """60 random 3-D scenes with exact cones (15 a chunk), as above; half in the slow suite (each SCIP answer now
    carries the exact-cone uniqueness proof, 0.1-1 s)."""
    statuses = [_agrees_with_scip(random_scene(3, 5000 + 15 * chunk + k)) for k in range(15)]
    assert any(scip in ("solved", "ambiguous") for _, scip in statuses)


@pytest.mark.parametrize("chunk", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_fast_never_fails_or_contradicts_scip_3d_pyramid(chunk: int) -> None:
    """40 random 3-D scenes with a 4-edge pyramid (20 a chunk): there the branch and bound's "no motion" is a proof."""
    statuses = [_agrees_with_scip(random_scene(3, 6000 + 20 * chunk + k, friction="pyramid:4")) for k in range(20)]
    assert any(scip in ("solved", "ambiguous") for _, scip in statuses)


# --------------------------------------------------------------------------- the two small pieces it adds to the certificates


def _planar_form(family: str, size: int, instance: int) -> LCPForm:
    problem = qs.assemble(FAMILIES[family].make(size, instance))
    return polyhedral_form(problem, aligned_edges(problem, problem.friction.edges))


def test_stop_at_ends_the_branch_and_bound_at_the_first_motion_it_accepts() -> None:
    """grasp-2d 2 #5 has several motions: accepting any stops at one of them; refusing all changes nothing."""
    form = _planar_form("grasp-2d", 2, 5)
    full = prove_by_patterns(form, None)
    assert full.verdict is PatternVerdict.ENUMERATED and len(full.motions) >= 2
    offered: list[RawMotion] = []
    refused = prove_by_patterns(form, None, stop_at=lambda motion: offered.append(motion) is not None)
    assert refused.verdict is full.verdict and refused.nodes == full.nodes and len(offered) >= 2
    first = prove_by_patterns(form, None, stop_at=lambda motion: True)
    assert first.verdict is PatternVerdict.FOUND and len(first.motions) == 1 and first.nodes < full.nodes
    assert np.allclose(first.motions[0].q, offered[0].q)  # the same first motion, the search stopped there


@pytest.mark.parametrize("instance", [2, 4, 5])
def test_motion_vertex_is_a_checked_motion(instance: int) -> None:
    """A motion vertex of grasp-2d 2 #2, #4, #5 (where Lemke ends on a ray) satisfies every law of the form."""
    form = _planar_form("grasp-2d", 2, instance)
    point = motion_vertex(form)
    assert point is not None and satisfies_form(form, point)


def test_motion_vertex_none_where_no_motion_exists() -> None:
    """The toppling block has no motion (unstable): no vertex holds one."""
    problem = qs.assemble(qs.load_scene(ROOT / "examples" / "topple.yaml"))
    assert motion_vertex(polyhedral_form(problem, aligned_edges(problem, 2))) is None


def test_first_solution_keeps_the_fast_paths_proven_jam() -> None:
    """``certify=False``: a jam the fast path's fallback proves is the answer (no SCIP search after it)."""
    scene = FAMILIES["grasp-2d"].make(4, 1)
    first = qs.solve(scene, certify=False)
    assert (first.status, first.method, first.certified, first.fallback) == ("jammed", "fast", True, ())
    assert first.diagnosis is qs.solve(scene).diagnosis


def test_a_hint_only_orders_the_branch_and_bound() -> None:
    """grasp-3d 8 #1 on the fallback's 8-edge pyramid: ordered by where Lemke's path ended, the search proves the
    same (its one motion, the same twist) as without."""
    problem = qs.assemble(FAMILIES["grasp-3d"].make(8, 1))
    form = polyhedral_form(problem, aligned_edges(problem, 8))
    status, hint = lemke_point(form)
    assert status == RAY
    plain, hinted = prove_by_patterns(form, None), prove_by_patterns(form, None, hint_x=hint)
    assert plain.verdict is hinted.verdict is PatternVerdict.UNIQUE
    assert plain.seed is not None and hinted.seed is not None
    assert np.allclose(plain.seed[: form.n_q], hinted.seed[: form.n_q], atol=1e-9)


def test_past_the_node_budget_scips_search_finds_the_motion(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #1 with the branch and bound held to 10 nodes: SCIP's search, stopped at its first motion,
    gives the pyramid motion Newton's method carries to the exact cones: the scene's only motion, which the
    unhindered fallback finds too (and SCIP, in the bench-scene test above)."""
    from quasistatic.solvers.certify import patterns

    scene = FAMILIES["grasp-3d"].make(8, 1)
    monkeypatch.setattr(fast, "_from_lemke_end", lambda *args: None)  # which answers 8 #1 first
    unhindered = qs.solve(scene, method="fast")
    monkeypatch.setattr(patterns, "PYRAMID_PATTERN_NODES", 10)
    answer = qs.solve(scene, method="fast")
    assert answer.status == "solved" and dict(answer.notes)["method"] == "SCIP search (8 edges)", answer.message
    assert dict(unhindered.notes)["method"] != "SCIP search (8 edges)"
    assert answer.motion is not None and answer.motion.audit.passed and unhindered.motion is not None
    problem = qs.assemble(scene)
    twists = [_twist(problem, motion.twists) for motion in (answer.motion, unhindered.motion)]
    assert np.allclose(twists[0], twists[1], rtol=0.0, atol=10 * TWIST_RTOL * np.abs(twists[1]).max())


@pytest.mark.parametrize(
    ("seed", "method"),
    [pytest.param(7128, "sector relaxation", marks=pytest.mark.slow), (7040, "(32 edges)"), (7339, "(32 edges)")],  # 7128: 18 s
)
def test_exact_motions_the_8_edge_pyramid_misses(seed: int, method: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Random 3-D scenes where the 8-edge pyramid has no motion that Newton's method carries to the exact cones
    (7339), or none at all (7128: a wedge of the pyramid, not of the circles; 7040: no equilibrium in it): a point
    of the exact cones' sector relaxation, or the 32-edge pyramid, gives the motion, one of SCIP's. (Newton's
    method from where Lemke's paths ended, which answers 7128 and 7040 first, is held off.)"""
    monkeypatch.setattr(fast, "_from_lemke_end", lambda *args: None)
    scene = random_scene(3, seed)
    answer = qs.solve(scene, method="fast")
    assert answer.status == "solved" and method in dict(answer.notes)["method"], answer.message
    assert _agrees_with_scip(scene)[0] == "solved"


@pytest.mark.slow
@pytest.mark.parametrize("chunk", range(20))
def test_fast_never_fails_or_contradicts_scip_3d_sweep(chunk: int) -> None:
    """400 more random 3-D scenes with exact cones (20 a chunk), where the 32-edge retry and the sector
    relaxation's motions were found needed."""
    for k in range(20):
        _agrees_with_scip(random_scene(3, 7000 + 20 * chunk + k))


@pytest.mark.parametrize("chunk", range(2))
def test_frictionless_3d_no_motion_is_proven_without_a_search(chunk: int) -> None:
    """40 random frictionless 3-D scenes (20 a chunk): the laws are an LP's optimality conditions, so where Lemke
    ends on a ray the kinematic or equilibrium certificate alone proves that no motion exists (no SCIP search);
    every verdict equals the frictionless LP's."""
    proven_alone = 0
    for k in range(20):
        problem = qs.assemble(random_scene(3, 6100 + 20 * chunk + k, friction="none"))
        fast, lp = qs.solve(problem, method="fast"), qs.solve(problem, method="lp")
        if fast.status == "solved":
            assert lp.status in ("solved", "ambiguous") and fast.motion is not None and fast.motion.audit.passed
            continue
        assert fast.status == lp.status and fast.certified, f"fast: {fast.message}; lp: {lp.message}"
        proven_alone += "without friction either proves" in str(dict(fast.notes).get("certificate"))
    assert proven_alone > 0


# --------------------------------------------------------------------------- Newton's method from where Lemke's path ended

FROM_LEMKE_END = "Newton's method from where Lemke's path ended"


def _without_lemke_end_starts(scene: qs.Scene, monkeypatch: pytest.MonkeyPatch) -> qs.Solution:
    """The fast answer as before these starts (the complete fallback alone)."""
    with monkeypatch.context() as patch:
        patch.setattr(fast, "_from_lemke_end", lambda *args: None)
        return qs.solve(scene, method="fast")


def test_newton_from_the_rays_last_point_answers_grasp_3d_6_3(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 6 #3: Lemke ends on a ray, and Newton's method from the ray's last point reaches the exact motion
    (the one the default solve finds) that the sector relaxation's point gave before, ~100x slower."""
    scene = FAMILIES["grasp-3d"].make(6, 3)
    problem = qs.assemble(scene)
    assert lemke_motion(problem)[0] == RAY
    answer = qs.solve(problem, method="fast")
    notes = dict(answer.notes)
    assert answer.status == "solved" and notes["method"] == FROM_LEMKE_END and "secondary ray" in notes["lemke"]
    assert answer.motion is not None and answer.motion.audit.passed and not answer.certified
    before = _without_lemke_end_starts(scene, monkeypatch)
    assert before.status == "solved" and dict(before.notes)["method"] == "sector relaxation"
    default = qs.solve(problem)
    assert default.status == "solved"
    twist = _twist(problem, answer.twists)
    for other in (before, default):
        assert np.allclose(twist, _twist(problem, other.twists), rtol=0.0, atol=1e-9 * np.abs(twist).max())


def _without_one_switch(patch: pytest.MonkeyPatch) -> None:
    """The fast path's Newton starts from Lemke's end without the one that switches one contact a round."""
    exact_from = fast._exact_from

    def every_switch(
        problem: qs.Problem, q: np.ndarray, c: np.ndarray, depth: float = 0.0, patience: int = NEWTON_ITERATIONS, one_switch: bool = False
    ) -> RawMotion | None:
        return None if one_switch else exact_from(problem, q, c, depth, patience)

    patch.setattr(fast, "_exact_from", every_switch)


def _textbook_lemke(patch: pytest.MonkeyPatch) -> None:
    """The fast path on Lemke's textbook path (the twist halves leave the basis as any variable does, covering vector
    of ones), as before session 19: its ray point on grasp-3d 8 #0 is the one from which the quick rounds switching
    every contact fail and the depth start converges."""
    patch.setattr(fast, "lemke_motion", lambda problem, short_path=False: lemke_motion(problem))


@pytest.mark.parametrize(("size", "instance"), [(4, 0), (6, 0), (6, 1), (6, 2), (6, 3), (8, 0), (8, 1)])
def test_the_fast_path_runs_lemkes_short_path_and_keeps_its_answers(size: int, instance: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """The fast path's Lemke keeps the twist halves basic once they enter (free variables) and starts from a covering
    vector of ``GAP_COVERING`` on the gap rates' rows: on these grasps it ends as the textbook path does (a solution,
    or a ray from whose last point Newton's method answers), in fewer pivots (8 #0: 59, not 143; 8 #1: 81, not 99),
    and the answer keeps its status and twist to 1e-9 relative."""
    problem = qs.assemble(FAMILIES["grasp-3d"].make(size, instance))
    short, textbook = lemke_motion(problem, short_path=True), lemke_motion(problem)
    assert short[0] == textbook[0] and short[4] < textbook[4]
    answer = qs.solve(problem, method="fast")
    notes = dict(answer.notes)
    if short[0] == RAY:
        assert f"({short[4]} pivots)" in notes["lemke"]
    else:
        assert notes["pivots"] == short[4]
    with monkeypatch.context() as patch:
        _textbook_lemke(patch)
        before = qs.solve(problem, method="fast")
    assert answer.status == before.status == "solved" and answer.motion is not None and answer.motion.audit.passed
    twist = _twist(problem, answer.twists)
    assert np.allclose(twist, _twist(problem, before.twists), rtol=0.0, atol=1e-9 * np.abs(twist).max())


def test_newton_switching_one_contact_a_round_answers_grasp_3d_8_0(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #0: from the textbook Lemke path's ray point, Newton's quick rounds that switch every contact that
    must switch fail (the first round ends with three closed contacts pulling, all opened at once); a round that
    switches only the first of them reaches, in one switch, the motion that the full rounds from the ray's depth
    reach in ~1,000 evaluations of the laws (one of the scene's two motions, the one the mode branch and bound gave
    before). (From the fast path's short path's ray point the quick rounds switching every contact answer.)"""
    problem = qs.assemble(FAMILIES["grasp-3d"].make(8, 0))
    assert lemke_motion(problem)[0] == RAY
    _textbook_lemke(monkeypatch)
    answer = qs.solve(problem, method="fast")
    notes = dict(answer.notes)
    assert answer.status == "solved" and notes["method"] == FROM_LEMKE_END, answer.message
    assert notes["newton_switches"] == "first" and notes["newton_patience"] == QUICK_PATIENCE
    assert answer.motion is not None and answer.motion.audit.passed and not answer.certified
    with monkeypatch.context() as patch:
        _without_one_switch(patch)
        full_rounds = qs.solve(problem, method="fast")
    assert dict(full_rounds.notes)["newton_patience"] == NEWTON_ITERATIONS and dict(full_rounds.notes)["newton_switches"] == "all"
    twist = _twist(problem, answer.twists)
    assert np.allclose(twist, _twist(problem, full_rounds.twists), rtol=0.0, atol=1e-9 * np.abs(twist).max())


def test_newton_from_the_rays_last_point_with_its_depth_answers_grasp_3d_8_0(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #0 without the start that switches one contact a round: Lemke's ray point solves the laws with
    every gap rate raised by the artificial variable, so the contacts the path holds closed penetrate by it.
    Newton's method started with those contacts closed reaches the motion the mode branch and bound gave before
    (one of its two; ~100x slower); read with no depth (those contacts open), it fails and the branch and bound answers.
    (The textbook path's ray point, where this start was found.)"""
    scene = FAMILIES["grasp-3d"].make(8, 0)
    problem = qs.assemble(scene)
    status, _, q, _, _, _ = lemke_motion(problem)
    assert status == RAY and lemke_depth(problem, q) > 0.0
    _without_one_switch(monkeypatch)
    _textbook_lemke(monkeypatch)
    answer = qs.solve(problem, method="fast")
    assert answer.status == "solved" and dict(answer.notes)["method"] == FROM_LEMKE_END, answer.message
    assert dict(answer.notes)["newton_patience"] == NEWTON_ITERATIONS  # quick mode switches miss this one
    assert answer.motion is not None and answer.motion.audit.passed and not answer.certified
    with monkeypatch.context() as patch:
        patch.setattr(fast, "lemke_depth", lambda *args: 0.0)
        no_depth = qs.solve(problem, method="fast")
    assert dict(no_depth.notes)["method"] == "mode branch and bound (8 edges)"
    twist = _twist(problem, answer.twists)
    assert np.allclose(twist, _twist(problem, no_depth.twists), rtol=0.0, atol=1e-9 * np.abs(twist).max())


def test_newton_with_quick_mode_switches_answers_grasp_3d_8_1(monkeypatch: pytest.MonkeyPatch) -> None:
    """grasp-3d 8 #1: from Lemke's ray point (with its depth), Newton's method whose rounds end once two iterations
    stall with a mode switch due reaches the scene's one motion, the one the mode branch and bound gave before
    (~100x slower); with the kernel's full rounds alone it fails there, and the branch and bound answers."""
    problem = qs.assemble(FAMILIES["grasp-3d"].make(8, 1))
    assert lemke_motion(problem)[0] == RAY
    answer = qs.solve(problem, method="fast")
    notes = dict(answer.notes)
    assert answer.status == "solved" and notes["method"] == FROM_LEMKE_END and notes["newton_patience"] == QUICK_PATIENCE
    assert answer.motion is not None and answer.motion.audit.passed and not answer.certified
    with monkeypatch.context() as patch:
        patch.setattr(fast, "QUICK_PATIENCE", NEWTON_ITERATIONS)
        patient = qs.solve(problem, method="fast")
    assert dict(patient.notes)["method"] == "mode branch and bound (8 edges)"
    twist = _twist(problem, answer.twists)
    assert np.allclose(twist, _twist(problem, patient.twists), rtol=0.0, atol=1e-9 * np.abs(twist).max())


@pytest.mark.parametrize(("seed", "edges"), [(7390, 8), (7040, 32)])
def test_newton_from_a_finer_pyramids_lemke_point(seed: int, edges: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Random 3-D scenes where Newton's method from the 6-edge ray's last point fails, but from where Lemke's path
    ended on the fallback's 8-edge pyramid (7390), or on the 32-edge one (7040: no equilibrium in the 8-edge
    pyramid), it converges before the branch and bound: a motion SCIP lists; before, the tree gave it."""
    scene = random_scene(3, seed)
    answer = qs.solve(scene, method="fast")
    assert answer.status == "solved" and dict(answer.notes)["method"] == f"{FROM_LEMKE_END} ({edges} edges)", answer.message
    assert _agrees_with_scip(scene)[0] == "solved"
    before = _without_lemke_end_starts(scene, monkeypatch)
    assert dict(before.notes)["method"] == f"mode branch and bound ({edges} edges)"
