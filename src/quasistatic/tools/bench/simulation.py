"""Motion over time in the benchmark: steps per second, and where a step's time goes.

Four runs of :func:`quasistatic.sim.step` (each step: contacts found again, a certified solve, the move):

- ``simulate push (planar)``: issue 13's planar two-finger push, ``examples/sim/push_planar.yaml`` built in
  Python: a box on a table pushed by two fingertips (disks) one above the other (4 contacts, detection in
  NumPy, solved and certified at every step; runs without the robots extra). The box only translates, so
  most steps' laws repeat bit for bit and take the previous certified answer again;
- ``simulate tip (planar, turning)``: ``examples/sim/tip_box_planar.yaml`` built in Python: a tall box tipped
  about its front corner by a fingertip pushing high. It turns, so every step's laws are new and proven anew:
  the cost of a step that cannot reuse;
- ``simulate push``: a box on a table pushed by two fingertips side by side (6 contacts; the answer is
  ambiguous, so the least-power motion is followed, as ``--ambiguous min-power`` does);
- ``simulate allegro``: the Allegro hand holding a cube on a table (the pipeline rows' grasp), the hand
  still, so every step re-detects and re-certifies the rest.

Each row gives the median step, steps per second in its note, and the split of one step into
detection, assembly and solve, measured on the same states.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from importlib.util import find_spec

import numpy as np

from ...adapters import (
    AnyWorld,
    Box,
    ContactDetection,
    Disk,
    FrictionPair,
    HalfPlane,
    Halfspace,
    PlanarBody,
    PlanarMover,
    PlanarWorld,
    Pose,
    Rectangle,
    ShapedMover,
    SolidBody,
    Sphere,
    World,
    planar_pose,
)
from ...errors import SceneError
from ...laws import assemble
from ...sim import Evaluation, Inputs, SimModel, State, StepOptions, advance, evaluate
from ...solve import Reuse, solve
from .pipeline import PipelineRow, allegro_grasp

__all__ = ["run_simulation_rows", "two_finger_push", "planar_two_finger_push", "planar_tipping_box"]

PUSH_STEP = 0.05  # [s]: the fingertips move 0.5 mm per step


def two_finger_push() -> World:
    """A 0.1 m, 1 kg cube on a table (friction 0.5), pushed in +x at 1 cm/s by two frictionless fingertips 6 cm apart."""
    fingers = tuple(
        ShapedMover(f"finger{i}", Sphere(0.005), Pose([-0.055, y, 0.05]), twist=[0.01, 0, 0, 0, 0, 0]) for i, y in enumerate((-0.03, 0.03))
    )
    table = ShapedMover("table", Halfspace([0, 0, 1], 0.0))
    pairs = tuple(FrictionPair(("box", f.name), 0.0) for f in fingers)
    return World(
        bodies=(SolidBody("box", 1.0, Box([0.1, 0.1, 0.1]), Pose([0, 0, 0.05])),),
        movers=(table, *fingers),
        detection=ContactDetection(mu=0.5, pairs=pairs),
        friction="pyramid:4",
    )


def planar_two_finger_push() -> PlanarWorld:
    """``examples/sim/push_planar.yaml``: a 0.1 m, 1 kg box on a table (friction 0.5), pushed in +x at 1 cm/s by two
    frictionless fingertips (disks, radius 5 mm) at heights 3 and 7 cm."""
    fingers = tuple(
        PlanarMover(name, Disk(0.005), planar_pose([-0.055, y]), twist=[0.01, 0.0, 0.0])
        for name, y in (("finger_low", 0.03), ("finger_high", 0.07))
    )
    pairs = tuple(FrictionPair(("box", f.name), 0.0) for f in fingers)
    return PlanarWorld(
        bodies=(PlanarBody("box", 1.0, Rectangle([0.1, 0.1]), planar_pose([0.0, 0.05])),),
        movers=(PlanarMover("table", HalfPlane([0.0, 1.0], 0.0)), *fingers),
        detection=ContactDetection(mu=0.5, pairs=pairs),
    )


def planar_tipping_box() -> PlanarWorld:
    """``examples/sim/tip_box_planar.yaml``: a 0.1 x 0.2 m, 1 kg box on a table (friction 0.8) tipped over by a
    frictionless fingertip (a disk, radius 5 mm) pushing its back face at height 0.15 m in +x at 1 cm/s."""
    finger = PlanarMover("finger", Disk(0.005), planar_pose([-0.055, 0.15]), twist=[0.01, 0.0, 0.0])
    return PlanarWorld(
        bodies=(PlanarBody("box", 1.0, Rectangle([0.1, 0.2]), planar_pose([0.0, 0.1])),),
        movers=(PlanarMover("table", HalfPlane([0.0, 1.0], 0.0)), finger),
        detection=ContactDetection(mu=0.8, pairs=(FrictionPair(("box", "finger"), 0.0),)),
    )


def run_simulation_rows(full: bool, say: Callable[[str], None]) -> list[PipelineRow]:
    """The simulation rows: the planar push always; the 3-D ones need the robots extra (the Allegro row also example-robot-data)."""
    steps = 20 if full else 6
    planar_steps = 200 if full else 60
    rows = [
        _row("simulate push (planar)", planar_two_finger_push(), planar_steps, "stop"),
        _row("simulate tip (planar, turning)", planar_tipping_box(), planar_steps, "stop"),
    ]
    if find_spec("coal") is None or find_spec("pinocchio") is None:
        rows.append(PipelineRow("simulate", skipped="coal/pinocchio not installed (pip install 'quasistatic[robots]')"))
        for row in rows:
            say(f"{row.case}: {row.note or row.skipped}")
        return rows
    rows.append(_row("simulate push (2 fingertips, box, table)", two_finger_push(), steps, "min_power"))
    try:
        world, _ = allegro_grasp()
    except SceneError:  # the URDF is not installed
        rows.append(PipelineRow("simulate allegro", skipped="example-robot-data not installed (pip install 'quasistatic[models]')"))
    else:
        rows.append(_row("simulate allegro (cube, table, 3 tips)", world, steps, "stop"))
    for row in rows:
        say(f"{row.case}: {row.note or row.skipped}")
    return rows


def _row(case: str, world: AnyWorld, steps: int, policy: str) -> PipelineRow:
    model = SimModel(world, StepOptions(PUSH_STEP, ambiguous=policy))  # type: ignore[arg-type]
    state, times, cpu, parts = State.of(world), [], [], []
    evaluation = evaluate(model, state, Inputs())  # warm: imports, caches, first compilations
    reused = model.reuse.hits if model.reuse is not None else 0
    for _ in range(steps):
        memory = copy.copy(model.reuse)  # as the step found it: the split's solve reuses exactly when the step did
        start, start_cpu = time.perf_counter(), time.process_time()
        evaluation = evaluate(model, state, Inputs())
        if evaluation.motion is None:
            break
        state = advance(evaluation, PUSH_STEP)
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        parts.append(_split(evaluation, memory))
    reused = model.reuse.hits - reused if model.reuse is not None else 0
    if not times:
        return PipelineRow(case, skipped=f"no step taken: {evaluation.solution.status}")
    median = float(np.median(times))
    detect, build, solving = (float(np.median(column)) for column in zip(*parts, strict=True))
    cpu_median = float(np.median(cpu))
    rest = max(median - detect - build - solving, 0.0)  # the step's own work: placing the world, penetration, the move
    note = (
        f"{1.0 / median:.3g} steps/s ({1.0 / cpu_median:.3g} by CPU time); per step: detect {detect * 1e3:.2f} ms, "
        f"assemble {build * 1e3:.2f} ms, solve {solving * 1e3:.2f} ms, the rest {rest * 1e3:.2f} ms; status {evaluation.solution.status}; "
        f"{reused} of {len(times)} steps took the previous certified answer again (the same laws, bit for bit)"
    )
    return PipelineRow(
        case, objects=len(world.bodies), contacts=len(evaluation.detection.contacts), samples=len(times), median=median,
        p25=float(np.percentile(times, 25)), p75=float(np.percentile(times, 75)), status=evaluation.solution.status,
        certified=evaluation.solution.certified, note=note, cpu_median=cpu_median,
    )  # fmt: skip


def _split(evaluation: Evaluation, memory: Reuse | None) -> tuple[float, float, float]:
    """One step's detection, assembly (the Scene and its Problem) and solve, timed apart on the step's own state.

    Detection is timed on the step's World (the look-ahead band); the Scene is the step's own (the contacts it
    touched), as is the solve, given the assembled Problem (so its time does not count the assembly a second time)
    and the run's memory of its last certified answer as the step found it (``memory``, a copy), so it reuses
    exactly when the step did.
    """
    world = evaluation.world
    start = time.perf_counter()
    world.detect()
    detected = time.perf_counter()
    problem = assemble(world.scene(evaluation.detection))
    assembled = time.perf_counter()
    solve(problem, reuse=memory)
    return detected - start, assembled - detected, time.perf_counter() - assembled
