"""Frictional behaviour the catalogue does not cover: friction models, time limits, exact-cone proofs, prescribed modes.

The hand-derived frictional cases (a block on a slope, a box pushed low or
high, two-finger grasps, a finger dragging a box, the friction wedge, the
puck slipping off-axis) live in ``catalogue.py`` and run over every method in
``test_catalogue.py``. Here each test states its statics in the docstring;
expected numbers come from those derivations, never from the library.
g = 9.81 m/s^2, angles counter-clockwise. Methods are chosen by what the
registry says they can do (``catalogue.methods``), never by name lists.
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pytest import approx

import quasistatic as qs
from catalogue import G, Method, methods, puck_data, slope_data, wedge_data
from quasistatic.wedging import wedging_friction

QUASISTATIC = str(Path(sys.executable).with_name("quasistatic"))


def floats(array: Any) -> list[float]:
    return [float(x) for x in np.asarray(array, dtype=float).ravel()]


def check_motion(motion: qs.Motion | qs.Solution, twist: Any, modes: list[str], body: str = "block") -> None:
    assert floats(motion.twists[body]) == approx(floats(twist), abs=1e-7)
    assert [c.mode for c in motion.contacts] == modes
    assert motion.audit is not None and motion.audit.passed, motion.audit


def puck(friction: str) -> qs.Scene:
    """A puck (1 kg, com 0.05 above the table) on four supports at +-0.05 on x and y, mu = 0.5, pushed through
    its centre by a frictionless finger at 0.01 m/s along d = (cos 30, sin 30, 0) (``catalogue.puck_data``)."""
    return qs.load_scene(puck_data(30.0, friction))


D30 = np.array([math.cos(math.radians(30.0)), math.sin(math.radians(30.0)), 0.0])


@pytest.mark.parametrize("method", methods(frictional=True, certifying=True), ids=str)
def test_4_edge_pyramid_bends_the_slip_to_the_diagonal(method: Method) -> None:
    """``friction: pyramid:4`` (edges along +-x and +-y): each support's friction set is the square with
    vertices mu N (+-1, 0), (0, +-1). Maximum dissipation puts the friction of a slip u at the vertex most
    opposed to u, or anywhere on a face when u is normal to that face. The exact answer (translation along
    d at 30 deg, see the catalogue's puck) would put every friction at the vertex -x: net friction along
    -x cannot balance a finger pushing along d. With the slip along the diagonal (1, 1)/sqrt 2 every
    friction lies on the face between -x and -y, which contains -d: w = -(P/(mu m g)) d with unit L1 norm,
    P = mu m g / (cos 30 + sin 30) = 3.5907 N. The finger (normal d) stays closed: v.d = 0.01, so
    v = 0.01 sqrt 2 / (cos 30 + sin 30) (1, 1)/sqrt 2 = (0.007321, 0.007321) and the finger contact slides
    (v is not along d). The centre of pressure 0.05 P/(m g) d lies on the line of d: no yaw moment.
    Every contact slides; the answer names its friction model."""
    sol = method.solve(puck("pyramid:4"))
    assert sol.status == "solved", sol.message
    assert sol.friction == "pyramid:4"
    speed = 0.01 / (D30[0] + D30[1])
    check_motion(sol, [speed, speed, 0, 0, 0, 0], ["sliding"] * 5)
    push = 0.5 * G / (D30[0] + D30[1])
    assert sol.contacts[4].normal_force == approx(push, rel=1e-6)
    assert sum(c.normal_force for c in sol.contacts[:4]) == approx(G, rel=1e-6)
    for c in sol.contacts[:4]:  # on the face between -x and -y: |f_x| + |f_y| = mu N, both <= 0
        assert c.force[0] <= 1e-9 and c.force[1] <= 1e-9
        assert abs(c.force[0]) + abs(c.force[1]) == approx(0.5 * c.normal_force, abs=1e-9)


def test_time_limit_bounds_the_whole_certified_solve_and_claims_nothing() -> None:
    """A search stopped by the time limit reports failed, never a uniqueness or ambiguity it did not prove."""
    problem = qs.assemble(puck("exact"))
    stopped = qs.solve(problem, method="scip", time_limit=1e-6)
    assert stopped.status == "failed"
    assert "time limit" in stopped.message
    assert not stopped.certified


def test_one_motion_from_an_incomplete_search_is_not_solved() -> None:
    """One motion found before the time limit: reported, audited, but failed (uniqueness unproven), not ambiguous.

    The block pushed up the 20 deg slope (catalogue ``slope-push-up-20``) has exactly one motion.
    """
    from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
    from quasistatic.solvers import Options
    from quasistatic.solvers.certify.search import enumerate_motions, summarise

    problem = qs.assemble(qs.load_scene(slope_data(20.0, push=0.01)))
    form = polyhedral_form(problem, aligned_edges(problem, problem.friction.edges))
    motions, complete = enumerate_motions(form, Options())
    assert complete and len(motions) == 1
    assert summarise(form, motions, complete, Options()).status == "solved"
    partial = summarise(form, motions, False, Options())
    assert partial.status == "failed" and "unique" in partial.message and len(partial.motions) == 1


def wedge_3d(mu_floor: float, mu_finger: float) -> qs.Scene:
    """The catalogue's friction wedge (a 1 kg box pushed low on its rear face by a finger moving forward and
    down) extruded along z, contacts at z = +-0.05: the box slides iff mu mu_f < 1, else friction wedges it."""
    from quasistatic.tools.validation import extrude

    return qs.load_scene(extrude(wedge_data(mu_floor, mu_finger), 0.1))


def test_friction_wedge_in_3d_is_jammed_and_proven_for_exact_cones() -> None:
    """mu mu_f = 1.2 > 1: wedged. In 3-D the pyramid's jam proves nothing for the circle: the verdict
    must come with the sector relaxation's certificate (the 2-D wedge is a catalogue case)."""
    sol = qs.solve(wedge_3d(1.2, 1.0), method="scip")
    assert sol.status == "jammed", sol.message
    assert sol.diagnosis is qs.Diagnosis.WEDGED
    assert sol.certificate is not None and sol.certificate.kind is qs.CertificateKind.SECTOR_RELAXATION


