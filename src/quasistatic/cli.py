"""Command line: ``quasistatic demo | solve | simulate | animate | plot | view | sweep | plan | check | contacts | validate | bench``.

A thin layer, no physics.

Exit codes: 0 when the library gave an answer (``solved``, ``ambiguous``,
``jammed`` or ``unstable``: a diagnosis is an answer), 1 when the solve
``failed`` or a solver crashed (:class:`SolverError`), 2 for bad input (an
unreadable or invalid scene, an unknown method or option, malformed
``--modes``). Every error is one ``error:`` line on stderr, never a traceback.
"""

from __future__ import annotations

import json
import shlex
import sys
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn, TypeVar

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.status import Status

from .errors import QuasistaticError, SolverError
from .loading import load_scene, load_world
from .model import Scene
from .model.io import read_scene_data, scene_to_dict
from .report import make_console, render_contacts, render_solution, render_trajectory
from .solution import Mode, Solution

if TYPE_CHECKING:
    from .adapters import AnyWorld, Detection
    from .sim import Trajectory
    from .solvers import SearchProgress
    from .sweeps import SweepResult

__all__ = ["app", "main"]

DEMO_SCENE = "two_finger_lift.yaml"
_MODE_WORDS: dict[str, Mode | None] = {
    "rolling": "rolling",
    "sliding": "sliding",
    "separating": "separating",
    "free": None,
}
_T = TypeVar("_T")
# `quasistatic.METHODS`, spelled out so that `--help` and a bad scene file answer without importing the
# solvers (SciPy, HiGHS, SCIP, numba); tests/test_cli.py checks that the two agree.
METHODS = ("auto", "lp", "scip", "certified", "paper", "fast")

