"""The vertex certificate's seed claim in Python floats (``certify/arrangement_floats.py``) against the array code.

On few planes, :func:`prove_by_vertices` first tries "the seed is the only motion" in floats and runs the array code
only where that proves nothing. Its verdicts must be the array code's, verdict for verdict and with the same number of
triples solved, and the proofs it returns the same values (the seed itself, to the last bit): on the turning run's
problems (the simulation's steps), on the benchmark's planar grasps of 1 to 3 contacts, with and without friction,
and on random planar scenes. The float path must also decide where the arrays say "unique" with a seed (else the
speed-up would be lost and these tests would pass on nothing). Measured on 3,200 grasps and 3,000 random scenes:
every verdict the same, and every seeded unique one of at most six planes proven in floats.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
import quasistatic.solvers.certified as certified_door
from quasistatic.laws.polyhedral import LCPForm, aligned_edges, polyhedral_form
from quasistatic.solvers.certify import arrangement_floats
from quasistatic.solvers.certify.arrangement import VertexProof, VertexVerdict, prove_by_vertices
from quasistatic.solvers.certify.cheap import seed_point
from quasistatic.tolerances import FLOAT_ARRANGEMENT_PLANES
from quasistatic.tools.bench.families import grasp_2d
from random_scenes import random_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _form(scene: qs.Scene) -> LCPForm:
    problem = qs.assemble(scene)
    return polyhedral_form(problem, aligned_edges(problem, problem.friction.edges))


def _planes(form: LCPForm) -> int:
    problem = form.problem
    return problem.n_contacts + int(np.count_nonzero(problem.mu > 0.0))


def _both(form: LCPForm, monkeypatch: pytest.MonkeyPatch) -> tuple[VertexProof, VertexProof, bool]:
    """The proof with the float path, the array code's alone, and whether the float path proved it."""
    seed = seed_point(form)
    proved = seed is not None and arrangement_floats.seed_is_only_motion(form, seed[:3].tolist()) is not None
    with_floats = prove_by_vertices(form, seed)
    with monkeypatch.context() as patch:
        patch.setattr(arrangement_floats, "FLOAT_ARRANGEMENT_PLANES", 0)  # every problem through the arrays
        arrays = prove_by_vertices(form, seed)
    return with_floats, arrays, proved


def _assert_same(with_floats: VertexProof, arrays: VertexProof) -> None:
    assert (with_floats.verdict, with_floats.triples, with_floats.equilibrium, with_floats.admissible) == (
        arrays.verdict,
        arrays.triples,
        arrays.equilibrium,
        arrays.admissible,
    )
    assert (with_floats.seed is None) == (arrays.seed is None)
    assert with_floats.seed is None or arrays.seed is None or with_floats.seed.tobytes() == arrays.seed.tobytes()
    assert len(with_floats.motions) == len(arrays.motions)
    assert all(a.tobytes() == b.tobytes() for a, b in zip(with_floats.motions, arrays.motions, strict=True))


def _compared(forms: Iterator[LCPForm], monkeypatch: pytest.MonkeyPatch) -> tuple[int, int]:
    """How many seeded unique verdicts on few planes the arrays gave, and how many of them the floats proved."""
    unique = proved_count = 0
    for form in forms:
        with_floats, arrays, proved = _both(form, monkeypatch)
        _assert_same(with_floats, arrays)
        few = _planes(form) <= FLOAT_ARRANGEMENT_PLANES and seed_point(form) is not None
        if few and arrays.verdict is VertexVerdict.UNIQUE:
            unique += 1
            proved_count += proved
        assert not proved or arrays.verdict is VertexVerdict.UNIQUE
    return unique, proved_count


def test_the_turning_runs_steps_are_proven_in_floats_as_by_the_arrays(monkeypatch: pytest.MonkeyPatch) -> None:
    forms: list[LCPForm] = []
    prove = certified_door.prove_by_vertices

    def kept(form: LCPForm, seed: np.ndarray | None, max_solutions: int | None = None) -> VertexProof:
        forms.append(form)
        return prove(form, seed, max_solutions)

    monkeypatch.setattr(certified_door, "prove_by_vertices", kept)
    run = qs.simulate(EXAMPLES / "sim" / "tip_box_planar.yaml", duration=2.0, dt=0.05, ambiguous="stop")
    monkeypatch.undo()
    assert run.status == "completed" and len(forms) >= len(run.steps) >= 40  # a box turning: every step proven anew
    unique, proved = _compared(iter(forms), monkeypatch)
    assert unique == proved == len(forms)


@pytest.mark.parametrize("friction", ["exact", "none"])
@pytest.mark.parametrize("contacts", [1, 2, 3])
def test_benchmark_grasps_get_the_array_verdicts(contacts: int, friction: str, monkeypatch: pytest.MonkeyPatch) -> None:
    unique, proved = _compared((_form(grasp_2d(contacts, instance, friction)) for instance in range(25)), monkeypatch)
    assert proved == unique


def test_random_planar_scenes_get_the_array_verdicts(monkeypatch: pytest.MonkeyPatch) -> None:
    scenes = (random_scene(2, 2000 + seed, friction="none" if seed % 5 == 4 else "exact") for seed in range(60))
    unique, proved = _compared((_form(scene) for scene in scenes), monkeypatch)
    assert proved == unique >= 10


def test_more_planes_than_the_limit_go_to_the_arrays() -> None:
    form = _form(grasp_2d(4, 0))  # 4 frictional contacts: 8 planes
    seed = seed_point(form)
    assert _planes(form) > FLOAT_ARRANGEMENT_PLANES and seed is not None
    assert arrangement_floats.seed_is_only_motion(form, seed[:3].tolist()) is None
