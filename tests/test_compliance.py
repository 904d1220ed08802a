"""Compliance: the forces of least elastic energy, checked against classical statically indeterminate results.

Each expected force is a hand-derived formula (compatibility of the spring
deflections of a rigid body), not a solver output.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs

G = 9.81
QUASISTATIC = str(Path(sys.executable).with_name("quasistatic"))


def _plane_of_springs(points: np.ndarray, stiffness: np.ndarray, load: float, at: np.ndarray) -> np.ndarray:
    """Vertical spring forces under a rigid body loaded by ``load`` at ``at`` (x or (x, y) per support).

    The body's deflection is a plane w(x) = w0 + theta . (x - centroid); each force k_i w(x_i).
    With the stiffness-weighted centroid and second moments the equations decouple:
    f_i = k_i [P / K + (P (e - c))^T I^-1 (x_i - c)], K = sum k, c = sum k x / K, I = sum k (x - c)(x - c)^T.
    """
    points = points.reshape(len(stiffness), -1)
    total = stiffness.sum()
    centre = stiffness @ points / total
    arms = points - centre
    inertia = np.einsum("i,ij,ik->jk", stiffness, arms, arms)
    tilt = np.linalg.solve(inertia, load * (np.atleast_1d(at) - centre))
    return stiffness * (load / total + arms @ tilt)


def _beam(stiffness: list[float], load_at: float, scale_length: float = 1.0, scale_mass: float = 1.0) -> qs.Scene:
    """A rigid beam on supports at x = -0.4, 0.1, 0.5 (a table, with friction), loaded by its weight at ``load_at``."""
    L, M = scale_length, scale_mass
    force = M * L  # unit of force in the scaled units (mass x length / s^2)
    contacts = [
        qs.Contact("beam", "ground", [x * L, 0.0], [0.0, 1.0], mu=0.5, stiffness=qs.Stiffness(k * force / L, 2.0 * k * force / L))
        for x, k in zip((-0.4, 0.1, 0.5), stiffness, strict=True)
    ]
    return qs.Scene([qs.Body("beam", 2.0 * M, [load_at * L, 0.02 * L])], contacts, [qs.Mover("ground")], dimension=2, gravity=[0, -G * L])


def test_rigid_beam_on_three_springs_by_compatibility() -> None:
    stiffness = np.array([1.0e4, 3.0e4, 2.0e4])
    rigid = qs.solve(
        qs.Scene(
            _beam(list(stiffness), 0.05).bodies,
            [_rigid(c) for c in _beam(list(stiffness), 0.05).contacts],
            [qs.Mover("ground")],
            dimension=2,
        )
    )
    assert rigid.status == "solved" and rigid.forces_indeterminate and not rigid.compliant_forces
    solution = qs.solve(_beam(list(stiffness), 0.05))
    assert solution.status == "solved" and solution.compliant_forces and not solution.forces_indeterminate
    assert solution.audit is not None and solution.audit.passed
    expected = _plane_of_springs(np.array([-0.4, 0.1, 0.5]), stiffness, 2.0 * G, np.array([0.05]))
    np.testing.assert_allclose([c.normal_force for c in solution.contacts], expected, rtol=1e-7)
    np.testing.assert_allclose([c.force[0] for c in solution.contacts], 0.0, atol=1e-7)
    assert all(c.normal_force_range is None for c in solution.contacts)
    assert "compliance determines the contact forces" in solution.message


def _rigid(contact: qs.Contact) -> qs.Contact:
    return qs.Contact(contact.body, contact.other, contact.point, contact.normal, contact.mu)


def test_stiffer_support_carries_more() -> None:
    """Moving stiffness to the middle support moves load to it: the forces follow the springs, not a vertex."""
    soft = qs.solve(_beam([1.0e4, 1.0e4, 1.0e4], 0.0))
    stiff = qs.solve(_beam([1.0e4, 1.0e6, 1.0e4], 0.0))
    assert stiff.contacts[1].normal_force > soft.contacts[1].normal_force + 1.0
    np.testing.assert_allclose(sum(c.normal_force for c in stiff.contacts), 2.0 * G, rtol=1e-9)


def test_scale_invariance_mm_g() -> None:
    """The same beam in millimetres and grams: forces x 1e6 (g mm / s^2 per N), the same split."""
    metres = qs.solve(_beam([1.0e4, 3.0e4, 2.0e4], 0.05))
    millimetres = qs.solve(_beam([1.0e4, 3.0e4, 2.0e4], 0.05, scale_length=1e3, scale_mass=1e3))
    assert millimetres.compliant_forces
    np.testing.assert_allclose([c.normal_force / 1e6 for c in millimetres.contacts], [c.normal_force for c in metres.contacts], rtol=1e-7)


def _table(friction: str, load_at: tuple[float, float], stiffness: qs.Stiffness | None = None, legs: list[bool] | None = None) -> qs.Scene:
    """A 3-D table top on four legs at (+-0.3, +-0.2), its 10 kg load at ``load_at``; ``legs`` marks the springy ones."""
    corners = [(-0.3, -0.2), (0.3, -0.2), (0.3, 0.2), (-0.3, 0.2)]
    springy = legs or [True] * 4
    spring = stiffness or qs.Stiffness(5.0e4)
    contacts = [
        qs.Contact("top", "floor", [x, y, 0.0], [0, 0, 1], mu=0.6, stiffness=spring if s else None)
        for (x, y), s in zip(corners, springy, strict=True)
    ]
    body = qs.Body("top", 10.0, [load_at[0], load_at[1], 0.3])
    return qs.Scene([body], contacts, [qs.Mover("floor")], friction=friction)


@pytest.mark.parametrize("friction", ["exact", "pyramid:8"])
def test_table_on_four_compliant_legs(friction: str) -> None:
    solution = qs.solve(_table(friction, (0.08, -0.05)))
    assert solution.status == "solved" and solution.compliant_forces and not solution.forces_indeterminate
    assert solution.audit is not None and solution.audit.passed
    # Equal legs at (+-a, +-b): f_i = P/4 (1 + e_x x_i / a^2 + e_y y_i / b^2).
    a, b, P = 0.3, 0.2, 10.0 * G
    signs = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    by_hand = P / 4 * (1 + 0.08 * signs[:, 0] * a / a**2 + -0.05 * signs[:, 1] * b / b**2)
    np.testing.assert_allclose([c.normal_force for c in solution.contacts], by_hand, rtol=1e-6)
    corners = signs * np.array([a, b])
    np.testing.assert_allclose(by_hand, _plane_of_springs(corners, np.full(4, 5.0e4), P, np.array([0.08, -0.05])), rtol=1e-12)
    np.testing.assert_allclose([np.linalg.norm(c.force[:2]) for c in solution.contacts], 0.0, atol=1e-6)


def test_rigid_legs_leave_the_forces_indeterminate() -> None:
    """Two rigid legs can push against each other along the line between them: compliance cannot fix that."""
    solution = qs.solve(_table("pyramid:8", (0.0, 0.0), legs=[True, False, True, False]))
    assert solution.status == "solved" and solution.forces_indeterminate and not solution.compliant_forces
    assert "rigid loaded contacts #1, #3" in solution.details["compliance"]


def test_joint_stiffness_in_series_with_the_contact() -> None:
    """The middle support is a robot's prismatic finger: its joint spring and the contact's act in series."""
    beam = _beam([1.0e4, 3.0e4, 2.0e4], 0.05)
    finger = qs.Contact("beam", "finger", [0.1, 0.0], [0.0, 1.0], mu=0.5, stiffness=qs.Stiffness(3.0e4, 6.0e4), jacobian=[[0.0], [1.0]])
    robot = qs.Robot("arm", [0.0], joint_stiffness=[1.5e4])
    scene = qs.Scene(
        beam.bodies,
        [beam.contacts[0], finger, beam.contacts[2]],
        [qs.Mover("ground"), qs.Mover("finger", robot="arm")],
        [robot],
        dimension=2,
    )
    solution = qs.solve(scene)
    assert solution.compliant_forces
    series = 1.0 / (1.0 / 3.0e4 + 1.0 / 1.5e4)  # 1e4
    expected = _plane_of_springs(np.array([-0.4, 0.1, 0.5]), np.array([1.0e4, series, 2.0e4]), 2.0 * G, np.array([0.05]))
    np.testing.assert_allclose([c.normal_force for c in solution.contacts], expected, rtol=1e-7)
    np.testing.assert_allclose(solution.robot_loads[0].torques, [expected[1]], rtol=1e-7)


def test_scene_file_keys_and_round_trip(tmp_path: Path) -> None:
    text = """
