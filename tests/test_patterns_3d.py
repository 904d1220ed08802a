"""The 3-D pyramid mode branch and bound (``certify/patterns.py``) against the complete SCIP search.

Property: on the same pyramid (``pyramid:4``, ``pyramid:8``, and the 8-edge pyramid inscribed in exact cones),
the branch and bound's verdict never contradicts SCIP's ``enumerate_motions``: "unique" only where SCIP finds
that one twist and proves the list complete, "no motion" only where SCIP finds none, and a listed set of
motions equal to SCIP's. 125 random scenes of 2-4 contacts (boxes of ``random_scenes.py`` and ellipsoid
grasps, some with frictionless contacts mixed in; 675 more with ``pytest -m slow``), degenerate scenes
(contacts on one line, coincident contacts, no load, every contact frictionless) and the 3-D benchmark grasps.
And it decides most scenes, so the property is not met by proving nothing. Then: the default ``certified``
solve takes this path on the benchmark grasps (SCIP's pyramid search monkeypatched to raise), and agrees with
``method="scip"``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certify.exact_cone as exact_cone
from hulls import covered
from quasistatic.laws import RawMotion
from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
from quasistatic.solvers.certify.cheap import seed_point
from quasistatic.solvers.certify.patterns import ENUMERATION_PROOF, NO_MOTION_PROOF, PATTERN_PROOF, PatternVerdict, prove_by_patterns
from quasistatic.solvers.certify.search import enumerate_motions
from quasistatic.solvers.result import Options
from quasistatic.tolerances import DISTINCT_TWIST
from quasistatic.tools.bench.families import grasp_3d
from random_scenes import random_scene

FRICTIONS = ("pyramid:4", "pyramid:8", "exact")
SCIP_SECONDS = 10.0  # SCIP's own search, the reference; a scene it cannot finish in this is left out


def _edges(problem: qs.Problem) -> int:
    """The pyramid both searches run on: the scene's own, or the 8-edge one the exact cones' search uses."""
    return problem.friction.edges if problem.friction.is_polyhedral(3) else exact_cone.SEARCH_EDGES


def _agrees_with_scip(scene: qs.Scene, scip_seconds: float = SCIP_SECONDS) -> PatternVerdict | None:
    """The branch and bound's verdict on the scene's pyramid, after checking it against SCIP's search (None
    where SCIP did not finish: nothing to compare)."""
    problem = qs.assemble(scene)
    form = polyhedral_form(problem, aligned_edges(problem, _edges(problem)))
    proof = prove_by_patterns(form, seed_point(form))
    if proof.verdict is PatternVerdict.UNDECIDED:
        return proof.verdict
    motions, complete = enumerate_motions(form, Options(time_limit=scip_seconds).start_clock())
    if not complete:
        return None
    if proof.verdict is PatternVerdict.UNIQUE:
        assert proof.seed is not None
        assert len(motions) == 1 and not motions[0].continuum, f"patterns: unique; scip: {len(motions)} motions"
        assert _close(motions[0].q, proof.seed[: form.n_q])
    elif proof.verdict is PatternVerdict.NONE:
        assert not motions, f"patterns: no motion; scip: {len(motions)}"
    elif any(m.unbounded for m in [*proof.motions, *motions]):
        _same_unbounded(problem, list(proof.motions), motions)
    else:
        _same_motion_sets(list(proof.motions), motions)
    return proof.verdict


def _same_unbounded(problem: qs.Problem, mine: list[RawMotion], scip: list[RawMotion]) -> None:
    """Unbounded continua have no canonical extremes (any LP vertex of the polyhedron, each search its own), and
    the two searches may cut one family differently (SCIP excludes a continuum's face whose forces are its own,
    here listed as a continuum of its own modes): every free direction SCIP lists is listed here, and (on a
    pyramid scene, where the audit judges the pyramid's laws) every motion listed here passes the audit,
    extremes included."""
    from quasistatic.solve import audited_raw_motion

    assert {m.free_axes for m in scip if m.unbounded} <= {m.free_axes for m in mine if m.unbounded}
    if problem.friction.is_polyhedral(3):
        assert all(audited_raw_motion(problem, m).audit.passed for m in mine)


def _close(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.max(np.abs(a - b)) <= DISTINCT_TWIST * max(1.0, float(np.max(np.abs(a)))))


def _same_motion_sets(mine: list[RawMotion], scip: list[RawMotion]) -> None:
    scale = max([1.0] + [float(np.max(np.abs(m.q))) for m in mine + scip])
    tol = DISTINCT_TWIST * scale
    assert all(covered(m, scip, tol) for m in mine), "patterns lists a motion scip does not"
    assert all(covered(m, mine, tol) for m in scip), "scip lists a motion patterns does not"


def _with_frictionless(scene: qs.Scene, every: int) -> qs.Scene:
    """The scene with every ``every``-th contact frictionless (a frictionless mix)."""
    contacts = tuple(dataclasses.replace(c, mu=0.0) if i % every == 0 else c for i, c in enumerate(scene.contacts))
    return dataclasses.replace(scene, contacts=contacts)


def _random(seed: int) -> qs.Scene:
    """Odd seeds: a box on a table and fingers (``random_scenes.py``); even: an ellipsoid held by 2-4 fingers
    (the bench's generator, other instances); one in seven with every other contact frictionless."""
    friction = FRICTIONS[seed % 3]
    scene = random_scene(3, 2000 + seed, friction=friction) if seed % 2 else grasp_3d(2 + seed % 3, 1000 + seed, friction=friction)
    return _with_frictionless(scene, 2) if seed % 7 == 6 else scene


def _check_chunk(chunk: int, size: int = 25) -> None:
    verdicts = [_agrees_with_scip(_random(seed)) for seed in range(size * chunk, size * (chunk + 1))]
    compared = [v for v in verdicts if v is not None]
    decided = sum(v is not PatternVerdict.UNDECIDED for v in compared)
    assert len(compared) >= 0.8 * size and decided >= 0.9 * len(compared), f"{decided} decided, {len(compared)} compared"


# Chunks 3-5 hold the scenes whose SCIP reference is slowest (12-18 s each on 2 cores): the slow suite runs them,
# keeping the default suite under its 10 minutes.
DEFAULT_CHUNKS, SLOW_CHUNKS = (0, 1, 6, 7), (2, 3, 4, 5, *range(8, 32))  # chunk 2: 6 s


@pytest.mark.parametrize("chunk", DEFAULT_CHUNKS)
def test_pyramid_proof_never_contradicts_scip_on_random_scenes(chunk: int) -> None:
    _check_chunk(chunk)


@pytest.mark.slow
@pytest.mark.parametrize("chunk", SLOW_CHUNKS)
def test_pyramid_proof_never_contradicts_scip_on_random_scenes_sweep(chunk: int) -> None:
    _check_chunk(chunk)


def _stick_3d(friction: str, finger_speed: float, gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)) -> qs.Scene:
    """A bar on two fingertips under it and one on its end, all three contacts on one line (the x axis)."""
    return qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 3,
            "friction": friction,
            "gravity": list(gravity),
            "bodies": {"bar": {"mass": 1.0, "com": [0.0, 0.0, 0.0]}},
            "movers": {
                "left": {"twist": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]},
                "right": {"twist": [finger_speed, 0.0, 0.0, 0.0, 0.0, 0.0]},
                "end": {"twist": [0.02, 0.0, 0.0, 0.0, 0.0, 0.0], "origin": [-0.5, 0.0, 0.0]},
            },
            "contacts": [
                {"body": "bar", "other": "left", "point": [-0.3, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "mu": 0.4},
                {"body": "bar", "other": "right", "point": [0.3, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "mu": 0.4},
                {"body": "bar", "other": "end", "point": [-0.5, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "mu": 0.3},
            ],
        }
    )


def _box_3d(friction: str, push: float, mu_table: float = 0.5, twin: bool = False, gravity: float = -9.81) -> qs.Scene:
    """A 0.2 m cube on four table corners pushed by a finger on its side; ``twin``: a second finger at the same
    point with the same normal (coincident contacts)."""
    fingers = [{"body": "box", "other": "finger", "point": [-0.1, 0.0, 0.1], "normal": [1.0, 0.0, 0.0], "mu": 0.3}]
    if twin:
        fingers.append({"body": "box", "other": "finger", "point": [-0.1, 0.0, 0.1], "normal": [1.0, 0.0, 0.0], "mu": 0.6})
    corners = [
        {"body": "box", "other": "table", "point": [x, y, 0.0], "normal": [0.0, 0.0, 1.0], "mu": mu_table}
        for x, y in ((-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1))
    ]
    return qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 3,
            "friction": friction,
            "gravity": [0.0, 0.0, gravity],
            "bodies": {"box": {"mass": 1.0, "com": [0.0, 0.0, 0.1]}},
            "movers": {"table": None, "finger": {"twist": [push, 0.0, 0.0, 0.0, 0.0, 0.0], "origin": [-0.1, 0.0, 0.1]}},
            "contacts": corners + fingers,
        }
    )