def test_sector_relaxation_never_excludes_an_exact_motion() -> None:
    """The wedge proof is sound only if every exact motion satisfies the relaxation: for scenes with
    an audited exact motion, the relaxation (with that motion's modes prescribed) is never infeasible."""
    from quasistatic.solvers import Options
    from quasistatic.solvers.certify.wedge import _relaxation

    for built in (wedge_3d(0.9, 1.0), puck("exact")):
        problem = qs.assemble(built)
        sol = qs.solve(problem, method="scip")
        assert sol.status == "solved"
        for count in (8, 16):
            sectors = [2.0 * np.pi * np.arange(count + 1) / count for _ in range(problem.n_contacts)]
            for modes in (None, sol.modes):
                clock = Options(time_limit=120.0).start_clock()  # a bound against a hang, not a speed check
                assert _relaxation(problem, clock, sectors, modes)[0] == "feasible"


def test_exact_cone_mode_specified_solve() -> None:
    """Prescribed modes with exact 3-D cones: the motion with those modes (even where the 8-edge
    pyramid bends the slip off them), or a proven jammed."""
    exact = puck("exact")
    sliding = qs.solve(exact, modes=["sliding"] * 4 + ["rolling"])
    assert sliding.status == "solved", sliding.message
    check_motion(sliding, [*(0.01 * D30), 0, 0, 0], ["sliding"] * 4 + ["rolling"])
    for modes in ([None] * 4 + ["separating"], ["rolling"] * 4 + [None]):  # the finger pushes in; supports cannot hold
        held = qs.solve(exact, modes=modes)
        assert held.status == "jammed", (modes, held.message)
        assert held.diagnosis is qs.Diagnosis.PRESCRIBED_MODES
        assert held.certificate is not None and held.certificate.kind is qs.CertificateKind.SECTOR_RELAXATION


@pytest.mark.slow
def test_exact_motions_prove_ambiguity_when_another_does_not_refine() -> None:
    """A random 6-contact 3-D grasp (benchmark family) whose 8-edge pyramid has many motions, one of which has
    no exact motion next to it: the exact ones that do refine still prove ``ambiguous`` (list incomplete)."""
    from quasistatic.tools.bench.families import grasp_3d

    sol = qs.solve(grasp_3d(6, 1), method="scip", time_limit=30.0)
    assert sol.status == "ambiguous", sol.message
    assert len(sol.solutions) >= 2 and all(m.audit.passed for m in sol.solutions)
    assert "incomplete" in sol.message or "incomplete" in sol.details.get("exact_cone", "")