quasistatic: 1
dimension: 2
stiffness: {normal: 10000.0, tangential: 20000.0}
bodies:
  beam: {mass: 2.0, com: [0.05, 0.02]}
movers:
  ground:
contacts:
  - {body: beam, other: ground, point: [-0.4, 0.0], normal: [0, 1], mu: 0.5}
  - {body: beam, other: ground, point: [0.1, 0.0], normal: [0, 1], mu: 0.5, stiffness: {normal: 30000.0, tangential: 60000.0}}
  - {body: beam, other: ground, point: [0.5, 0.0], normal: [0, 1], mu: 0.5, stiffness: {normal: 20000.0, tangential: 40000.0}}
"""
    path = tmp_path / "beam.yaml"
    path.write_text(text)
    scene = qs.load_scene(path)
    assert scene.contacts[0].stiffness == qs.Stiffness(1.0e4, 2.0e4) and scene.contacts[1].stiffness == qs.Stiffness(3.0e4, 6.0e4)
    again = qs.load_scene(qs.model.io.scene_to_dict(scene))
    assert [c.stiffness for c in again.contacts] == [c.stiffness for c in scene.contacts]
    out = json.loads(subprocess.run([QUASISTATIC, "solve", str(path), "--json"], capture_output=True, text=True, check=True).stdout)
    assert out["status"] == "solved" and out["compliant_forces"] is True and out["forces_indeterminate"] is False
    expected = _plane_of_springs(np.array([-0.4, 0.1, 0.5]), np.array([1.0e4, 3.0e4, 2.0e4]), 2.0 * G, np.array([0.05]))
    np.testing.assert_allclose([c["normal_force"] for c in out["contacts"]], expected, rtol=1e-7)
    assert all("normal_force_range" not in c for c in out["contacts"])
    table = subprocess.run([QUASISTATIC, "solve", str(path)], capture_output=True, text=True, check=True).stdout
    assert "forces: compliant" in table and "f_n range" not in table


@pytest.mark.parametrize(
    ("entry", "field"),
    [
        ("stiffness: {normal: -1.0}", "contacts[0].stiffness.normal"),
        ("stiffness: {normal: 1.0, tangential: 0}", "contacts[0].stiffness.tangential"),
        ("stiffness: {normal: .nan}", "contacts[0].stiffness.normal"),
        ("stiffness: {tangential: 1.0}", "contacts[0].stiffness.normal"),
    ],
)
def test_bad_stiffness_is_one_error_line(tmp_path: Path, entry: str, field: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(
        "quasistatic: 1\ndimension: 2\nbodies: {box: {mass: 1, com: [0, 0.1]}}\nmovers: {ground: }\n"
        f"contacts:\n  - {{body: box, other: ground, point: [0, 0], normal: [0, 1], {entry}}}\n"
    )
    result = subprocess.run([QUASISTATIC, "solve", str(path)], capture_output=True, text=True)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and field in lines[0] and "Traceback" not in result.stderr


def test_joint_stiffness_must_match_the_joints() -> None:
    with pytest.raises(qs.SceneError, match="expected 2 numbers") as error:
        qs.Robot("arm", [0.0, 0.0], joint_stiffness=[1.0])
    assert error.value.field == "robots.arm.joint_stiffness"
    with pytest.raises(qs.SceneError, match="> 0"):
        qs.Robot("arm", [0.0], joint_stiffness=[0.0])


def _energy(solution: qs.Solution, scene: qs.Scene) -> float:
    """1/2 sum f_n^2 / k_n + |f_t|^2 / k_t over the contacts, by hand."""
    total = 0.0
    for result, contact in zip(solution.contacts, scene.contacts, strict=True):
        assert contact.stiffness is not None
        tangential = np.linalg.norm(result.force) ** 2 - result.normal_force**2
        total += 0.5 * (result.normal_force**2 / contact.stiffness.normal + tangential / contact.stiffness.tangential)
    return total


def test_exact_cone_active_at_the_optimum() -> None:
    """A push on the table top: the slippery, stiff leg's share reaches its cone, where SCIP holds it.

    The exact cones contain the inscribed 64-edge pyramid, so their optimum has no more energy, and at most
    1 - cos(pi/64) = 0.12 % of the friction less.
    """

    def scene(friction: str) -> qs.Scene:
        table = _table(friction, (0.0, 0.0))
        legs = [
            qs.Contact(
                c.body, c.other, c.point, c.normal, mu=0.05 if i == 0 else 0.6, stiffness=qs.Stiffness(5.0e4, 5.0e5 if i == 0 else 5.0e4)
            )
            for i, c in enumerate(table.contacts)
        ]
        body = qs.Body("top", 10.0, [0.0, 0.0, 0.3], wrench=[20.0, 10.0, 0.0, 0.0, 0.0, 0.0])
        return qs.Scene([body], legs, table.movers, friction=friction)

    exact, pyramid = qs.solve(scene("exact")), qs.solve(scene("pyramid:64"), certify=False)  # the rest is not in question
    assert exact.status == "solved" and exact.compliant_forces and exact.audit is not None and exact.audit.passed
    leg = exact.contacts[0]
    np.testing.assert_allclose(np.linalg.norm(leg.force[:2]), 0.05 * leg.normal_force, rtol=1e-5)  # on its cone
    assert pyramid.compliant_forces
    energy, bound = _energy(exact, scene("exact")), _energy(pyramid, scene("pyramid:64"))
    assert energy <= bound * (1 + 1e-6) and energy >= bound * (1 - 5e-3)


# --------------------------------------------------------------------------- the compliant step (a squeeze)


def _grasp(
    closing_time: float,
    *,
    gravity: float = G,
    k: tuple[float, float] = (2000.0, 2000.0),
    kt: tuple[float, float] = (1000.0, 1000.0),
    mu: float = 0.8,
    length: float = 1.0,
    mass: float = 1.0,
) -> qs.Scene:
    """A 0.5 kg box (0.1 wide) between two fingers at its com's height, closing at 0.01 each; springs k (normal), kt."""
    L, M = length, mass
    contacts = [
        qs.Contact("box", "left", [-0.05 * L, 0.05 * L], [1.0, 0.0], mu=mu, stiffness=qs.Stiffness(k[0] * M, kt[0] * M)),
        qs.Contact("box", "right", [0.05 * L, 0.05 * L], [-1.0, 0.0], mu=mu, stiffness=qs.Stiffness(k[1] * M, kt[1] * M)),
    ]
    movers = [qs.Mover("left", [0.01 * L, 0.0, 0.0]), qs.Mover("right", [-0.01 * L, 0.0, 0.0])]
    body = qs.Body("box", 0.5 * M, [0.0, 0.05 * L])
    return qs.Scene([body], contacts, movers, dimension=2, gravity=[0.0, -gravity * L], closing_time=closing_time)