DEGENERATE = {
    **{f"contacts on one line, {f}": _stick_3d(f, 0.05) for f in FRICTIONS},
    **{f"contacts on one line, fingers still, {f}": _stick_3d(f, 0.0) for f in FRICTIONS},
    **{f"contacts on one line, no load, {f}": _stick_3d(f, 0.05, (0.0, 0.0, 0.0)) for f in FRICTIONS},
    **{f"box pushed, {f}": _box_3d(f, 0.05) for f in FRICTIONS},
    **{f"box pushed, coincident fingers, {f}": _box_3d(f, 0.05, twin=True) for f in FRICTIONS},
    **{f"box at rest, coincident fingers, {f}": _box_3d(f, 0.0, twin=True) for f in FRICTIONS},
    **{f"box, no load, {f}": _box_3d(f, 0.05, gravity=0.0) for f in FRICTIONS},
    **{f"box on a frictionless table, {f}": _box_3d(f, 0.05, mu_table=0.0) for f in FRICTIONS},
    "box, every contact frictionless": _box_3d("none", 0.05),
}


@pytest.mark.parametrize("name", sorted(DEGENERATE))
def test_pyramid_proof_never_contradicts_scip_on_degenerate_scenes(name: str) -> None:
    scene = DEGENERATE[name]
    if scene.friction.kind == "none":  # no pyramid: the frictionless columns are every contact's normal
        scene = dataclasses.replace(_box_3d("pyramid:4", 0.05), contacts=tuple(dataclasses.replace(c, mu=0.0) for c in scene.contacts))
    _agrees_with_scip(scene)