app = typer.Typer(
    name="quasistatic",
    help="Quasi-static manipulation: predict how pushed or grasped objects move, their contact forces and modes.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

JsonOption = Annotated[bool, typer.Option("--json", help="Print the solution as JSON (Solution.to_dict()) and nothing else.")]
SceneArgument = Annotated[Path, typer.Argument(metavar="SCENE", help="Scene file (.yaml, .yml or .json).")]


@app.command()
def demo(as_json: JsonOption = False) -> None:
    """Solve the built-in example (two fingertips lifting a box) and print the result."""
    with resources.as_file(resources.files("quasistatic") / "examples" / DEMO_SCENE) as path:
        scene = _guarded(lambda: load_scene(path))
    _report(_solved(scene, None, all_solutions=True), as_json)


@app.command("solve")
def solve_command(
    scene_file: SceneArgument,
    as_json: JsonOption = False,
    method: Annotated[str, typer.Option(help=f"Solver: {', '.join(METHODS)}.")] = "auto",
    modes: Annotated[
        str | None,
        typer.Option(help="Prescribed contact modes, one per contact in order: rolling, sliding, separating or free."),
    ] = None,
    max_solutions: Annotated[int, typer.Option(help="Most distinct motions listed when ambiguous (at least 1).")] = 16,
    all_solutions: Annotated[
        bool,
        typer.Option(
            "--all-solutions/--first-solution",
            help="Certify: list every motion (default), or stop at the first audited one the fast path finds.",
        ),
    ] = True,
    time_limit: Annotated[float, typer.Option(help="Seconds the certified search may take; it says so when it stops early.")] = 60.0,
) -> None:
    """Solve a scene file: twists, contact forces and modes, power balance and audit."""
    if max_solutions < 1:
        _fail(f"--max-solutions must be at least 1 (got {max_solutions})")
    if not 0.0 < time_limit < float("inf"):
        _fail(f"--time-limit must be a positive number of seconds (got {time_limit})")
    scene, detection = _loaded(scene_file)
    prescribed = _guarded(lambda: _parse_modes(modes)) if modes is not None else None
    certify = all_solutions and method in ("auto", "scip", "certified")
    with _StatusLine(enabled=not as_json) as status:
        solution = _solved(
            scene,
            detection,
            method=method,
            modes=prescribed,
            all_solutions=certify,
            max_solutions=max_solutions,
            time_limit=time_limit,
            progress=status.update,
        )
    _report(solution, as_json)


def _solved(scene: Scene, detection: Detection | None, **options: Any) -> Solution:
    """The audited ``solve`` of ``scene``, with what detection found; the solvers are imported only here, when needed."""
    from .solve import solve, with_detection
    from .wedging import with_wedging_friction

    solution = _guarded(lambda: solve(scene, **options))
    solution = _guarded(lambda: with_wedging_friction(solution, scene, options.get("time_limit", 60.0)))
    return solution if detection is None else with_detection(solution, detection)


def _loaded(scene_file: Path) -> tuple[Scene, Detection | None]:
    """The scene of a file; for shapes and URDF robots, with the contacts found and what detection saw."""
    scene, detection, _ = _loaded_world(scene_file)
    return scene, detection


def _loaded_world(scene_file: Path) -> tuple[Scene, Detection | None, AnyWorld | None]:
    """As :func:`_loaded`, and the world of shapes the scene came from (None for a file that lists its contacts)."""
    loaded = _guarded(lambda: load_world(scene_file))
    if isinstance(loaded, Scene):
        return loaded, None, None
    world = loaded
    detection = _guarded(world.detect)
    scene = _guarded(lambda: world.scene(detection))
    return scene, detection, world


class _StatusLine:
    """A rich status line on stderr for a certified search that runs longer than a second (terminals only)."""

    def __init__(self, enabled: bool) -> None:
        console = Console(stderr=True)
        self.enabled = enabled and console.is_terminal
        self.console = console
        self.status: Status | None = None

    def __enter__(self) -> _StatusLine:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.status is not None:
            self.status.stop()

    def update(self, progress: SearchProgress) -> None:
        if not self.enabled or progress.seconds < 1.0:
            return
        text = f"certified search: {progress.motions} motions found, {progress.nodes} nodes, {progress.seconds:.1f} s"
        if self.status is None:
            self.status = self.console.status(text)
            self.status.start()
        else:
            self.status.update(text)


_PICTURE_FORMATS = (".png", ".svg", ".pdf")


@app.command()
def plot(
    scene_file: SceneArgument,
    output: Annotated[Path, typer.Option("--output", "-o", help="Picture file: .png, .svg or .pdf (by its extension).")],
    method: Annotated[str, typer.Option(help=f"Solver: {', '.join(METHODS)}.")] = "auto",
    view: Annotated[str, typer.Option(help="How a 3-D scene is seen: iso, xy, xz or yz (a 2-D one: its plane).")] = "iso",
) -> None:
    """Solve a scene file and draw the answer: contact modes, forces and slips to scale, the twist (docs/pictures.md)."""
    from .viz import VIEWS

    if output.suffix.lower() not in _PICTURE_FORMATS:
        _fail(f"--output {str(output)!r}: the extension must be one of {', '.join(_PICTURE_FORMATS)}")
    if view not in VIEWS:
        _fail(f"--view {view!r} is not one of {', '.join(VIEWS)}")
    from .viz import plot as draw  # matplotlib and the solvers load once the options are known to be good
    from .viz import require_matplotlib, save

    _guarded(require_matplotlib)
    scene, detection, world = _loaded_world(scene_file)
    solution = _solved(scene, detection, method=method)
    figure = _guarded(lambda: draw(solution, world or scene, view=view))
    try:
        save(figure, output)
    except OSError as exc:
        _fail(f"cannot write {str(output)!r}: {exc.strerror or exc}")
    typer.echo(f"wrote {output}: {solution.status}")
    raise typer.Exit(1 if solution.status == "failed" else 0)


@app.command("sweep")
def sweep_command(
    scene_file: SceneArgument,
    param: Annotated[list[str], typer.Option(help="PATH=START:STOP:COUNT or PATH=V1,V2,... (repeatable; the grid is their product).")],
    out: Annotated[Path | None, typer.Option(help="Table of every point: .parquet or .csv (chunks kept in OUT.chunks/).")] = None,
    plot: Annotated[Path | None, typer.Option(help="Phase diagram over the (one or two) parameters: .png, .svg or .pdf.")] = None,
    jobs: Annotated[int, typer.Option(help="Local worker processes (joblib); -1: every core.")] = 1,
    dask: Annotated[str | None, typer.Option(help="Dask scheduler address (tcp://host:8786) or local:N workers.")] = None,
    resume: Annotated[bool, typer.Option("--resume", help="Skip the chunks already finished in OUT.chunks/.")] = False,
    refine: Annotated[int | None, typer.Option(help="Bisections of each phase boundary (default 3 with --plot, else 0).")] = None,
    phase: Annotated[str, typer.Option(help="Phases: status, or modes (status and every contact's mode).")] = "status",
    method: Annotated[str, typer.Option(help=f"Solver: {', '.join(METHODS)}.")] = "auto",
    certify: Annotated[
        bool, typer.Option("--certify/--no-certify", help="Prove every answer (default), or take the first audited one: unproven.")
    ] = True,
    chunk_size: Annotated[int | None, typer.Option(min=1, help="Points per chunk (default: 4 chunks per worker, at most 256).")] = None,
    time_limit: Annotated[float, typer.Option(help="Seconds each point's certified search may take.")] = 60.0,
) -> None:
    """Solve a scene over a grid of parameter values (docs/planning.md#sweeps): a table, a phase diagram."""
    from .sweeps.params import parse_param_spec, sweep_params

    if out is not None and out.suffix.lower() not in (".parquet", ".csv"):
        _fail(f"--out {str(out)!r}: the extension must be .parquet or .csv")
    if plot is not None and plot.suffix.lower() not in _PICTURE_FORMATS:
        _fail(f"--plot {str(plot)!r}: the extension must be one of {', '.join(_PICTURE_FORMATS)}")
    if resume and out is None:
        _fail("--resume needs --out: the finished chunks are kept next to it")
    if plot is not None and len(param) > 2:
        _fail(f"--plot draws one or two parameters; {len(param)} --param options were given")
    if plot is not None:
        from .viz import require_matplotlib

        _guarded(require_matplotlib)
    grid = dict(_guarded(lambda: [parse_param_spec(text) for text in param]))
    _guarded(lambda: sweep_params(read_scene_data(scene_file), grid))  # a bad file or path, refused as sweep() would
    from .sweeps import sweep  # the solvers (and pyarrow, dask where asked for) load once the options are known to be good

    bar = _SweepBar()
    try:
        result = _guarded(
            lambda: sweep(
                scene_file,
                grid,
                method=method,
                certify=certify,
                time_limit=time_limit,
                jobs=jobs,
                dask=dask,
                chunk_size=chunk_size,
                chunk_dir=None if out is None else out.with_name(out.name + ".chunks"),
                resume=resume,
                refine=(3 if plot is not None else 0) if refine is None else refine,
                phase=phase,  # type: ignore[arg-type]  # checked by sweep()
                progress=bar.update,
            )
        )
    finally:
        bar.stop()
    _sweep_outputs(result, out, plot, phase)


class _SweepBar:
    """A progress bar on stderr, shown from the first finished chunk (so an input error stays one line)."""

    def __init__(self) -> None:
        from rich.progress import Progress

        self.progress = Progress(console=Console(stderr=True), transient=True)
        self.task = self.progress.add_task("sweep", total=None)
        self.started = False

    def update(self, done: int, planned: int) -> None:
        if not self.started:
            self.progress.start()
            self.started = True
        self.progress.update(self.task, completed=done, total=planned)

    def stop(self) -> None:
        if self.started:
            self.progress.stop()


def _sweep_outputs(result: SweepResult, out: Path | None, plot: Path | None, phase: str) -> None:
    """Write the table and the diagram, print the count of each status; exit 1 when a point failed."""
    try:
        if out is not None:
            _guarded(lambda: result.to_csv(out) if out.suffix.lower() == ".csv" else result.to_parquet(out))
            typer.echo(f"wrote {out}")
        if plot is not None:
            from .viz import phase_diagram, save

            save(phase_diagram(result.phase_map(phase)), plot)  # type: ignore[arg-type]
            typer.echo(f"wrote {plot}")
    except OSError as exc:
        _fail(f"cannot write {exc.filename!r}: {exc.strerror or exc}")
    counts = Counter(p.status for p in result.points)
    unproven = sum(not p.certified for p in result.points if p.status != "failed")
    summary = ", ".join(f"{n} {status}" for status, n in counts.most_common())
    reused = f"; {result.reused} read from finished chunks" if result.reused else ""
    typer.echo(f"{len(result.points)} points ({len(result.refined)} refinement): {summary}; {unproven} unproven{reused}")
    raise typer.Exit(1 if counts.get("failed") else 0)


@app.command()
def simulate(
    scene_file: SceneArgument,
    duration: Annotated[float, typer.Option(help="Length of the run [s].")],
    dt: Annotated[float, typer.Option(help="Largest time step [s]; shortened where surfaces close in, bisected at events.")] = 0.01,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Save the trajectory: .npz or .jsonl.")] = None,
    ambiguous: Annotated[
        str, typer.Option(help="At an ambiguous answer: stop, or min-power (go on with the least-power motion).")
    ] = "stop",
    method: Annotated[str, typer.Option(help=f"Solver at every step: {', '.join(METHODS)}.")] = "auto",
    all_solutions: Annotated[
        bool,
        typer.Option(
            "--all-solutions/--first-solution",
            help="Certify every step (default), or follow the first audited motion found, marked unproven.",
        ),
    ] = True,
) -> None:
    """Follow a scene of shapes or URDF robots over time: contacts found again and a certified solve at every step (docs/simulation.md)."""
    policies = {"stop": "stop", "min-power": "min_power", "min_power": "min_power"}
    if ambiguous not in policies:
        _fail(f"--ambiguous {ambiguous!r} is not one of stop, min-power")
    if out is not None and out.suffix not in (".npz", ".jsonl"):
        _fail(f"--out {str(out)!r}: a trajectory is saved as .npz or .jsonl")
    world = _guarded(lambda: load_world(scene_file))
    from .sim import simulate as run  # the solvers load once the options and the scene are known to be good

    console = make_console()
    with _progress_bar(console, duration) as advance:
        trajectory: Trajectory = _guarded(
            lambda: run(world, duration, dt, ambiguous=policies[ambiguous], method=method, certify=all_solutions, progress=advance)  # type: ignore[arg-type]
        )
    trajectory = replace(trajectory, scene_file=str(scene_file.resolve()))  # for `animate`
    if out is not None:
        try:
            trajectory.save(out)
        except OSError as exc:
            _fail(f"cannot write {str(out)!r}: {exc.strerror or exc}")
    render_trajectory(trajectory, console, saved=str(out or ""))
    raise typer.Exit(1 if trajectory.status == "failed" else 0)


@app.command()
def animate(
    trajectory_file: Annotated[Path, typer.Argument(metavar="TRAJECTORY", help="A trajectory saved by `simulate --out` (.npz or .jsonl).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The animation: .gif, or .mp4 when ffmpeg is installed.")],
    scene: Annotated[Path | None, typer.Option(help="The scene file it was run on (default: the one the trajectory names).")] = None,
    view: Annotated[str, typer.Option(help="How a 3-D scene is seen: iso, xy, xz or yz (a planar one: its plane).")] = "iso",
    fps: Annotated[int, typer.Option(help="Frames per second.", min=1, max=120)] = 20,
) -> None:
    """Draw a simulated trajectory as an animation: shapes, robot links, contacts by mode, forces to scale."""
    from .viz import VIEWS, animation_output

    if view not in VIEWS:
        _fail(f"--view {view!r} is not one of {', '.join(VIEWS)}")
    output = _guarded(lambda: animation_output(output))
    from .sim import Trajectory  # matplotlib, sim/ and the solvers load once the options are known to be good
    from .viz import animate as draw
    from .viz import require_matplotlib

    _guarded(require_matplotlib)
    trajectory = _guarded(lambda: Trajectory.load(trajectory_file))
    world = _run_world(trajectory_file, trajectory, scene)
    try:
        _guarded(lambda: draw(trajectory, world, output, view=view, fps=fps))
    except OSError as exc:
        _fail(f"cannot write {str(output)!r}: {exc.strerror or exc}")
    typer.echo(f"wrote {output}: {len(trajectory.states)} states, {trajectory.status}")


@contextmanager
def _progress_bar(console: Console, duration: float) -> Iterator[Callable[[float, float], None]]:
    """A progress bar over simulated time, on stderr, shown once a run has taken a second."""
    with Progress(
        TextColumn("simulating"),
        BarColumn(),
        TextColumn("t = {task.completed:.4g} / {task.total:.4g} s"),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        task = progress.add_task("run", total=duration)
        yield lambda time, _: progress.update(task, completed=time)


@app.command()
def view(
    scene_file: Annotated[
        Path,
        typer.Argument(
            metavar="SCENE", help="Scene file (.yaml, .yml or .json), or a trajectory saved by `simulate --out` (.npz, .jsonl)."
        ),
    ],
    method: Annotated[str, typer.Option(help=f"Solver: {', '.join(METHODS)} (also for the live re-solves).")] = "auto",
    host: Annotated[str, typer.Option(help="Address the viewer's server listens on.")] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="Port of the viewer's server (the next free one when taken; 0: any free one).")] = 8080,
    export: Annotated[Path | None, typer.Option(help="Write the view as one .html file that opens without a server, and exit.")] = None,
    scene: Annotated[Path | None, typer.Option(help="For a trajectory: the scene file it was run on (default: the one it names).")] = None,
    view: Annotated[str, typer.Option("--view", help="Where the camera starts (3-D): iso, xy, xz or yz.")] = "iso",
) -> None:
    """Show the answer in an interactive 3-D viewer in the browser (viser; docs/pictures.md), until Ctrl-C.

    Given a trajectory, a timeline (with play/pause) scrubs its states: nothing is solved, everything drawn was recorded.
    """
    from .viz import VIEWS

    if view not in VIEWS:
        _fail(f"--view {view!r} is not one of {', '.join(VIEWS)}")
    if export is not None and export.suffix.lower() != ".html":
        _fail(f"--export {str(export)!r}: the file must end in .html")
    if not 0 <= port <= 65535:
        _fail(f"--port {port}: not a port number (0 to 65535)")
    from .viz import require_viser  # viser and the solvers load once the options are known to be good
    from .viz import view as show

    _guarded(require_viser)
    if scene_file.suffix.lower() in _TRAJECTORY_FORMATS:
        if method != "auto":
            _fail(f"--method {method!r}: a trajectory is drawn from what it recorded, never solved again")
        _view_trajectory(scene_file, scene, host, port, export, view)
        return
    if scene is not None:
        _fail(f"--scene {str(scene)!r}: only a trajectory (.npz, .jsonl) is drawn on another scene file")
    from .adapters import World

    answered, detection, loaded = _loaded_world(scene_file)
    world = loaded if isinstance(loaded, World) else None  # the 3-D viewer draws a planar world as its 2-D scene
    solution = _solved(answered, detection, method=method)
    viewer = _guarded(
        lambda: show(solution, world or answered, host=host, port=0 if export is not None else port, method=method, camera=view)
    )
    _serve_or_export(viewer, export, solution.status)
    if export is not None:
        raise typer.Exit(1 if solution.status == "failed" else 0)