@pytest.mark.parametrize("closing_time", [0.1, 0.2, 0.4])
def test_rigid_squeeze_is_jammed_compliant_squeeze_grows_with_closing(closing_time: float) -> None:
    """Frictionless, no gravity, springs 1000 and 3000 in series: N = 2 v h / (1/k1 + 1/k2) = 1500 v h."""
    solution = qs.solve(_grasp(closing_time, gravity=0.0, k=(1000.0, 3000.0), mu=0.0))
    assert solution.status == "jammed"
    step = solution.compliant_step
    assert step is not None and step.valid and step.audit.passed
    squeeze = 1500.0 * 0.01 * closing_time
    np.testing.assert_allclose(step.normal_forces, [squeeze, squeeze], rtol=1e-9)
    # The softer left spring takes up more of the closing: the box moves toward it, by v h - N / k1.
    np.testing.assert_allclose(step.displacements["box"][0], 0.01 * closing_time - squeeze / 1000.0, rtol=1e-9)
    assert "leave the displacement free" in step.message  # nothing holds the box along y, nor its turn


def test_level_grasp_held_by_the_squeeze() -> None:
    """Held when 2 mu k v h >= m g: N = k v h; the moment balance gives each finger m g / 2; the box sags and turns.

    Tangential springs kt1, kt2: the contact points drop dy -+ 0.05 dtheta = -m g / (2 kt_i).
    """
    h, m, kt = 0.5, 0.5, (1000.0, 3000.0)
    solution = qs.solve(_grasp(h, kt=kt))
    step = solution.compliant_step
    assert solution.status == "jammed" and step is not None and step.valid, solution.message
    np.testing.assert_allclose(step.normal_forces, [2000.0 * 0.01 * h] * 2, rtol=1e-9)
    np.testing.assert_allclose(step.forces[:, 1], [m * G / 2] * 2, rtol=1e-9)
    drop = [-m * G / (2 * k) for k in kt]
    dy, turn = (drop[0] + drop[1]) / 2, (drop[1] - drop[0]) / 0.1
    np.testing.assert_allclose(step.displacements["box"], [0.0, dy, turn], rtol=1e-9, atol=1e-15)
    assert step.states == ("stuck", "stuck") and "hold the bodies" in solution.message


