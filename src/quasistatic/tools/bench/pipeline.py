"""Robots and geometry in the benchmark: from joint positions to contacts, Jacobians and a certified answer.

The measurements, each a list of :class:`PipelineRow`:

- ``allegro detect+jacobians``: the Allegro hand (16 joints, 21 collision
  geometries) grasping a cube on a table with three fingertips, timed from its
  joint positions to the detected contacts with their point Jacobians as a
  simulation step gets them (``World.moved``, then ``detect``), against the bare
  Pinocchio and coal calls over the same pairs in the same run (their ratio is
  the Python overhead); ``, new World`` is the same with a World built anew
  around ``UrdfRobot.at(q)`` (the detection layout rebuilt each time);
- ``allegro scene build``: the Scene from those contacts (checked whole);
- ``allegro pipeline``: the same scene, from joint positions to the default
  ``qs.solve``'s answer, with its status and certified flag;
- ``detect growth``: ``World.detect`` on rows of spheres and boxes resting on a
  table and touching their neighbours, against the number of near pairs (those
  the broad phase leaves to coal), with the fitted exponent.

Every row needs the ``robots`` extra (coal, Pinocchio) and the Allegro rows the
``example-robot-data`` package; without them the rows say so and are skipped.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from importlib.util import find_spec
from typing import Any

import numpy as np

from ...adapters import Box, ContactDetection, FrictionPair, Halfspace, Pose, ShapedMover, SolidBody, Sphere, UrdfRobot, World
from ...adapters.detect import Collider, candidate_pairs
from ...adapters.robot import installed_model_folders, resolve_package_path
from ...errors import SceneError
from ...solve import solve

__all__ = ["PipelineRow", "run_pipeline", "allegro_grasp", "resting_rows", "ALLEGRO_URDF"]

ALLEGRO_URDF = "package://example-robot-data/robots/allegro_hand_description/urdf/allegro_right_hand.urdf"
TIP_RADIUS = 0.012  # the Allegro fingertips' collision spheres [m]
GRASP_TIPS = ("link_3.0_tip", "link_7.0_tip", "link_15.0_tip")  # index, middle, thumb
GROWTH_QUICK = (10, 40, 160)
GROWTH_FULL = (10, 20, 40, 80, 160)
_ROW = 10  # objects per row on the table in the growth scenes


@dataclass(frozen=True)
class PipelineRow:
    """One robots-and-geometry measurement; times in seconds.

    ``pairs``: candidate pairs after the broad phase; ``near``: those left to coal (pairs
    that may touch); ``ratio``: the row's baseline median / this median (> 1: faster);
    ``cpu_median``: the median of the same calls' process (CPU) time, which other work on a
    shared machine inflates far less than the wall time of ``median``.
    """

    case: str
    objects: int = 0
    pairs: int = 0
    near: int = 0
    contacts: int = 0
    samples: int = 0
    median: float | None = None
    p25: float | None = None
    p75: float | None = None
    baseline: str = ""
    ratio: float | None = None
    status: str = ""
    certified: bool | None = None
    skipped: str | None = None
    note: str = ""
    cpu_median: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def run_pipeline(full: bool, budget: float, say: Callable[[str], None]) -> list[PipelineRow]:
    """Every robots-and-geometry row; ``budget`` is the seconds of timed calls aimed at per row."""
    if find_spec("coal") is None or find_spec("pinocchio") is None:
        row = PipelineRow("robots and geometry", skipped="coal/pinocchio not installed (pip install 'quasistatic[robots]')")
        say(f"{row.case}: skipped ({row.skipped})")
        return [row]
    rows = _allegro_rows(budget)
    rows += [_growth_row(n, budget) for n in (GROWTH_FULL if full else GROWTH_QUICK)]
    for row in rows:
        say(_line(row))
    return rows


def growth_exponent(rows: list[PipelineRow]) -> float | None:
    """Least-squares slope of log(median detect time) against log(near pairs) over the growth rows.

    The CPU-time medians when every growth row has one (other work on the machine inflates wall time
    unevenly across rows, and so the slope), else the wall-time medians.
    """
    growth = [r for r in rows if r.case == "detect growth" and r.median is not None and r.near > 0]
    cpu = all(r.cpu_median is not None for r in growth)
    points = [(r.near, float((r.cpu_median if cpu else r.median) or 0.0)) for r in growth]
    if len({n for n, _ in points}) < 3:
        return None
    return float(np.polyfit(np.log([n for n, _ in points]), np.log([t for _, t in points]), 1)[0])


# --------------------------------------------------------------------------- the Allegro grasp


def allegro_grasp() -> tuple[World, np.ndarray]:
    """The Allegro hand holding a cube on a table between its thumb and two fingers, and its joint positions.

    The joint positions are fixed (fingers half closed, thumb opposed, ring finger
    nearly straight); the cube is then placed from forward kinematics: one face
    against the index and middle tips, the opposite face against the thumb tip
    (its side is their distance less two tip radii), the tips at 60 % of its height.
    The hand's base pose puts the cube on the table ``z <= 0``, upright. The hand holds
    still: its joint velocities are zero (lifting or pushing the cube makes the answer
    ambiguous, and the certified search then takes 20 to 60 s instead of about 1 s).
    """
    angles = {0: 0.05, 1: 0.6, 2: 0.6, 3: 0.5, 4: 0.0, 5: 0.6, 6: 0.6, 7: 0.5}
    angles |= {8: -0.05, 9: 0.1, 10: 0.1, 11: 0.1, 12: 1.3, 13: 0.4, 14: 0.5, 15: 0.6}
    hand = UrdfRobot("hand", ALLEGRO_URDF)
    hand = hand.at(q={f"joint_{k}.0": v for k, v in angles.items()})
    tips = {c.link: c.pose.position for c in hand.colliders if c.link in GRASP_TIPS}
    index, middle, thumb = (tips[name] for name in GRASP_TIPS)
    across = (index - middle) / np.linalg.norm(index - middle)
    squeeze = thumb - (index + middle) / 2.0
    squeeze -= (squeeze @ across) * across
    squeeze /= np.linalg.norm(squeeze)
    down = np.cross(squeeze, across)  # away from the palm: where the table is
    side = float((thumb - index) @ squeeze) - 2.0 * TIP_RADIUS
    centre = (index @ squeeze + TIP_RADIUS + side / 2.0) * squeeze + ((index + middle) / 2.0 @ across) * across
    centre += (index @ down + 0.1 * side) * down  # the tips 0.6 side above the cube's bottom face
    cube_in_hand = Pose(centre, np.column_stack([across, squeeze, -down]))
    base = Pose((0.0, 0.0, side / 2.0)).compose(cube_in_hand.inverse())
    hand = hand.at(base=base)
    world = World(
        bodies=(SolidBody("cube", 0.1, Box([side] * 3), Pose((0.0, 0.0, side / 2.0))),),
        movers=(ShapedMover("table", Halfspace((0.0, 0.0, 1.0), 0.0)),),
        robots=(hand,),
        detection=ContactDetection(mu=0.8, pairs=(FrictionPair(("cube", "table"), 0.5),)),
    )
    return world, hand.q


def _allegro_rows(budget: float) -> list[PipelineRow]:
    names = (
        "allegro detect+jacobians",
        "allegro detect+jacobians, new World",
        "bare pinocchio+coal",
        "allegro scene build",
        "allegro pipeline (certified)",
    )
    if not _allegro_installed():
        reason = "the Allegro URDF is not installed (pip install example-robot-data)"
        return [PipelineRow(name, skipped=reason) for name in names]
    world, q = allegro_grasp()
    hand = world.robots[0]

    def step() -> World:
        """What a simulation step does: the same world at new joint positions (parsed robot and layout kept)."""
        return world.moved(robot_q={"hand": q})

    colliders, pairs, near = _pairs(world)
    detection = step().detect()
    head = PipelineRow("", len(colliders), len(pairs), len(near), len(detection.contacts), baseline=names[2])
    base = _timed(
        replace(head, case=names[2], note="computeJointJacobians, updateGeometryPlacements, coal.collide"),
        _times(_bare_calls(hand, colliders, near, detection.margin), budget),
    )
    base = replace(base, ratio=1.0)
    note = "World.moved(robot_q) then detect(): forward kinematics, contacts, point Jacobians"
    kept = _timed(replace(head, case=names[0], note=note), _times(lambda: step().detect(), budget))
    note = "a World built anew around UrdfRobot.at(q), then detect(): the detection layout rebuilt"
    anew = _timed(replace(head, case=names[1], note=note), _times(lambda: replace(world, robots=(hand.at(q=q),)).detect(), budget))
    moved = step()
    note = "World.scene(detection): the Scene checked whole (names, normals, Jacobian shapes)"
    scene = _timed(replace(head, case=names[3], baseline="", note=note), _times(lambda: moved.scene(detection), budget))
    solution = solve(moved.scene(detection))
    note = f"method {solution.method}; World.moved(robot_q) to the audited answer"
    whole = _timed(replace(head, case=names[4], baseline="", note=note), _times(lambda: solve(step().scene()), budget, at_least=3))
    return [
        replace(kept, ratio=_ratio(base, kept)),
        replace(anew, ratio=_ratio(base, anew)),
        base,
        scene,
        replace(whole, status=str(solution.status), certified=solution.certified),
    ]


def _allegro_installed() -> bool:
    try:
        resolve_package_path(ALLEGRO_URDF, installed_model_folders(), "urdf")
    except SceneError:
        return False
    return True


def _bare_calls(hand: UrdfRobot, colliders: list[Any], near: list[tuple[int, int]], margin: float) -> Callable[[], None]:
    """The library calls the detection stands on, with nothing around them: what Python costs on top."""
    import coal
    import pinocchio

    model = pinocchio.buildModelFromUrdf(str(hand.urdf))
    folders = [str(folder) for folder in installed_model_folders()]
    geometry = pinocchio.buildGeomFromUrdf(model, str(hand.urdf), pinocchio.GeometryType.COLLISION, package_dirs=folders)
    data, geometry_data = model.createData(), pinocchio.GeometryData(geometry)
    configuration = np.array(hand.q)  # every Allegro joint is revolute: Pinocchio's q is the joint positions
    shapes = {i: _coal_shape(coal, c.shape) for pair in near for i in pair for c in (colliders[i],)}
    placed = {i: coal.Transform3s(np.array(colliders[i].pose.rotation), np.array(colliders[i].pose.position)) for i in shapes}
    request, result = coal.CollisionRequest(), coal.CollisionResult()
    request.security_margin = margin

    def call() -> None:
        pinocchio.computeJointJacobians(model, data, configuration)
        pinocchio.updateGeometryPlacements(model, data, geometry, geometry_data)
        for i, j in near:
            result.clear()
            coal.collide(shapes[i], placed[i], shapes[j], placed[j], request, result)

    return call


def _coal_shape(coal: Any, shape: Any) -> Any:
    if isinstance(shape, Box):
        return coal.Box(*shape.size)
    if isinstance(shape, Sphere):
        return coal.Sphere(shape.radius)
    assert isinstance(shape, Halfspace)  # the only shapes of these scenes
    return coal.Halfspace(np.array(shape.normal), shape.offset)


# --------------------------------------------------------------------------- growth with the pairs


def resting_rows(count: int) -> World:
    """``count`` objects on the table ``z <= 0``: rows of :data:`_ROW`, spheres and boxes in turn, each touching the next.

    Spheres of radius 2 cm and 4 cm cubes: a sphere touches the table at one point and its
    neighbours' faces at one point each, a cube touches the table on its four corners.
    Rows are 1 cm apart, so only neighbours in a row are near.
    """
    radius = 0.02
    bodies = []
    for k in range(count):
        row, place = divmod(k, _ROW)
        position = (place * 2.0 * radius, row * (2.0 * radius + 0.01), radius)
        shape = Sphere(radius) if (row + place) % 2 == 0 else Box([2.0 * radius] * 3)
        bodies.append(SolidBody(f"part{k}", 0.05, shape, Pose(position)))
    table = ShapedMover("table", Halfspace((0.0, 0.0, 1.0), 0.0))
    return World(bodies=tuple(bodies), movers=(table,), detection=ContactDetection(mu=0.5))


def _growth_row(count: int, budget: float) -> PipelineRow:
    world = resting_rows(count)
    _, pairs, near = _pairs(world)
    note = "World.detect(), its layout kept from the first call"
    row = PipelineRow("detect growth", count, len(pairs), len(near), len(world.detect().contacts), note=note)
    return _timed(row, _times(world.detect, budget))


def _pairs(world: World) -> tuple[list[Collider], list[tuple[int, int]], list[tuple[int, int]]]:
    """The world's placed shapes, the broad phase's candidate pairs, and those that may touch (one is a free body)."""
    parts: list[SolidBody | ShapedMover] = [*world.bodies, *world.movers]
    colliders = [Collider(p.name, p.shape, p.pose) for p in parts if p.shape is not None]
    colliders += [Collider(c.owner, c.shape, c.pose) for robot in world.robots for c in robot.colliders]
    pairs = candidate_pairs(colliders, world.detect().margin)
    free = {b.name for b in world.bodies}
    near = [(i, j) for i, j in pairs if colliders[i].owner in free or colliders[j].owner in free]
    return colliders, pairs, near


# --------------------------------------------------------------------------- timing


def _times(call: Callable[[], Any], budget: float, at_least: int = 5) -> list[tuple[float, float]]:
    """One discarded warm-up call, then (wall, CPU) times of calls until ``budget`` seconds are spent (at least ``at_least``)."""
    call()
    times: list[tuple[float, float]] = []
    started = time.perf_counter()
    while len(times) < at_least or (time.perf_counter() - started < budget and len(times) < 2000):
        t0, c0 = time.perf_counter(), time.process_time()
        call()
        times.append((time.perf_counter() - t0, time.process_time() - c0))
    return times


def _timed(row: PipelineRow, times: list[tuple[float, float]]) -> PipelineRow:
    """``row`` with the median and quartiles of the wall times, and the median of the CPU times."""
    q25, median, q75 = np.percentile([wall for wall, _ in times], [25, 50, 75])
    cpu = float(np.median([used for _, used in times]))
    return replace(row, samples=len(times), median=float(median), p25=float(q25), p75=float(q75), cpu_median=cpu)


def _ratio(base: PipelineRow, row: PipelineRow) -> float | None:
    return None if base.median is None or not row.median else base.median / row.median


def _line(row: PipelineRow) -> str:
    if row.skipped:
        return f"{row.case}: skipped ({row.skipped})"
    extra = f", {row.status}, certified {row.certified}" if row.status else ""
    median = f"median {(row.median or 0.0) * 1e3:.3g} ms (CPU {(row.cpu_median or 0.0) * 1e3:.3g} ms) over {row.samples} calls"
    return f"{row.case}, {row.objects} objects, {row.near} near pairs: {median}{extra}"