_TRAJECTORY_FORMATS = (".npz", ".jsonl")


def _view_trajectory(trajectory_file: Path, scene: Path | None, host: str, port: int, export: Path | None, camera: str) -> None:
    """`view` of a trajectory: its states on the scene file it names (or --scene), with a timeline."""
    from .adapters import World
    from .sim import Trajectory
    from .viz import view_trajectory

    trajectory = _guarded(lambda: Trajectory.load(trajectory_file))
    world = _run_world(trajectory_file, trajectory, scene)
    if not isinstance(world, World):
        command = f"quasistatic animate {shlex.quote(str(trajectory_file))} -o {shlex.quote(trajectory_file.with_suffix('.gif').name)}"
        reason = f"the 3-D viewer does not draw runs of planar scenes of shapes yet; `{command}` does"
        _fail(f"{str(trajectory_file)!r}: {reason}")
    viewer = _guarded(lambda: view_trajectory(trajectory, world, host=host, port=0 if export is not None else port, camera=camera))
    summary = f"{len(trajectory.states)} states, {trajectory.status}" + ("" if trajectory.certified else ", NOT proven")
    _serve_or_export(viewer, export, summary)


def _run_world(trajectory_file: Path, trajectory: Trajectory, scene: Path | None) -> AnyWorld:
    """The world a run is drawn on: ``--scene``, or the scene file the trajectory names."""
    if scene is None:
        if not trajectory.scene_file:
            _fail(f"{str(trajectory_file)!r} names no scene file (it was run on a World built in Python): give --scene")
        return _guarded(trajectory.scene_world)
    loaded = _guarded(lambda: load_world(scene))
    if isinstance(loaded, Scene):
        _fail(f"--scene {str(scene)!r} lists its contacts: a trajectory is run on a scene of shapes")
    return loaded