def test_level_grasp_slips_without_enough_closing() -> None:
    """2 mu k v h = 2 x 0.8 x 2000 x 0.01 x 0.1 = 3.2 N < m g = 4.905 N: the fingers reach their friction limit."""
    solution = qs.solve(_grasp(0.1))
    step = solution.compliant_step
    assert step is not None and not step.valid and set(step.states) == {"at friction limit"}
    assert "reach their friction limit" in solution.message and "no answer" in solution.message


def test_step_units_mm_g() -> None:
    metres = qs.solve(_grasp(0.5, kt=(1000.0, 3000.0))).compliant_step
    millimetres = qs.solve(_grasp(0.5, kt=(1000.0, 3000.0), length=1e3, mass=1e3)).compliant_step
    assert metres is not None and millimetres is not None and millimetres.valid
    np.testing.assert_allclose(np.array(millimetres.normal_forces) / 1e6, metres.normal_forces, rtol=1e-9)
    np.testing.assert_allclose(millimetres.displacements["box"] * [1e-3, 1e-3, 1.0], metres.displacements["box"], rtol=1e-8, atol=1e-15)


def test_rigid_fingers_stay_jammed() -> None:
    """Only the table has springs: nothing takes up the fingers' closing, and the step says so."""
    scene = _grasp(0.5)
    rigid = [qs.Contact(c.body, c.other, c.point, c.normal, c.mu) for c in scene.contacts]
    table = qs.Contact("box", "table", [0.0, 0.0], [0.0, 1.0], mu=0.5, stiffness=qs.Stiffness(1000.0))
    solution = qs.solve(qs.Scene(scene.bodies, [*rigid, table], [*scene.movers, qs.Mover("table")], dimension=2, closing_time=0.5))
    assert solution.status == "jammed" and solution.compliant_step is None
    assert "a rigid contact is closed" in solution.details["compliance"]


