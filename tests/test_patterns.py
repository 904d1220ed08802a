"""The planar mode branch and bound (``certify/patterns.py``) against the complete SCIP search.

Property: the branch and bound never says "unique" (or "no motion") where
``method="scip"`` says otherwise, on 240 random 2-D scenes (with and without
friction; 600 more with ``pytest -m slow``), the 2-D benchmark grasps, and degenerate scenes: a finger touching
with zero force, equal loads (a continuum), a box resting on a table with a
still finger. And it decides most scenes, so the property is not met by
proving nothing. Then: the default ``certified`` method takes this path on the
benchmark grasps (the certificate names it, and SCIP is not run).
"""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certified as certified_door
from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
from quasistatic.solvers.certify.cheap import seed_point
from quasistatic.solvers.certify.patterns import NO_MOTION_PROOF, PATTERN_PROOF, PatternVerdict, prove_by_patterns
from quasistatic.tools.bench.families import grasp_2d
from random_scenes import random_scene

TWIST_RTOL = 1e-6  # scene-relative agreement of the proven twist with SCIP's


def _stick(right_speed: float, left_speed: float = 0.0) -> qs.Scene:
    """A stick on two fingertips 1 m apart, com midway (equal loads); at different finger speeds every stick
    speed between them is a motion (a continuum)."""
    return qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 2,
            "bodies": {"stick": {"mass": 1.0, "com": [0.0, 0.0]}},
            "movers": {"left": {"twist": [left_speed, 0.0, 0.0]}, "right": {"twist": [right_speed, 0.0, 0.0]}},
            "contacts": [
                {"body": "stick", "other": "left", "point": [-0.5, 0.0], "normal": [0.0, 1.0], "mu": 0.4},
                {"body": "stick", "other": "right", "point": [0.5, 0.0], "normal": [0.0, 1.0], "mu": 0.4},
            ],
        }
    )


def _box(finger_twist: list[float], finger_y: float = 0.05, mu_table: float = 0.5) -> qs.Scene:
    """A 0.2 x 0.1 box on two table corners with a finger on its left face (touching: zero gap)."""
    return qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 2,
            "bodies": {"box": {"mass": 1.0, "com": [0.0, 0.05]}},
            "movers": {"table": None, "finger": {"twist": finger_twist, "origin": [-0.1, finger_y]}},
            "contacts": [
                {"body": "box", "other": "table", "point": [-0.1, 0.0], "normal": [0.0, 1.0], "mu": mu_table},
                {"body": "box", "other": "table", "point": [0.1, 0.0], "normal": [0.0, 1.0], "mu": mu_table},
                {"body": "box", "other": "finger", "point": [-0.1, finger_y], "normal": [1.0, 0.0], "mu": 0.3},
            ],
        }
    )


DEGENERATE = {
    "stick, one finger sliding (continuum)": _stick(0.1),
    "stick, fingers still": _stick(0.0),
    "stick, fingers equal speed": _stick(0.1, 0.1),
    "stick, fingers opposite": _stick(0.1, -0.1),
    "box at rest, finger touching with zero force": _box([0.0, 0.0, 0.0]),
    "box pushed at mid-height": _box([0.05, 0.0, 0.0]),
    "box pushed high (tips or slides)": _box([0.05, 0.0, 0.0], finger_y=0.1),
    "box, finger sliding along its face": _box([0.0, 0.05, 0.0]),
    "box, finger pulling away": _box([-0.05, 0.0, 0.0]),
    "box on frictionless table pushed": _box([0.05, 0.0, 0.0], mu_table=0.0),
    "box on frictionless table, finger still": _box([0.0, 0.0, 0.0], mu_table=0.0),
}


def _reference_twist(problem: qs.Problem, motion: qs.Motion) -> np.ndarray:
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    return np.concatenate([motion.twists[b.name] for b in problem.scene.bodies]) / units


def _close(twist: np.ndarray, q: np.ndarray) -> bool:
    return bool(np.max(np.abs(q - twist)) <= TWIST_RTOL * max(1.0, float(np.max(np.abs(twist)))))


def _proof_agrees_with_scip(scene: qs.Scene) -> PatternVerdict:
    """The branch and bound's verdict, after checking it against the SCIP search on the same scene."""
    problem = qs.assemble(scene)
    form = polyhedral_form(problem, aligned_edges(problem, problem.friction.edges))
    proof = prove_by_patterns(form, seed_point(form))
    reference = qs.solve(problem, method="scip")
    if proof.verdict is PatternVerdict.UNIQUE:
        assert proof.seed is not None
        q = proof.seed[: form.n_q]
        assert reference.status == "solved", f"patterns: unique; scip: {reference.message}"
        assert reference.motion is not None
        assert _close(_reference_twist(problem, reference.motion), q)
    elif proof.verdict is PatternVerdict.NONE:
        assert reference.status in ("jammed", "unstable"), f"patterns: no motion; scip: {reference.message}"
    return proof.verdict


@pytest.mark.parametrize("chunk", range(8))
def test_pattern_proof_never_contradicts_scip_on_random_scenes(chunk: int) -> None:
    verdicts = []
    for seed in range(30 * chunk, 30 * (chunk + 1)):
        friction = "none" if seed % 5 == 4 else "exact"  # one in five frictionless: every cone a ray
        verdicts.append(_proof_agrees_with_scip(random_scene(2, 1000 + seed, friction=friction)))
    decided = sum(v is not PatternVerdict.UNDECIDED for v in verdicts)
    assert decided >= 0.6 * len(verdicts), f"only {decided} of {len(verdicts)} decided"


@pytest.mark.slow
@pytest.mark.parametrize("chunk", range(8, 28))
def test_pattern_proof_never_contradicts_scip_on_random_scenes_sweep(chunk: int) -> None:
    test_pattern_proof_never_contradicts_scip_on_random_scenes(chunk)


@pytest.mark.parametrize("name", sorted(DEGENERATE))
def test_pattern_proof_never_contradicts_scip_on_degenerate_scenes(name: str) -> None:
    _proof_agrees_with_scip(DEGENERATE[name])


def test_pattern_proof_leaves_a_continuum_to_the_search() -> None:
    assert _proof_agrees_with_scip(DEGENERATE["stick, one finger sliding (continuum)"]) is PatternVerdict.UNDECIDED


@pytest.mark.parametrize(("contacts", "instance"), [(m, i) for m in (2, 3, 4, 6, 8) for i in range(8)])
def test_pattern_proof_never_contradicts_scip_on_benchmark_grasps(contacts: int, instance: int) -> None:
    _proof_agrees_with_scip(grasp_2d(contacts, instance))


# Benchmark grasps that Lemke alone cannot certify: solved (with or without a Lemke point), jammed, unstable.
PATTERN_DECIDED = {(2, 0): "solved", (2, 2): "solved", (2, 3): "unstable", (2, 6): "jammed", (3, 1): "solved", (4, 0): "solved"}


@pytest.mark.parametrize(("contacts", "instance"), sorted(PATTERN_DECIDED))
def test_certified_grasps_are_proven_by_the_mode_branch_and_bound_without_scip(
    contacts: int, instance: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_scip(*args: object, **kwargs: object) -> None:
        raise AssertionError("the SCIP search ran")

    monkeypatch.setattr(certified_door, "certified_polyhedral", no_scip)
    solution = qs.solve(grasp_2d(contacts, instance))
    assert solution.status == PATTERN_DECIDED[(contacts, instance)]
    assert solution.certified
    proof = PATTERN_PROOF if solution.status == "solved" else NO_MOTION_PROOF
    assert dict(solution.notes)["certificate"] == proof