def _serve_or_export(viewer: Any, export: Path | None, summary: str) -> None:
    """Write the view to ``export`` and stop the server, or print the address and serve until Ctrl-C."""
    if export is None:
        typer.echo(f"viewer at {viewer.url} ({summary}); press Ctrl-C to stop")
        viewer.wait()
        return
    try:
        viewer.export_html(export)
    except OSError as exc:
        _fail(f"cannot write {str(export)!r}: {exc.strerror or exc}")
    finally:
        viewer.stop()
    typer.echo(f"wrote {export}: {summary}")


@app.command()
def check(scene_file: SceneArgument) -> None:
    """Validate a scene file without solving it (a scene with shapes or URDF robots has its contacts found)."""
    scene, detection = _loaded(scene_file)
    found = "" if detection is None else f" ({len(detection.contacts)} found)"
    typer.echo(
        f"ok: {len(scene.bodies)} bodies, {len(scene.movers)} movers, {len(scene.contacts)} contacts{found}, "
        f"dimension {scene.dimension}, friction {scene.friction}"
    )
    for line in () if detection is None else detection.notes():
        typer.echo(line)


@app.command()
def contacts(
    scene_file: SceneArgument,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the scene with its contacts listed (format version 1, JSON), and nothing else.")
    ] = False,
) -> None:
    """Find the contacts of a scene with shapes or URDF robots, and print them.

    With --json the output is the same scene with every contact listed (points, normals, mu, robot Jacobians):
    a plain scene file that `quasistatic solve` reads.
    """
    scene, detection = _loaded(scene_file)
    if as_json:
        typer.echo(json.dumps(scene_to_dict(scene), indent=2, allow_nan=False))
        return
    gaps = (0.0,) * len(scene.contacts) if detection is None else detection.gaps + (0.0,) * (len(scene.contacts) - len(detection.gaps))
    render_contacts(scene.contacts, gaps, () if detection is None else detection.notes(), make_console())