def test_exact_cone_squeeze_in_3d() -> None:
    """The level grasp in 3-D on exact cones (SCIP): N = k v h, each finger m g / 2 upward."""
    contacts = [
        qs.Contact("box", "left", [-0.05, 0.0, 0.05], [1, 0, 0], mu=0.8, stiffness=qs.Stiffness(2000.0, 1000.0)),
        qs.Contact("box", "right", [0.05, 0.0, 0.05], [-1, 0, 0], mu=0.8, stiffness=qs.Stiffness(2000.0, 1000.0)),
    ]
    movers = [qs.Mover("left", [0.01, 0, 0, 0, 0, 0]), qs.Mover("right", [-0.01, 0, 0, 0, 0, 0])]
    scene = qs.Scene([qs.Body("box", 0.5, [0.0, 0.0, 0.05])], contacts, movers, closing_time=0.5)
    solution = qs.solve(scene)
    step = solution.compliant_step
    assert solution.status == "jammed" and step is not None and step.valid, solution.message
    np.testing.assert_allclose(step.normal_forces, [10.0, 10.0], rtol=1e-6)
    np.testing.assert_allclose(step.forces[:, 2], [0.25 * G] * 2, rtol=1e-6)
    np.testing.assert_allclose(step.displacements["box"][2], -0.5 * G / 2000.0, rtol=1e-5)


