"""Pictures as a person sees them: ``quasistatic plot`` run as a command, its PNGs read back and looked at.

Each picture must exist, have a sane size, not be blank, and show the colour of
every contact mode of the answer (and none of the others); one reference picture
is compared with ``tests/data/two_finger_lift.png`` within a tolerance. To make
that reference again after a deliberate change of the picture:
``quasistatic plot examples/two_finger_lift.yaml -o tests/data/two_finger_lift.png``.
"""

from __future__ import annotations

import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")

import quasistatic as qs  # noqa: E402
from quasistatic.viz import MODE_COLOURS  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
DATA = Path(__file__).resolve().parent / "data"
COMMAND = Path(sys.executable).with_name("quasistatic")
REFERENCE = DATA / "two_finger_lift.png"

# scene -> (status, the modes its answer has); a mode not listed must not be drawn.
CASES = {
    "two_finger_lift.yaml": ("solved", {"rolling", "sliding"}),
    "robot_tip.yaml": ("solved", {"rolling", "sliding"}),
    "box_push_3d.yaml": ("ambiguous", {"rolling", "sliding"}),
    "box_push_shapes.yaml": ("ambiguous", {"rolling", "sliding"}),
    "push_into_wall.yaml": ("jammed", set()),
    "topple.yaml": ("unstable", set()),
    str(DATA / "lift_off_floor.yaml"): ("solved", {"rolling", "separating"}),
}
_NEAR = 0.06  # RGB distance (0..1 per channel) within which a pixel has a colour: antialiased edges stay out
_PRESENT = 40  # pixels of a colour that show it is drawn (a contact dot alone is about 100)
_ABSENT = 8  # at most this many stray pixels of a colour that is not drawn


def _plot(scene: str | Path, output: Path, *options: str) -> subprocess.CompletedProcess[str]:
    scene_path = Path(scene) if Path(scene).is_absolute() else EXAMPLES / scene
    command = [str(COMMAND), "plot", str(scene_path), "-o", str(output), *options]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)


def _pixels(path: Path) -> np.ndarray:
    from matplotlib.image import imread

    image = imread(path)
    return np.asarray(image[..., :3], dtype=float)


def _count(pixels: np.ndarray, colour: str) -> int:
    from matplotlib.colors import to_rgb

    distance = np.linalg.norm(pixels - np.array(to_rgb(colour)), axis=-1)
    return int(np.count_nonzero(distance < _NEAR))


def _above_the_legend(pixels: np.ndarray) -> np.ndarray:
    """The rows above the lowest panel's bottom frame (a long black line): the legend below shows every mode drawn too."""
    dark = np.linalg.norm(pixels, axis=-1) < 0.1
    frames = np.flatnonzero(dark.mean(axis=1) > 0.3)
    assert len(frames), "no panel frame found"
    return pixels[: frames[-1]]


@pytest.fixture(scope="module")
def pictures(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, subprocess.CompletedProcess[str]]]:
    """Every case drawn once by the console script, two processes at a time (each takes ~3 s, mostly imports)."""
    folder = tmp_path_factory.mktemp("pictures")
    outputs = {scene: folder / f"{Path(scene).stem}.png" for scene in CASES}
    with ThreadPoolExecutor(max_workers=2) as pool:
        runs = dict(zip(outputs, pool.map(lambda scene: _plot(scene, outputs[scene]), outputs), strict=True))
    return {scene: (outputs[scene], runs[scene]) for scene in CASES}


@pytest.mark.parametrize("scene", sorted(CASES))
def test_the_command_writes_a_picture_that_is_not_blank(scene: str, pictures: dict) -> None:
    path, run = pictures[scene]
    status, _ = CASES[scene]
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip().endswith(status) and not run.stderr
    assert 10_000 < path.stat().st_size < 2_000_000
    pixels = _pixels(path)
    assert 400 <= pixels.shape[0] <= 2000 and 400 <= pixels.shape[1] <= 2000
    assert pixels.std() > 0.05, "the picture is blank"


@pytest.mark.parametrize("scene", sorted(CASES))
def test_the_modes_of_the_answer_are_drawn_in_their_colours(scene: str, pictures: dict) -> None:
    path, _ = pictures[scene]
    _, modes = CASES[scene]
    pixels = _above_the_legend(_pixels(path))
    counts = {mode: _count(pixels, colour) for mode, colour in MODE_COLOURS.items()}
    for mode in MODE_COLOURS:
        if mode in modes:
            assert counts[mode] >= _PRESENT, (mode, counts)
        else:
            assert counts[mode] <= _ABSENT, (mode, counts)


def test_the_demo_matches_its_reference_picture(pictures: dict) -> None:
    from matplotlib.testing.compare import compare_images

    path, _ = pictures["two_finger_lift.yaml"]
    # RMS over 0..255 pixel values: font rendering may differ a little between machines, a changed drawing does not pass.
    assert compare_images(str(REFERENCE), str(path), tol=12) is None