@app.command()
def validate(
    folder: Annotated[Path, typer.Option(help="Folder holding cases.yaml and its scenes.")] = Path("validation"),
) -> None:
    """Run the validation suite (classical results with known answers) and print a table.

    Exit 1 when a case fails, or when a documented disagreement no longer fails (update cases.yaml).
    """
    from .tools.validation import render_results, run_validation

    results = _guarded(lambda: run_validation(folder))
    render_results(results, make_console())
    raise typer.Exit(0 if all(r.ok for r in results) else 1)


@app.command("plan")
def plan_command(
    scene_file: SceneArgument,
    twist: Annotated[
        list[str], typer.Option(help="Wanted twist of a body, BODY=v1,v2,... (repeat per body; a one-body scene may omit BODY=).")
    ],
    modes: Annotated[str, typer.Option(help="Wanted contact modes, one per contact in order: rolling, sliding or separating.")],
    free: Annotated[
        list[str] | None, typer.Option(help="A robot or mover whose inputs the planner chooses (repeatable; default: every robot).")
    ] = None,
    certify: Annotated[
        bool, typer.Option("--certify/--no-certify", help="Also solve the planned scene forward: is the motion the only one?")
    ] = False,
    min_speed: Annotated[float | None, typer.Option(help="Smallest slip or separation speed to plan for [length/time].")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the plan as JSON (PlanResult.to_dict()) and nothing else.")] = False,
) -> None:
    """Plan the inputs (joint velocities, mover twists) that give a wanted motion with wanted contact modes."""
    from .plan import plan  # the planner's numerics load only for this command

    scene, _ = _loaded(scene_file)
    wanted = _guarded(lambda: _parse_twists(twist))
    wanted_modes = _guarded(lambda: _parse_plan_modes(modes))
    result = _guarded(
        lambda: plan(scene, wanted, wanted_modes, free=free, certify=certify, min_speed=min_speed)  # type: ignore[arg-type]
    )
    if as_json:
        typer.echo(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    else:
        typer.echo(f"{result.status}: {result.message}")
        for name, value in zip(result.input_names, result.inputs, strict=True):
            typer.echo(f"  {name} = {float(value) + 0.0:.6g}")
    raise typer.Exit(1 if result.status == "failed" else 0)


def _parse_twists(entries: list[str]) -> dict[str, list[float]] | list[float]:
    """``BODY=v1,v2,...`` per entry, or one bare ``v1,v2,...`` for a one-body scene."""
    parsed: dict[str, list[float]] = {}
    for entry in entries:
        name, _, numbers = entry.rpartition("=")
        try:
            values = [float(x) for x in numbers.split(",")]
        except ValueError:
            raise ValueError(f"--twist {entry!r}: expected BODY=v1,v2,... with numbers") from None
        if not name and len(entries) == 1:
            return values
        parsed[name] = values
    return parsed


def _parse_plan_modes(text: str) -> list[Mode]:
    words = [word.strip().lower() for word in text.split(",")]
    for index, word in enumerate(words):
        if word not in ("rolling", "sliding", "separating"):
            raise ValueError(f"--modes entry {index} is {word!r}; expected rolling, sliding or separating")
    return words  # type: ignore[return-value]


def main() -> None:
    """Entry point of the ``quasistatic`` command: every failure is one ``error:`` line on stderr.

    Usage errors (an unknown option, a missing argument, a bad option value) exit 2 like bad
    input; an error nobody expected exits 1 with its type and message, not a traceback.
    """
    try:
        code = app(standalone_mode=False)
    except _USAGE_ERROR as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # the help is the answer to no arguments
            _echo_help(exc)
            sys.exit(2)
        _print_error(_usage_message(exc))
        sys.exit(2)
    except typer.Abort:
        _print_error("aborted")
        sys.exit(1)
    except Exception as exc:  # a bug or a crash below the library: still one line
        _print_error(f"internal error, please report it: {type(exc).__name__}: {exc}")
        sys.exit(1)
    sys.exit(code if isinstance(code, int) else 0)


# typer vendors click in recent versions: the click exception class is found through typer's own public subclass.
_USAGE_ERROR: type[Exception] = next(k for k in typer.BadParameter.__mro__ if k.__name__ == "ClickException")


def _usage_message(exc: Exception) -> str:
    """Click's message for a usage error, and where the command's help is."""
    message = str(getattr(exc, "format_message", lambda: str(exc))()).rstrip(".")
    context = getattr(exc, "ctx", None)
    command = getattr(context, "command_path", None) or "quasistatic"
    return f"{message} (see '{command} --help')"


def _echo_help(exc: Exception) -> None:
    """Print the help that click put in a no-arguments error, unless typer's rich output printed it already."""
    text = str(getattr(exc, "format_message", lambda: "")())
    if text.strip():
        typer.echo(text)


def _parse_modes(text: str) -> list[Mode | None]:
    words = [word.strip().lower() for word in text.split(",")]
    for index, word in enumerate(words):
        if word not in _MODE_WORDS:
            raise ValueError(f"--modes entry {index} is {word!r}; expected one of {', '.join(_MODE_WORDS)}")
    return [_MODE_WORDS[word] for word in words]


def _guarded(action: Callable[[], _T]) -> _T:
    """Run a library call; bad input becomes one ``error:`` line on stderr and exit code 2, a solver crash exit code 1."""
    try:
        return action()
    except SolverError as exc:
        _fail(str(exc), code=1)
    except (QuasistaticError, ValueError) as exc:
        _fail(str(exc))


def _fail(message: str, code: int = 2) -> NoReturn:
    _print_error(message)
    raise typer.Exit(code)


def _print_error(message: str) -> None:
    """One ``error:`` line on stderr: whitespace runs become one space, other control characters are escaped."""
    line = " ".join(message.split())
    if not line.isprintable():
        line = "".join(c if c.isprintable() else repr(c)[1:-1] for c in line)
    typer.echo(f"error: {line}", err=True)


def _report(solution: Solution, as_json: bool) -> None:
    if as_json:
        try:
            text = json.dumps(solution.to_dict(), indent=2, allow_nan=False)
        except ValueError:  # strict JSON has no Infinity or NaN: such an answer is a bug, not output
            _fail("the answer holds a number that is not finite; JSON cannot carry it (please report it)", code=1)
        typer.echo(text)
    else:
        render_solution(solution, make_console())
    raise typer.Exit(1 if solution.status == "failed" else 0)


@app.command()
def bench(
    full: Annotated[bool, typer.Option("--full/--quick", help="Full families and sizes, or the quick CI subset (default).")] = False,
    out: Annotated[Path | None, typer.Option(help="Folder for results.csv, results.json, results.md and scaling.png.")] = None,
    repeat: Annotated[int, typer.Option(min=1, help="Timed solves per scene after the discarded warm-up solve.")] = 5,
    family: Annotated[list[str] | None, typer.Option(help="Run only this family (repeatable).")] = None,
    method: Annotated[list[str] | None, typer.Option(help="Run only this method (repeatable); the baseline always runs.")] = None,
    instances: Annotated[int | None, typer.Option(min=1, help="Scenes per size (default: the family's own).")] = None,
    cap: Annotated[float | None, typer.Option(min=0.001, help="Seconds per solve past which larger sizes are skipped.")] = None,
    budget: Annotated[float | None, typer.Option(min=0.001, help="Seconds of timed solves aimed at per row.")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write the log-log time-vs-contacts plot here (needs matplotlib).")] = None,
    batch: Annotated[bool, typer.Option("--batch/--no-batch", help="Measure solve_many throughput.")] = True,
    robots: Annotated[bool, typer.Option("--robots/--no-robots", help="Measure robots and geometry (Allegro, detection).")] = True,
    sweeps: Annotated[bool, typer.Option("--sweeps/--no-sweeps", help="Measure sweep throughput (serial, joblib, Dask).")] = True,
    check: Annotated[bool, typer.Option("--check", help="Exit 1 if a method contradicts the certified answer (CI).")] = False,
) -> None:
    """Benchmark every method on generated problem families against baselines measured in the same run."""
    import sys

    from .tools.bench import BenchConfig, render_result, run_benchmarks, write_results, write_scaling_plot

    config = _guarded(
        lambda: BenchConfig(
            full=full,
            repeat=repeat,
            families=tuple(family) if family else None,
            methods=tuple(method) if method else None,
            instances=instances,
            cap=cap if cap is not None else (30.0 if full else 5.0),
            row_budget=budget if budget is not None else (5.0 if full else 2.0),
            batch=batch,
            robots=robots,
            sweeps=sweeps,
        )
    )
    console = make_console()
    result = run_benchmarks(config, progress=lambda line: print(line, file=sys.stderr, flush=True))
    render_result(result, console)
    if out is not None:
        for path in write_results(result, out):
            console.print(f"wrote {path}")
    for target in [p for p in (plot, out / "scaling.png" if out is not None else None) if p is not None]:
        written = write_scaling_plot(result, target)
        console.print(f"wrote {written}" if written else f"no plot written to {target} (matplotlib missing or no scaling rows)")
    contradicting = [row for row in result.rows if row.contradictions]
    for row in contradicting:
        console.print(f"[red]{row.family} {row.size_label} {row.method}: {row.contradictions} answer(s) contradict the certified one[/red]")
    if check and contradicting:
        raise typer.Exit(1)