def test_step_in_json_and_table(tmp_path: Path) -> None:
    path = tmp_path / "grasp.yaml"
    path.write_text(
        "quasistatic: 1\ndimension: 2\nclosing_time: 0.5\nstiffness: {normal: 2000.0, tangential: 1000.0}\n"
        "bodies: {box: {mass: 0.5, com: [0.0, 0.05]}}\n"
        "movers: {left: {twist: [0.01, 0.0, 0.0]}, right: {twist: [-0.01, 0.0, 0.0]}}\n"
        "contacts:\n"
        "  - {body: box, other: left, point: [-0.05, 0.05], normal: [1.0, 0.0], mu: 0.8}\n"
        "  - {body: box, other: right, point: [0.05, 0.05], normal: [-1.0, 0.0], mu: 0.8}\n"
    )
    out = json.loads(subprocess.run([QUASISTATIC, "solve", str(path), "--json"], capture_output=True, text=True, check=True).stdout)
    assert out["status"] == "jammed" and out["compliant_step"]["valid"] is True
    np.testing.assert_allclose([c["normal_force"] for c in out["compliant_step"]["contacts"]], [10.0, 10.0], rtol=1e-9)
    assert out["compliant_step"]["audit"]["passed"] is True
    table = subprocess.run([QUASISTATIC, "solve", str(path)], capture_output=True, text=True, check=True).stdout
    assert "compliant step (0.5): valid" in table and "box displacement" in table
    path.write_text(path.read_text().replace("closing_time: 0.5", "closing_time: -1"))
    bad = subprocess.run([QUASISTATIC, "solve", str(path)], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.startswith("error:") and "closing_time" in bad.stderr and len(bad.stderr.splitlines()) == 1


def test_level_grasp_without_closing_cannot_hold() -> None:
    """Still fingers: the rigid model lists four motions (held with any squeeze, or sliding down); with springs
    and no closing the squeeze is zero, so friction cannot carry the weight: the box slips."""
    grasp = _grasp(0.5)
    still = qs.Scene(grasp.bodies, grasp.contacts, [qs.Mover("left"), qs.Mover("right")], dimension=2, closing_time=0.5)
    solution = qs.solve(still)
    assert solution.status == "ambiguous"
    step = solution.compliant_step
    assert step is not None and not step.valid and set(step.states) == {"at friction limit"}


def test_detected_contacts_take_the_pair_stiffness(tmp_path: Path) -> None:
    """A box on a table found from shapes, its com off-centre: the four corners share the load as a plane of springs."""
    pytest.importorskip("coal")
    text = """
quasistatic: 1
stiffness: {normal: 1.0}
bodies:
  box:
    mass: 2.0
    com: [0.02, -0.01, 0.0]
    shape: {box: [0.1, 0.1, 0.1]}
    pose: {position: [0.0, 0.0, 0.05]}
movers:
  table:
    shape: {halfspace: {normal: [0.0, 0.0, 1.0], offset: 0.0}}
contact_detection:
  friction: {default: 0.5}
  stiffness:
    default: {normal: 2.0}
    pairs:
      - {between: [box, table], normal: 40000.0, tangential: 20000.0}
"""
    path = tmp_path / "box.yaml"
    path.write_text(text)
    world = qs.load_world(path)
    scene = world.scene()
    assert {c.stiffness for c in scene.contacts} == {qs.Stiffness(4.0e4, 2.0e4)} and len(scene.contacts) == 4
    solution = qs.solve(world)
    assert solution.status == "solved" and solution.compliant_forces
    corners = np.array([c.point[:2] for c in scene.contacts])
    expected = _plane_of_springs(corners, np.full(4, 4.0e4), 2.0 * G, np.array([0.02, -0.01]))
    np.testing.assert_allclose([c.normal_force for c in solution.contacts], expected, rtol=1e-6)
    bad = text.replace("between: [box, table]", "between: [box, tabel]")
    path.write_text(bad)
    with pytest.raises(qs.SceneError) as error:
        qs.load_world(path)
    assert error.value.field == "contact_detection.stiffness.pairs[0].between"


def test_compliant_grasp_example_gives_the_answer_its_comment_derives() -> None:
    example = Path(__file__).resolve().parents[1] / "examples" / "compliant_grasp.yaml"
    solution = qs.solve(qs.load_scene(example))
    step = solution.compliant_step
    assert solution.status == "jammed" and step is not None and step.valid
    np.testing.assert_allclose(step.forces, [[10.0, 2.4525], [-10.0, 2.4525]], rtol=1e-9)
    np.testing.assert_allclose(step.displacements["box"], [0.0, -0.0024525, 0.0], atol=1e-12)


def test_closing_time_without_springs_says_so() -> None:
    grasp = _grasp(0.5)
    rigid = [qs.Contact(c.body, c.other, c.point, c.normal, c.mu) for c in grasp.contacts]
    solution = qs.solve(qs.Scene(grasp.bodies, rigid, grasp.movers, dimension=2, closing_time=0.5))
    assert solution.status == "jammed" and solution.compliant_step is None
    assert "nothing has a stiffness" in solution.details["compliance"]


HAND = Path(__file__).resolve().parents[1] / "examples" / "robots" / "planar_hand.yaml"
HAND_STIFFNESS = {"left_base": 2.0, "left_middle": 5.0, "right_base": 3.0, "right_middle": 7.0}  # N m/rad, all different


def _closing_hand(tmp_path: Path, joint_stiffness: object) -> Path:
    """examples/robots/planar_hand.yaml with its base joints closing the fingertips on the box for 0.1 s, contact
    springs of 2000 N/m, the given joint stiffness, and no gravity (the squeeze alone: no tangential load)."""
    import yaml

    data = yaml.safe_load(HAND.read_text(encoding="utf-8"))
    data["robots"]["hand"]["urdf"] = str(HAND.parent / data["robots"]["hand"]["urdf"])
    data["robots"]["hand"]["joint_velocities"] = {"left_base": -0.05, "right_base": 0.05}
    data["robots"]["hand"]["joint_stiffness"] = joint_stiffness
    data["contact_detection"]["stiffness"] = {"default": {"normal": 2000.0}}
    data["gravity"] = [0.0, 0.0, 0.0]
    data["closing_time"] = 0.1
    path = tmp_path / "closing_hand.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_a_urdf_robots_joint_stiffness_yields_in_series(tmp_path: Path) -> None:
    """A URDF robot's joint stiffness by joint name (robots.hand.joint_stiffness), mapped to the contacts through
    Pinocchio's Jacobians. The two fingertips squeeze the box along x, collinear, so their springs act in series
    across it: N = h (b_1 + b_2) / (c_1 + c_2), with each contact's closing speed b_i = n_i . J_i qdot and its
    normal compliance c_i = 1/k_n + sum_j (n_i . J_i[:, j])^2 / k_j (the box's turn and lift take up the
    fingertips' other deflections). Each joint has its own stiffness, so a joint mapped to another's value, or
    joint stiffness ignored (N = 10.5 N), fails."""
    pytest.importorskip("pinocchio")
    path = _closing_hand(tmp_path, HAND_STIFFNESS)
    scene = qs.load_scene(path)
    robot = scene.robot("hand")
    assert robot.joint_names == ("left_base", "left_middle", "right_base", "right_middle")
    np.testing.assert_array_equal(robot.joint_stiffness, [2.0, 5.0, 3.0, 7.0])
    compliance = [1 / 2000.0 + ((c.normal @ c.jacobian) ** 2) @ (1 / robot.joint_stiffness) for c in scene.contacts]
    advance = [0.1 * c.normal @ c.jacobian @ robot.joint_velocities for c in scene.contacts]
    squeeze = sum(advance) / sum(compliance)
    assert squeeze == pytest.approx(0.0853684, rel=1e-5)  # the Jacobians' columns: 0.105, 0.0785 m per rad
    out = json.loads(subprocess.run([QUASISTATIC, "solve", str(path), "--json"], capture_output=True, text=True, check=True).stdout)
    assert out["status"] == "jammed"  # rigid fingers cannot close on a rigid box
    step = out["compliant_step"]
    assert step["valid"] and [c["state"] for c in step["contacts"]] == ["stuck", "stuck"]
    np.testing.assert_allclose([c["normal_force"] for c in step["contacts"]], [squeeze, squeeze], rtol=1e-8)


@pytest.mark.parametrize(
    ("stiffness", "message"),
    [
        ({"left_base": 2.0}, "name every joint (missing: left_middle, right_base, right_middle)"),
        ({**HAND_STIFFNESS, "left_base": -1.0}, "every joint stiffness must be > 0"),
        ({**HAND_STIFFNESS, "elbow": 1.0}, "robots.hand.joint_stiffness.elbow"),
    ],
)
def test_bad_urdf_joint_stiffness_is_one_error_line(tmp_path: Path, stiffness: object, message: str) -> None:
    pytest.importorskip("pinocchio")
    result = subprocess.run([QUASISTATIC, "solve", str(_closing_hand(tmp_path, stiffness))], capture_output=True, text=True)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], result.stderr