def test_a_wedged_jam_names_the_contacts_whose_friction_wedges_it(tmp_path: Path) -> None:
    """The friction wedge (mu mu_f = 1.2 > 1): the finger's friction pushes the box down, the floor's holds it.
    The console script names the contacts whose friction alone jams it, none of which can be spared; re-solving
    checks both halves of that claim."""
    scene_file = tmp_path / "wedge.json"
    scene_file.write_text(json.dumps(wedge_data(1.2, 1.0)))
    text = subprocess.run([QUASISTATIC, "solve", str(scene_file)], capture_output=True, text=True, check=True).stdout
    assert "friction at contacts #0 (box/floor), #1 (box/floor), #2 (box/finger) wedges it" in " ".join(text.split())
    answer = json.loads(
        subprocess.run([QUASISTATIC, "solve", str(scene_file), "--json"], capture_output=True, text=True, check=True).stdout
    )
    assert answer["status"] == "jammed" and answer["diagnosis"] == "wedged"
    assert answer["details"]["wedging_friction"] == [0, 1, 2]
    scene = qs.load_scene(wedge_data(1.2, 1.0))
    for spared in range(3):  # without friction at any one of them, the box moves
        contacts = tuple(dataclasses.replace(c, mu=0.0) if i == spared else c for i, c in enumerate(scene.contacts))
        assert qs.solve(dataclasses.replace(scene, contacts=contacts)).status != "jammed"


def test_a_wedged_jam_leaves_out_friction_it_does_not_need() -> None:
    """A second finger pad touching the box's top with friction, moving along with it, plays no part in the wedge
    (made frictionless, the jam stays): it is not named."""
    data = wedge_data(1.2, 1.0)
    data["movers"]["pad"] = {"twist": [0.0, 0.0, 0.0]}
    data["contacts"].append({"body": "box", "other": "pad", "point": [0.0, 0.1], "normal": [0.0, -1.0], "mu": 0.3})
    scene = qs.load_scene(data)
    solution = qs.solve(scene)
    assert solution.status == "jammed" and solution.diagnosis is qs.Diagnosis.WEDGED
    assert wedging_friction(scene) == (0, 1, 2)


def _fall_checks(scene: qs.Scene, twist: np.ndarray) -> None:
    """A Farkas twist of "no equilibrium", checked from the scene data alone: the load does work along it, and at
    every contact its velocity lies in the friction cone's dual (u_n >= mu |u_t|), where no force in the cone
    takes work away."""
    body = scene.bodies[0]
    d = scene.dimension
    v, w = twist[:d], twist[d:]
    weight = body.mass * scene.gravity
    assert float(weight @ v) > 1e-6
    for contact in scene.contacts:
        r = contact.point - body.com
        u = v + (w[0] * np.array([-r[1], r[0]]) if d == 2 else np.cross(w, r))
        u_n = float(u @ contact.normal)
        u_t = np.linalg.norm(u - u_n * contact.normal)
        assert u_n >= contact.mu * u_t - 1e-9, (u_n, u_t)


@pytest.mark.parametrize("dimension", [2, 3])
def test_an_unstable_answer_names_a_direction_no_contact_force_resists(dimension: int) -> None:
    """A block on a 30 degree slope with mu = 0.5 < tan 30: no equilibrium. The certificate carries a twist along
    which the weight does work and every contact opens inside its cone's dual, so no contact force can take that
    work away (with exact 3-D cones, proven through a polygon around each circle)."""
    scene = qs.load_scene(slope_data(30.0)) if dimension == 2 else _extruded(slope_data(30.0))
    solution = qs.solve(scene)
    assert solution.status == "unstable" and solution.certified
    assert solution.certificate is not None and solution.certificate.kind is qs.CertificateKind.INFEASIBLE_EQUILIBRIUM
    twist = np.asarray(solution.certificate.data, dtype=float)
    assert twist.size == (3 if dimension == 2 else 6) and np.max(np.abs(twist)) == pytest.approx(1.0)
    _fall_checks(scene, twist)


def _extruded(data: dict[str, Any]) -> qs.Scene:
    from quasistatic.tools.validation import extrude

    return qs.load_scene(extrude(data, 0.1))


def test_the_console_script_says_which_way_an_unstable_block_goes(tmp_path: Path) -> None:
    scene_file = tmp_path / "slope.json"
    scene_file.write_text(json.dumps(slope_data(30.0)))
    text = subprocess.run([QUASISTATIC, "solve", str(scene_file)], capture_output=True, text=True, check=True).stdout
    assert "the load does work along the twist" in " ".join(text.split())
