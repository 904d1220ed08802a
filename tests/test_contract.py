"""The status contract: ``solved`` from a default solve means proven unique; an unproven answer says so everywhere.

Scenes where the fast path's first motion is not the only one (found by the
benchmark and by hand) must come out ``ambiguous`` from ``qs.solve(scene)``;
``certify=False`` still gives the fast path's motion, marked as not certified
in the Solution, its JSON and its table.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

import quasistatic as qs
from quasistatic.report import render_solution
from quasistatic.tools.bench.families import grasp_2d, grasp_3d
from random_scenes import random_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def stick_on_two_fingers() -> qs.Scene:
    """A stick (1 kg, com midway) on two fingertips 1 m apart, mu = 0.4 each; the right finger slides
    under it at 0.1 m/s, the left one stays.

    By symmetry each finger carries m g / 2. Friction drags the stick right at the right finger and
    holds it back at the left one. Any stick speed v in [0, 0.1] satisfies the laws: for 0 < v < 0.1
    both contacts slide with opposite frictions mu m g / 2, which balance; at v = 0 the left contact
    rolls and the right slides; at v = 0.1 the right rolls and the left slides. A continuum of motions:
    the rigid model cannot say which happens.
    """
    return qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 2,
            "bodies": {"stick": {"mass": 1.0, "com": [0.0, 0.0]}},
            "movers": {"left": None, "right": {"twist": [0.1, 0.0, 0.0]}},
            "contacts": [
                {"body": "stick", "other": "left", "point": [-0.5, 0.0], "normal": [0.0, 1.0], "mu": 0.4},
                {"body": "stick", "other": "right", "point": [0.5, 0.0], "normal": [0.0, 1.0], "mu": 0.4},
            ],
        }
    )


def test_stick_sliding_on_two_fingers_is_ambiguous_by_default() -> None:
    sol = qs.solve(stick_on_two_fingers())
    assert sol.status == "ambiguous", sol.message
    assert sol.certified
    speeds = [float(m.twists["stick"][0]) for m in sol.solutions]
    extremes = [float(e["stick"][0]) for m in sol.solutions for e in m.extreme_twists]
    assert any(m.continuum for m in sol.solutions)
    # Every listed speed, and every extreme of a continuum, lies in [0, 0.1]; the ends of the interval are reached.
    assert all(-1e-9 <= v <= 0.1 + 1e-9 for v in speeds + extremes)
    assert min(speeds + extremes) == pytest.approx(0.0, abs=1e-9) and max(speeds + extremes) == pytest.approx(0.1, abs=1e-9)


def test_fast_first_motion_is_marked_not_certified() -> None:
    """certify=False returns the fast path's one motion (here: at one end of the continuum), flagged in every output."""
    sol = qs.solve(stick_on_two_fingers(), certify=False)
    assert sol.status == "solved" and sol.method == "fast"
    assert sol.certified is False
    assert sol.to_dict()["certified"] is False and sol.details["uniqueness"] == "not checked"
    buffer = io.StringIO()
    render_solution(sol, Console(file=buffer, width=160))
    assert "NOT certified" in buffer.getvalue()


@pytest.mark.parametrize(("contacts", "instance"), [(4, 4), (6, 2), (6, 4)])
def test_benchmark_grasps_with_several_motions_are_ambiguous_by_default(contacts: int, instance: int) -> None:
    """grasp-2d scenes the fast path called solved: the certified search lists several motions."""
    scene = grasp_2d(contacts, instance)
    assert qs.solve(scene, certify=False).status == "solved"  # the fast path finds one of them
    sol = qs.solve(scene)
    assert sol.status == "ambiguous" and sol.certified, sol.message
    assert len(sol.solutions) >= 2 or any(m.continuum for m in sol.solutions)


@pytest.mark.slow
def test_benchmark_3d_grasp_with_several_motions_is_ambiguous_by_default() -> None:
    sol = qs.solve(grasp_3d(6, 1))
    assert sol.status == "ambiguous", sol.message


