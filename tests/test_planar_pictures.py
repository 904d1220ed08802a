"""Pictures of planar worlds of shapes: each shape drawn at its pose (patches checked), by `plot` and `animate`."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")

import quasistatic as qs  # noqa: E402
from quasistatic.adapters import Disk, HalfPlane, PlanarBody, PlanarMover, PlanarWorld, Polygon, Rectangle, planar_pose  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "sim"
PUSH = EXAMPLES / "push_planar.yaml"
TIP = EXAMPLES / "tip_box_planar.yaml"
COMMAND = Path(sys.executable).with_name("quasistatic")

TURN = 0.3  # the box's angle [rad]: its drawn corners must be turned by it


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(COMMAND), *args], capture_output=True, text=True, timeout=300, check=False)


def shapes_world() -> PlanarWorld:
    """A turned box resting on one corner on a table, a fingertip disk at its side, and a triangle resting on a wall-less floor."""
    box, half = Rectangle([0.1, 0.06]), np.array([0.05, 0.03])
    lowest = min(planar_pose((0.0, 0.0), TURN).rotation[1, :2] @ (half * s) for s in ([1, 1], [1, -1], [-1, 1], [-1, -1]))
    return PlanarWorld(
        bodies=(
            PlanarBody("box", 1.0, box, planar_pose((0.0, -lowest), TURN)),
            PlanarBody("wedge", 0.5, Polygon([[0.0, 0.0], [0.04, 0.0], [0.0, 0.03]]), planar_pose((0.2, 0.0))),
        ),
        movers=(
            PlanarMover("table", HalfPlane((0.0, 1.0), 0.0)),
            PlanarMover("finger", Disk(0.005), planar_pose((-0.08, 0.04)), (0.01, 0.0, 0.0)),
        ),
    )


def patches_by_name(figure: matplotlib.figure.Figure) -> dict[str, matplotlib.patches.Patch]:
    return {p.get_gid(): p for ax in figure.axes for p in ax.patches if p.get_gid()}


def test_plot_draws_each_planar_shape_at_its_pose() -> None:
    from matplotlib.patches import Circle
    from matplotlib.patches import Polygon as PolygonPatch

    world = shapes_world()
    figure = qs.plot(qs.solve(world), world)
    drawn = patches_by_name(figure)
    assert set(drawn) == {"box", "wedge", "table", "finger"}
    finger = drawn["finger"]
    assert isinstance(finger, Circle)
    np.testing.assert_allclose(finger.center, [-0.08, 0.04])
    assert finger.radius == pytest.approx(0.005)
    box = world.bodies[0]
    c, s = math.cos(TURN), math.sin(TURN)
    corners = np.array([[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]]) @ np.array([[c, s], [-s, c]]) + box.pose.position[:2]
    assert isinstance(drawn["box"], PolygonPatch)
    np.testing.assert_allclose(drawn["box"].get_xy()[:4], corners, atol=1e-12)
    np.testing.assert_allclose(drawn["wedge"].get_xy()[:3], [[0.2, 0.0], [0.24, 0.0], [0.2, 0.03]], atol=1e-12)
    table = drawn["table"].get_xy()[:4]
    assert np.allclose(table[:2, 1], 0.0) and np.all(table[2:, 1] < 0.0)  # the line y = 0, shaded below (its solid side)
    ax = figure.axes[0]
    assert table[:, 0].min() < ax.get_xlim()[0] and table[:, 0].max() > ax.get_xlim()[1]  # longer than the view: clipped to it


def test_the_view_holds_every_bounded_shape() -> None:
    world = shapes_world()
    ax = qs.plot(qs.solve(world), world).axes[0]
    (x0, x1), y1 = ax.get_xlim(), ax.get_ylim()[1]
    assert x0 < -0.085 and x1 > 0.24 and y1 > 0.086  # the finger's left edge, the wedge's tip, the turned box's top corner


@pytest.mark.parametrize("scene", [PUSH, TIP])
def test_the_command_draws_a_planar_example_with_its_shapes(scene: Path, tmp_path: Path) -> None:
    from matplotlib.image import imread

    from quasistatic.viz.style import MOVER_FILL

    out = tmp_path / "scene.png"
    result = run("plot", str(scene), "-o", str(out))
    assert result.returncode == 0, result.stderr
    pixels = np.asarray(imread(out)[..., :3], dtype=float)
    assert pixels.std() > 0.05  # not blank
    grey = np.array(matplotlib.colors.to_rgb(MOVER_FILL))
    assert np.sum(np.all(np.abs(pixels - grey) < 0.02, axis=-1)) > 50  # the fingertip disks are filled in


@pytest.fixture(scope="module")
def push_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run") / "push.npz"
    result = run("simulate", str(PUSH), "--duration", "2", "--dt", "0.1", "--out", str(out))
    assert result.returncode == 0, result.stderr
    return out


def test_animate_draws_a_planar_run_frame_by_frame(push_run: Path, tmp_path: Path) -> None:
    image_module = pytest.importorskip("PIL.Image")
    from matplotlib.colors import to_rgb

    from quasistatic.viz.style import MOVER_FILL

    gif = tmp_path / "push.gif"
    result = run("animate", str(push_run), "-o", str(gif))
    assert result.returncode == 0, result.stderr
    trajectory = qs.Trajectory.load(push_run)
    with image_module.open(gif) as image:
        assert image.n_frames == len(trajectory.states)
        first = np.asarray(image.convert("RGB"), dtype=float) / 255
        image.seek(image.n_frames - 1)
        last = np.asarray(image.convert("RGB"), dtype=float) / 255
    assert last.std() > 0.05  # not blank
    grey = np.array(to_rgb(MOVER_FILL))
    assert np.sum(np.all(np.abs(last - grey) < 0.03, axis=-1)) > 50  # the fingertip disks
    below_title = slice(first.shape[0] // 8, None)  # the title's time changes in every frame
    moved = np.any(np.abs(first[below_title] - last[below_title]) > 0.1, axis=-1)
    assert moved.sum() > 2000  # the box (about 170 px tall) and the fingers have moved 2 cm (about 30 px) to the right


def test_a_planar_run_shows_itself_in_a_notebook(push_run: Path) -> None:
    pytest.importorskip("PIL.Image")
    page = qs.Trajectory.load(push_run)._repr_html_()
    assert '<img alt="the run on its scene" src="data:image/gif;base64,' in page
    assert "not drawn" not in page


def test_the_3d_viewer_refuses_a_planar_run_in_one_line(push_run: Path, tmp_path: Path) -> None:
    pytest.importorskip("viser")
    result = run("view", str(push_run), "--export", str(tmp_path / "push.html"))
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert "planar" in lines[0] and f"`quasistatic animate {push_run} -o push.gif` does" in lines[0]
    assert not (tmp_path / "push.html").exists()
