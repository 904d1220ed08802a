"""The 3-D viewer as a person sees it: the page in a real headless Chromium, and viser's scene tree behind it.

The live server (``qs.view`` and the ``quasistatic view`` console script) and the exported HTML are
opened in Chromium over the DevTools protocol (tests/browser.py): the page must load without a console
error or an uncaught exception, and its screenshot must show the scene: the mode colours of the contacts
drawn (hue bands, as lighting shades them), and none of a mode the answer lacks. The scene tree must hold
one node per body, contact, force and slip of the answer. Chromium is the Debian ``chromium`` package:
without it these tests skip, except under CI (``CI=true``), where they fail. They are left out of the
default run (marker ``viewer``): ``pytest -m viewer`` runs them, as ``.ci/run`` does.
"""

from __future__ import annotations

import io
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.viewer  # about 100 s (a browser, servers, console scripts): .ci/run runs them apart

pytest.importorskip("viser")
Image = pytest.importorskip("PIL.Image")

import quasistatic as qs  # noqa: E402
from browser import Chromium, PageVisit, chromium_or_skip  # noqa: E402
from quasistatic.viz import Velocities  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
DATA = Path(__file__).resolve().parent / "data"
COMMAND = Path(sys.executable).with_name("quasistatic")

# Hue bands [degrees] of the mode colours as the viewer's lights render them (measured: rolling 150,
# sliding 10, separating 195 at high value; slips 50, forces 190 at lower value, com velocities ~330).
_ROLLING = (135.0, 180.0)
_SLIDING = (0.0, 30.0)
_SATURATED = 0.45  # saturation above which a pixel is coloured (grey parts, white background, text stay out)
_PRESENT = 30  # pixels of a band that show a contact of that mode is drawn (a contact's ball is about 100)
_ABSENT = 15  # at most this many stray pixels of a band that no contact has
_SEEN_THROUGH = 0.3  # saturation of a contact's colour seen through a translucent part (it keeps its hue)
_NOTICE_ROWS = 170  # Chromium's "software WebGL" notice covers the top left: its orange bar is no contact


@pytest.fixture(scope="module")
def chromium() -> Iterator[Chromium]:
    browser = Chromium(chromium_or_skip())
    yield browser
    browser.close()


def _hues(screenshot: bytes) -> tuple[np.ndarray, np.ndarray]:
    """(hue [degrees], saturation) of every pixel below the notice, from a PNG."""
    pixels = np.asarray(Image.open(io.BytesIO(screenshot)).convert("RGB"), dtype=float)[_NOTICE_ROWS:] / 255.0
    high, low = pixels.max(axis=2), pixels.min(axis=2)
    spread = np.maximum(high - low, 1e-9)
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    hue = np.where(high == r, ((g - b) / spread) % 6, np.where(high == g, (b - r) / spread + 2, (r - g) / spread + 4)) * 60.0
    return hue, (high - low) / np.maximum(high, 1e-9)


def _band(visit: PageVisit, band: tuple[float, float], saturated: float = _SATURATED) -> int:
    hue, saturation = _hues(visit.screenshot)
    return int(np.count_nonzero((saturation > saturated) & (hue >= band[0]) & (hue <= band[1])))


def _assert_shows_the_modes(visit: PageVisit, modes: set[str]) -> None:
    assert not visit.errors, visit.errors
    pixels = np.asarray(Image.open(io.BytesIO(visit.screenshot)).convert("RGB"))
    assert pixels.shape[0] >= 600 and len(np.unique(pixels.reshape(-1, 3), axis=0)) > 50, "the page is blank"
    for mode, band in (("rolling", _ROLLING), ("sliding", _SLIDING)):
        count = _band(visit, band)
        assert count >= _PRESENT if mode in modes else count <= _ABSENT, (mode, count, modes)


def _answer(name: str | Path) -> tuple[qs.Scene | qs.World, qs.Solution]:
    loaded = qs.load_world(EXAMPLES / name)
    return loaded, qs.solve(loaded)


def _assert_tree_holds_the_answer(viewer: qs.viz.Viewer, motion: qs.Motion) -> None:
    """One node per body, contact, non-zero force and sliding contact's slip, each in viser's scene tree."""
    drawn, scene = viewer.drawn, viewer.scene
    assert [n.rsplit("/", 1)[1] for n in drawn.bodies] == [b.name for b in scene.bodies]
    assert len(drawn.contacts) == len(scene.contacts)
    assert [int(n.rsplit("/", 1)[1]) for n in drawn.forces] == [i for i, c in enumerate(motion.contacts) if np.linalg.norm(c.force) > 0]
    sliding = [i for i, c in enumerate(motion.contacts) if c.mode == "sliding" and np.linalg.norm(c.slip) > 0]
    assert [int(n.rsplit("/", 1)[1]) for n in drawn.slips] == sliding
    for name in drawn.names:
        assert viewer.server.scene.get_handle_by_name(name) is not None, name