@pytest.mark.parametrize("extension", [".svg", ".pdf"])
def test_vector_formats_by_extension(extension: str, tmp_path: Path) -> None:
    output = tmp_path / f"lift{extension}"
    run = _plot("two_finger_lift.yaml", output, "--method", "lp")
    assert run.returncode == 0, run.stderr
    head = output.read_bytes()[:200]
    assert (b"<svg" in head or b"<?xml" in head) if extension == ".svg" else head.startswith(b"%PDF")


@pytest.mark.parametrize(
    ("scene", "options", "needle"),
    [
        ("two_finger_lift.yaml", ("--view", "sideways"), "--view"),
        ("no_such_scene.yaml", (), "no_such_scene.yaml"),
        ("two_finger_lift.yaml", ("--method", "nope"), "nope"),
    ],
)
def test_bad_input_is_one_error_line(scene: str, options: tuple[str, ...], needle: str, tmp_path: Path) -> None:
    run = _plot(scene, tmp_path / "out.png", *options)
    _assert_one_error(run, needle)
    assert not (tmp_path / "out.png").exists()


def test_an_unknown_extension_is_one_error_line(tmp_path: Path) -> None:
    run = _plot("two_finger_lift.yaml", tmp_path / "out.gif")
    _assert_one_error(run, ".gif")


def test_missing_matplotlib_is_one_error_line_with_the_install_hint(tmp_path: Path) -> None:
    hide = "import sys; sys.modules['matplotlib'] = None; from quasistatic.cli import main; sys.argv[0] = 'quasistatic'; main()"
    scene = str(EXAMPLES / "two_finger_lift.yaml")
    command = [sys.executable, "-c", hide, "plot", scene, "-o", str(tmp_path / "out.png")]
    run = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    _assert_one_error(run, "quasistatic[figures]")


def _assert_one_error(run: subprocess.CompletedProcess[str], needle: str) -> None:
    assert run.returncode == 2, (run.stdout, run.stderr)
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], run.stderr


# --------------------------------------------------------------------------- the Python side


@pytest.fixture(scope="module")
def box_push() -> tuple[qs.Scene, qs.Solution]:
    scene = qs.load_scene(EXAMPLES / "box_push_3d.yaml")
    return scene, qs.solve(scene)


@pytest.mark.parametrize("view", ["iso", "xy", "xz", "yz"])
def test_plot_returns_a_figure_in_each_view(view: str, box_push: tuple[qs.Scene, qs.Solution]) -> None:
    scene, solution = box_push
    figure = qs.plot(solution, scene, view=view)
    assert len(figure.axes) == len(solution.solutions)
    assert solution.status in figure.get_suptitle()


def test_plot_draws_into_a_given_axes(box_push: tuple[qs.Scene, qs.Solution]) -> None:
    from matplotlib.figure import Figure

    scene, solution = box_push
    figure = Figure()
    ax = figure.add_subplot()
    assert qs.plot(solution, scene, ax=ax) is figure
    assert ax.get_legend() is not None and solution.status in ax.get_title(loc="left")


def test_an_unknown_view_is_a_value_error(box_push: tuple[qs.Scene, qs.Solution]) -> None:
    scene, solution = box_push
    with pytest.raises(ValueError, match="view"):
        qs.plot(solution, scene, view="top")


def test_a_solution_shows_itself_in_a_notebook(box_push: tuple[qs.Scene, qs.Solution], monkeypatch: pytest.MonkeyPatch) -> None:
    _, solution = box_push
    png = solution._repr_png_()
    assert png is not None and png.startswith(b"\x89PNG") and len(png) > 5_000
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if the figures extra were not installed
    assert solution._repr_png_() is None


def test_robot_links_are_drawn_behind_the_scene(tmp_path: Path, pictures: dict) -> None:
    """A URDF robot's collision shapes appear (translucent robot fill over white); a scene without one has none."""
    pytest.importorskip("pinocchio")
    from matplotlib.colors import to_hex, to_rgb

    from quasistatic.viz.style import ROBOT_FILL

    over_white = to_hex(0.6 * np.array(to_rgb(ROBOT_FILL)) + 0.4)  # alpha 0.6 on the white page
    robot, (plain, _) = tmp_path / "allegro.png", pictures["box_push_shapes.yaml"]
    assert _plot(EXAMPLES / "robots" / "allegro_ball.yaml", robot).returncode == 0
    drawn, stray = _count(_above_the_legend(_pixels(robot)), over_white), _count(_above_the_legend(_pixels(plain)), over_white)
    assert drawn > 100 * _PRESENT and stray < _PRESENT, (drawn, stray)  # whole links, against antialiased edges
