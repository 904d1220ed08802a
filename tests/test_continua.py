"""Every extreme of a listed continuum is a motion, audited as one: in Python and in the JSON of the console script.

A continuum is described by its extreme twists; each must satisfy the laws with forces of its own (on the exact
cones for exact 3-D friction: the pyramid's extremes are refined, and only those the exact cones carry are kept).
The audit (``check/``) judges each with the forces the method found there; an extreme that fails is not listed as a
motion but kept apart as unproven.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.laws import RawMotion, physical_twists
from quasistatic.model.io import scene_to_dict
from quasistatic.solve import audited_raw_motion
from quasistatic.solvers import Options, get_backend
from quasistatic.tools.bench.families import box_push

SCRIPT = Path(sys.executable).with_name("quasistatic")


def continua(solution: qs.Solution) -> list[qs.Motion]:
    return [motion for motion in solution.solutions if motion.continuum]


@pytest.mark.parametrize("instance", range(6))
def test_each_extreme_of_a_certified_exact_cone_continuum_passed_its_own_audit(instance: int) -> None:
    """Random 3-D boxes pushed on one support (the benchmark's box-push family, exact cones): certified ambiguous,
    their continua's extremes each audited with the forces found at it."""
    solution = qs.solve(box_push(1, instance))
    assert solution.status == "ambiguous" and solution.certified and solution.friction == "exact"
    assert continua(solution)
    for motion in continua(solution):
        assert motion.audit.passed
        assert len(motion.extreme_audits) == len(motion.extreme_twists) >= 1
        assert all(audit.passed for audit in motion.extreme_audits)
        assert motion.unproven_extremes == ()
        out = motion.to_dict()
        assert [a["passed"] for a in out["extreme_audits"]] == [True] * len(motion.extreme_twists)


def certified_continuum(problem: qs.Problem) -> RawMotion:
    """The first continuum the certified method gives, in the problem's units, with the forces at its extremes."""
    result = get_backend("certified").solver(problem, Options())
    return next(m for m in result.motions if m.continuum)


def test_an_extreme_that_fails_its_audit_is_not_listed_but_kept_as_unproven() -> None:
    """A continuum with its true extreme and a made-up one whose forces (the true extreme's) cannot hold there."""
    problem = qs.assemble(box_push(1, 0))
    motion = certified_continuum(problem)
    assert len(motion.extreme_forces) == len(motion.extremes) >= 1
    bogus = motion.extremes[0] + 0.3  # every twist entry moved
    extremes, forces = (motion.extremes[0], bogus), (motion.extreme_forces[0], motion.extreme_forces[0])
    audited = audited_raw_motion(
        problem, RawMotion(motion.q, motion.c, extremes, motion.unbounded, motion.free_axes, extreme_forces=forces)
    )
    assert len(audited.extreme_twists) == 1 and audited.extreme_audits[0].passed
    (refused,) = audited.unproven_extremes
    assert refused.audit is not None and not refused.audit.passed
    np.testing.assert_allclose(refused.twists["box"], physical_twists(problem, bogus)["box"])
    out = audited.to_dict()
    assert len(out["extreme_twists"]) == 1 and out["unproven_extremes"][0]["audit"]["passed"] is False


def test_an_extreme_without_forces_is_not_listed() -> None:
    problem = qs.assemble(box_push(1, 0))
    motion = certified_continuum(problem)
    audited = audited_raw_motion(problem, RawMotion(motion.q, motion.c, motion.extremes, motion.unbounded, motion.free_axes))
    assert audited.extreme_twists == () and len(audited.unproven_extremes) == len(motion.extremes)
    assert all(extreme.audit is None for extreme in audited.unproven_extremes)


def test_the_json_of_the_console_script_carries_each_extremes_audit(tmp_path: Path) -> None:
    path = tmp_path / "push.json"
    path.write_text(json.dumps(scene_to_dict(box_push(1, 1))))
    result = subprocess.run([str(SCRIPT), "solve", str(path), "--json"], capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    answer = json.loads(result.stdout)
    assert answer["status"] == "ambiguous"
    listed = [m for m in answer["solutions"] if m.get("continuum")]
    assert listed
    for motion in listed:
        assert len(motion["extreme_audits"]) == len(motion["extreme_twists"]) >= 1
        assert all(audit["passed"] for audit in motion["extreme_audits"])
        assert motion["unproven_extremes"] == []
    text = subprocess.run([str(SCRIPT), "solve", str(path)], capture_output=True, text=True, timeout=120, check=False)
    assert "extreme twists (each audited with forces found at it):" in text.stdout