BENCH_GRASPS = [(4, 0), (4, 1), (6, 0), (8, 0), (8, 1)]  # (6, 1): SCIP's own search takes more than a minute


@pytest.mark.parametrize(("contacts", "instance"), BENCH_GRASPS)
@pytest.mark.parametrize("friction", ["pyramid:8", "exact"])
def test_pyramid_proof_never_contradicts_scip_on_benchmark_grasps(contacts: int, instance: int, friction: str) -> None:
    assert _agrees_with_scip(grasp_3d(contacts, instance, friction=friction), 60.0) not in (PatternVerdict.UNDECIDED, None)


PROOFS = (PATTERN_PROOF, ENUMERATION_PROOF, NO_MOTION_PROOF)


@pytest.mark.parametrize(("contacts", "instance"), [(4, 0), (4, 1), (6, 0), (8, 0), pytest.param(8, 1, marks=pytest.mark.slow)])  # 9 s
def test_certified_3d_grasps_take_the_branch_and_bound_without_the_scip_pyramid_search(
    contacts: int, instance: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The default solve of the exact-cone bench grasps never runs SCIP's pyramid search, and says which proof
    the pyramid's completeness rests on (or that no pyramid was searched: the fast path's motion was proven the
    only one first); its answer is the one of ``method="scip"``."""
    scene = grasp_3d(contacts, instance)
    reference = qs.solve(scene, method="scip")

    def no_scip(*args: object, **kwargs: object) -> None:
        raise AssertionError("the SCIP pyramid search ran")

    monkeypatch.setattr(exact_cone, "enumerate_motions", no_scip)
    solution = qs.solve(scene)
    assert solution.status == reference.status
    assert solution.certified == reference.certified
    if solution.status in ("solved", "ambiguous"):  # (a jam is proven on the exact cones, after the pyramid's)
        notes = dict(solution.notes)
        assert notes.get("pyramid_search") in PROOFS or notes["pyramid"].startswith("not searched")
    if solution.status == "solved":
        assert solution.motion is not None and reference.motion is not None
        for body, twist in solution.motion.twists.items():
            assert np.allclose(twist, reference.motion.twists[body], atol=1e-6)


@pytest.mark.parametrize("instance", range(2))
def test_certified_pyramid_grasps_are_proven_without_scip(instance: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """With ``pyramid:8`` friction the certified answer of a 4-contact bench grasp needs no SCIP at all."""
    import quasistatic.solvers.certified as certified_door

    scene = grasp_3d(4, instance, friction="pyramid:8")
    reference = qs.solve(scene, method="scip")

    def no_scip(*args: object, **kwargs: object) -> None:
        raise AssertionError("the SCIP search ran")

    monkeypatch.setattr(certified_door, "certified_polyhedral", no_scip)
    solution = qs.solve(scene)
    assert solution.status == reference.status and solution.certified
    assert dict(solution.notes)["certificate"] in PROOFS