@pytest.mark.parametrize("seed", range(12))
def test_a_default_answer_never_contradicts_the_certified_method(seed: int) -> None:
    """Random 2-D scenes: the default answer has the certified method's status, and its twist when solved."""
    scene = random_scene(2, 1000 + seed)
    default, certified = qs.solve(scene), qs.solve(scene, method="scip")
    assert default.status == certified.status
    assert default.certified or default.status == "failed"
    if default.status == "solved":
        for name, twist in certified.twists.items():
            np.testing.assert_allclose(default.twists[name], twist, atol=1e-7)


def test_forces_indeterminate_inside_an_ambiguous_answer() -> None:
    """Two level fingers (mu = 0.5) lift a 0.5 kg box between them at 0.01 m/s.

    Two motions satisfy the laws: the lift (both rolling) and the slip down (both sliding). In the lift
    each finger carries half the weight by friction, so the squeeze N must satisfy mu N >= m g / 2:
    N >= 4.905 N, with no upper bound: that motion's forces are indeterminate, N in [4.905, inf).
    """
    up = {"twist": [0.0, 0.01, 0.0]}
    scene = qs.load_scene(
        {
            "quasistatic": 1,
            "dimension": 2,
            "bodies": {"block": {"mass": 0.5, "com": [0.0, 0.0]}},
            "movers": {"left": up, "right": up},
            "contacts": [
                {"body": "block", "other": "left", "point": [-0.05, 0.0], "normal": [1.0, 0.0], "mu": 0.5},
                {"body": "block", "other": "right", "point": [0.05, 0.0], "normal": [-1.0, 0.0], "mu": 0.5},
            ],
        }
    )
    sol = qs.solve(scene)
    assert sol.status == "ambiguous", sol.message
    lift = next(m for m in sol.solutions if m.modes == ("rolling", "rolling"))
    assert lift.forces_indeterminate and lift.to_dict()["forces_indeterminate"] is True
    for contact in lift.contacts:
        assert contact.normal_force_range is not None
        low, high = contact.normal_force_range
        assert low == pytest.approx(0.5 * 9.81 / 2 / 0.5, rel=1e-6) and high is None


def test_audit_measures_friction_direction_linearly() -> None:
    """Maximum dissipation on exact 3-D cones: a sliding contact's friction must be -mu f_n slip/|slip|.

    Turning each sliding support's friction of the pushed puck by 1e-4 rad about its normal leaves the
    dissipated power short by only mu f_n |slip| (1 - cos 1e-4) ~ 5e-9 of it, which a power measure
    passes; the force is off by |f_t| 1e-4, which the audit must see (its residual is per force scale).
    """
    from quasistatic.check import audit_motion

    scene = qs.load_scene(EXAMPLES / "puck_push_3d.yaml")
    problem = qs.assemble(scene)
    sol = qs.solve(problem, certify=False)
    assert sol.status == "solved" and sol.audit is not None and sol.audit.passed
    forces = np.array([c.force for c in sol.contacts])
    angle = 1e-4
    for i, contact in enumerate(sol.contacts):
        if contact.mode == "sliding":
            n = np.asarray(scene.contacts[i].normal)
            f_n = forces[i] @ n * n
            f_t = forces[i] - f_n
            forces[i] = f_n + f_t * np.cos(angle) + np.cross(n, f_t) * np.sin(angle)
    audit, _ = audit_motion(scene, sol.twists, forces, problem.scales)
    assert audit.dissipation > 10 * audit.tolerance


def test_certified_search_reports_its_progress() -> None:
    """The stick's search finds its two motions (a rolling end and the sliding continuum) and then proves
    there is no third: progress is reported after each step, with the count of motions found so far."""
    seen: list[qs.solvers.SearchProgress] = []
    sol = qs.solve(stick_on_two_fingers(), progress=seen.append)
    assert sol.status == "ambiguous"
    assert [p.motions for p in seen] == sorted(p.motions for p in seen)
    assert seen[-1].motions == len(sol.solutions) == 2
    assert all(p.seconds >= 0.0 and p.nodes >= 0 for p in seen)