def test_the_viewers_live_resolve_keeps_springs_closing_time_and_joint_stiffness() -> None:
    """The viewer re-solves the scene with its sliders' velocities; everything else must be the scene's own
    (it once rebuilt the Scene from a few fields and dropped the springs, the closing time and joint stiffness)."""
    pytest.importorskip("viser")
    from quasistatic.viz import Velocities

    scene = qs.load_scene(Path(__file__).resolve().parents[1] / "examples" / "compliant_grasp.yaml")
    arm = qs.Robot("arm", [0.01, -0.02], joint_stiffness=[5.0, 7.0], torque_limits=[1.0, 2.0])
    scene = dataclasses.replace(scene, robots=(arm,))
    faster = Velocities({"arm": np.array([0.03, 0.04])}, {m.name: np.ones(3) * 0.001 for m in scene.movers if m.robot is None})
    live = faster.applied(scene)
    assert isinstance(live, qs.Scene)
    assert live.stiffness == scene.stiffness and live.closing_time == scene.closing_time
    assert [c.stiffness for c in live.contacts] == [c.stiffness for c in scene.contacts]
    (robot,) = live.robots
    assert robot.joint_velocities.tolist() == [0.03, 0.04]
    assert robot.joint_stiffness is not None and robot.joint_stiffness.tolist() == [5.0, 7.0]
    assert robot.torque_limits is not None and robot.torque_limits.tolist() == [1.0, 2.0]
    assert all(np.allclose(m.twist, 0.001) for m in live.movers if m.robot is None)