def test_the_live_viewer_shows_a_point_contact_scene(chromium: Chromium) -> None:
    scene, solution = _answer("two_finger_lift.yaml")
    viewer = qs.view(solution, scene, port=0)
    try:
        assert solution.motion is not None
        _assert_tree_holds_the_answer(viewer, solution.motion)
        visit = chromium.visit(viewer.url)
    finally:
        viewer.stop()
    _assert_shows_the_modes(visit, set(solution.motion.modes))


def test_the_motion_control_switches_between_the_motions_of_an_ambiguous_answer() -> None:
    """The planar hand's two motions (the box rises with the fingertips, or slides down between them), and its links."""
    pytest.importorskip("pinocchio")
    world, solution = _answer("robots/planar_hand.yaml")
    assert isinstance(world, qs.World) and solution.status == "ambiguous" and len(solution.solutions) == 2
    viewer = qs.view(solution, world, port=0)
    try:
        links = viewer.drawn.robot_links
        assert len(links) == sum(len(r.colliders) for r in world.robots) > 0
        for index, motion in enumerate(solution.solutions):
            viewer.show_motion(index)
            _assert_tree_holds_the_answer(viewer, motion)
        with pytest.raises(ValueError, match="motion"):
            viewer.show_motion(len(solution.solutions))
    finally:
        viewer.stop()


def test_a_slider_change_solves_again_with_the_new_velocities() -> None:
    """The two fingers lifting the box stopped: the box rests between them, every contact rolling (audited, proven)."""
    scene, solution = _answer("two_finger_lift.yaml")
    viewer = qs.view(solution, scene, port=0)
    try:
        assert solution.motion is not None and solution.motion.twists["box"][1] > 0
        still = Velocities(viewer.velocities.robots, {name: 0.0 * twist for name, twist in viewer.velocities.movers.items()})
        answer = viewer.resolve(still)
        assert answer is viewer.solution and answer.status == "solved" and answer.certified
        assert answer.motion is not None and answer.motion.audit.passed
        assert answer.motion.modes == ("rolling",) * 4 and np.allclose(answer.motion.twists["box"], 0.0)
        assert all(np.allclose(twist, 0.0) for twist in viewer.velocities.movers.values())
        _assert_tree_holds_the_answer(viewer, answer.motion)
        assert viewer.drawn.slips == ()
    finally:
        viewer.stop()


def test_moving_the_sliders_solves_again() -> None:
    """The same stop through the sliders (as a browser sets them): one finger stopped, then the other."""
    scene, solution = _answer("two_finger_lift.yaml")
    viewer = qs.view(solution, scene, port=0)
    try:
        sliders = viewer.sliders
        assert set(sliders) == {"left_finger", "right_finger", "left_wall", "right_wall"} and len(sliders["left_finger"]) == 3
        assert [s.value for s in sliders["left_finger"]] == pytest.approx([0.0, 0.01, 0.0])
        sliders["left_finger"][1].value = 0.0
        half = viewer.solution
        assert half is not solution and np.allclose(viewer.velocities.movers["left_finger"], 0.0)
        assert np.allclose(viewer.velocities.movers["right_finger"], [0.0, 0.01, 0.0])
        sliders["right_finger"][1].value = 0.0
        rest = viewer.solution
        assert rest is not half and rest.status == "solved" and rest.certified and rest.motion is not None
        assert np.allclose(rest.motion.twists["box"], 0.0) and rest.motion.audit.passed
    finally:
        viewer.stop()


# --------------------------------------------------------------------------- the console script


def test_the_command_serves_the_view_until_interrupted(chromium: Chromium) -> None:
    scene = DATA / "lift_off_floor.yaml"
    process = subprocess.Popen([str(COMMAND), "view", str(scene), "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        line = process.stdout.readline()
        found = re.search(r"viewer at (http://\S+) \((\w+)\)", line)
        assert found, (line, process.stderr.read() if process.poll() is not None and process.stderr else "")
        visit = chromium.visit(found.group(1))
    finally:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=60)
    assert process.returncode == 0, err
    assert not err.strip(), err
    _assert_shows_the_modes(visit, {"rolling", "separating"})


def test_the_export_opens_without_a_server(chromium: Chromium, tmp_path: Path) -> None:
    target = tmp_path / "scene.html"
    run = subprocess.run(
        [str(COMMAND), "view", str(EXAMPLES / "two_finger_lift.yaml"), "--export", str(target)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0 and run.stdout.strip() == f"wrote {target}: solved", (run.stdout, run.stderr)
    assert target.stat().st_size > 100_000 and "__VISER_EMBED_DATA__" in target.read_text()
    _assert_shows_rolling_and_sliding(chromium.visit(target.as_uri()))


def _assert_shows_rolling_and_sliding(visit: PageVisit) -> None:
    """No console error, not blank, and rolling and sliding contacts in their colours. A contact inside a translucent
    part (the tipping box's fingertip) keeps its hue at a lower saturation, so the lower threshold is used."""
    assert not visit.errors, visit.errors
    pixels = np.asarray(Image.open(io.BytesIO(visit.screenshot)).convert("RGB"))
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 50, "the page is blank"
    for band in (_ROLLING, _SLIDING):
        assert _band(visit, band, _SEEN_THROUGH) >= _PRESENT, band


@pytest.mark.parametrize(
    ("options", "needle"),
    [
        (("--export", "scene.png"), "--export 'scene.png': the file must end in .html"),
        (("--port", "70000"), "--port 70000"),
        (("--export", "/nonexistent/folder/scene.html"), "cannot write '/nonexistent/folder/scene.html'"),
        (("--host", "no such host.invalid"), "host: cannot listen on 'no such host.invalid'"),
    ],
)
def test_bad_options_are_one_error_line(options: tuple[str, ...], needle: str) -> None:
    run = subprocess.run(
        [str(COMMAND), "view", str(EXAMPLES / "two_finger_lift.yaml"), *options], capture_output=True, text=True, timeout=300
    )
    _assert_one_error(run, needle)


def test_missing_viser_is_one_error_line_with_the_install_hint() -> None:
    hide = "import sys; sys.modules['viser'] = None; from quasistatic.cli import main; sys.argv[0] = 'quasistatic'; main()"
    run = subprocess.run(
        [sys.executable, "-c", hide, "view", str(EXAMPLES / "two_finger_lift.yaml")], capture_output=True, text=True, timeout=120
    )
    _assert_one_error(run, 'pip install "quasistatic[viewer]"')


def _assert_one_error(run: subprocess.CompletedProcess[str], needle: str) -> None:
    assert run.returncode == 2, (run.stdout, run.stderr)
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], run.stderr


# --------------------------------------------------------------------------- a simulated run on the timeline

RUN = DATA / "tip_box_run.npz"  # examples/sim/tip_box.yaml simulated for 1 s with dt 0.25 (tests/test_timeline.py)
TIP = EXAMPLES / "sim" / "tip_box.yaml"


def test_the_timeline_moves_the_run_in_the_browser(chromium: Chromium) -> None:
    """The first and last states of the tipping box: both show the step's rolling (table) and sliding (fingertip)
    contacts, without a console error; the box's pose in the scene tree and the picture change between them."""
    pytest.importorskip("coal")
    trajectory = qs.Trajectory.load(RUN)
    world = qs.load_world(TIP)
    assert isinstance(world, qs.World)
    viewer = qs.view(trajectory, world, port=0, camera="xz")  # the push is in the xz plane: the fingertip is in sight
    try:
        box = viewer.server.scene.get_handle_by_name("/frame/bodies/box")
        start = (np.array(box.position), np.array(box.wxyz))
        first = chromium.visit(viewer.url)
        viewer.timeline.value = len(trajectory.states) - 1  # as dragging the slider to the end does
        box = viewer.server.scene.get_handle_by_name("/frame/bodies/box")
        end = (np.array(box.position), np.array(box.wxyz))
        last = chromium.visit(viewer.url)
    finally:
        viewer.stop()
    assert not np.allclose(start[0], end[0]) and not np.allclose(start[1], end[1])
    for visit, step in ((first, trajectory.steps[0]), (last, trajectory.steps[-1])):
        assert {c.mode for c in step.contacts} >= {"rolling", "sliding"}
        _assert_shows_rolling_and_sliding(visit)
    before = np.asarray(Image.open(io.BytesIO(first.screenshot)).convert("RGB"), dtype=int)
    after = np.asarray(Image.open(io.BytesIO(last.screenshot)).convert("RGB"), dtype=int)
    assert np.count_nonzero(np.abs(before - after).sum(axis=2) > 30) > 200, "the picture did not change along the timeline"


def test_the_exported_run_plays_without_a_server(chromium: Chromium, tmp_path: Path) -> None:
    pytest.importorskip("coal")
    target = tmp_path / "run.html"
    run = subprocess.run(
        [str(COMMAND), "view", str(RUN), "--scene", str(TIP), "--view", "xz", "--export", str(target)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0 and run.stdout.strip() == f"wrote {target}: 6 states, completed", (run.stdout, run.stderr)
    _assert_shows_rolling_and_sliding(chromium.visit(target.as_uri()))
