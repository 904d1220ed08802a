"""A simulated run in the viewer, without a browser: the timeline handle, what each state draws, the exported
recording, the console script, and a Trajectory in a notebook (``_repr_html_``).

The run is ``examples/sim/tip_box.yaml`` simulated for 1 s with dt 0.25 (tests/data/tip_box_run.npz, 6
states): a fingertip pushes a tall box high on its back face, the box pivots on its front edge (two
rolling contacts) while the fingertip slides up its face; at t = 0 the back corners are still on the table
(separating). tests/test_viewer.py opens the same run in a real headless Chromium.
"""

from __future__ import annotations

import base64
import dataclasses
import io
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.viz import MODE_COLOURS, NO_MOTION_COLOUR
from quasistatic.viz.scene3d import rgb

pytest.importorskip("coal")

ROOT = Path(__file__).resolve().parents[1]
TIP = ROOT / "examples" / "sim" / "tip_box.yaml"
RUN = Path(__file__).resolve().parent / "data" / "tip_box_run.npz"
COMMAND = Path(sys.executable).with_name("quasistatic")


@pytest.fixture(scope="module")
def run() -> qs.Trajectory:
    return qs.Trajectory.load(RUN)


@pytest.fixture(scope="module")
def world() -> qs.World:
    loaded = qs.load_world(TIP)
    assert isinstance(loaded, qs.World)
    return loaded


@pytest.fixture
def viewer(run: qs.Trajectory, world: qs.World) -> Any:
    pytest.importorskip("viser")
    shown = qs.view(run, world, port=0)
    yield shown
    shown.stop()


def test_each_state_draws_its_recorded_contacts_in_the_colour_of_their_mode(viewer: Any, run: qs.Trajectory) -> None:
    scene = viewer.server.scene
    for index in (0, 3, len(run.states) - 1):
        drawn = viewer.go_to(index)
        step = run.steps[index]
        assert viewer.index == index and viewer.timeline.value == index
        assert [n.rsplit("/", 1)[1] for n in drawn.bodies] == ["box"] and len(drawn.movers) == 2
        assert len(drawn.contacts) == len(step.contacts)
        for name, contact in zip(drawn.contacts, step.contacts, strict=True):
            colour = MODE_COLOURS[contact.mode] if contact.mode else NO_MOTION_COLOUR
            assert tuple(scene.get_handle_by_name(name).color) == rgb(colour), (name, contact.mode)
        forces = [i for i, c in enumerate(step.contacts) if np.linalg.norm(c.force) > 0]
        assert [int(n.rsplit("/", 1)[1]) for n in drawn.forces] == forces
        assert drawn.twists == ("/frame/twists/box",)
        for name in drawn.names:
            assert scene.get_handle_by_name(name) is not None, name
    modes_at_start = {c.mode for c in run.steps[0].contacts}
    assert modes_at_start == {"sliding", "separating", "rolling"}


def test_moving_the_timeline_places_the_box_at_each_recorded_pose(viewer: Any, run: qs.Trajectory) -> None:
    box = viewer.server.scene.get_handle_by_name
    for index in range(len(run.states)):
        viewer.timeline.value = index  # as dragging the slider in a browser does
        pose = run.states[index].bodies["box"]
        assert viewer.index == index
        assert np.allclose(box("/frame/bodies/box").position, pose.position)
        assert np.allclose(_matrix(box("/frame/bodies/box").wxyz), pose.rotation, atol=1e-9)
        finger = run.states[index].movers["finger"]
        assert np.allclose(box("/frame/movers/finger").position, finger.position)
    first, last = run.states[0].bodies["box"], run.states[-1].bodies["box"]
    assert not np.allclose(first.rotation, last.rotation, atol=1e-3)  # the box has tipped: the poses differ


def _matrix(wxyz: Any) -> np.ndarray:
    """The rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = (float(v) for v in wxyz)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_the_panel_says_the_time_status_proof_and_events_of_the_step(viewer: Any, run: qs.Trajectory) -> None:
    viewer.go_to(1)
    text = viewer._step_text.content
    event = run.steps[1].events[0]
    assert "t = 0.00390625 s" in text and "solved, proven" in text and f"event at t = {event.time:.6g} s: mode change" in text
    with pytest.raises(ValueError, match="step 6 is not one of the 6 states"):
        viewer.go_to(6)
    assert viewer.go_to(-1) is viewer.drawn and viewer.index == 5


def test_an_uncertified_run_is_marked_not_proven(run: qs.Trajectory, world: qs.World) -> None:
    pytest.importorskip("viser")
    steps = tuple(dataclasses.replace(s, certified=False) if i == 2 else s for i, s in enumerate(run.steps))
    shown = qs.view(dataclasses.replace(run, steps=steps), world, port=0)
    try:
        shown.go_to(2)
        assert "NOT proven" in shown._step_text.content
        label = shown.server.scene.get_handle_by_name("/frame/label")
        assert label.text == f"t = {steps[2].time:.4g} s: solved, not proven"  # the export keeps the label, not the panel
        shown.go_to(3)
        label = shown.server.scene.get_handle_by_name("/frame/label")  # each state draws its own
        assert "NOT proven" not in shown._step_text.content and label.text.endswith(": solved")
    finally:
        shown.stop()


def test_play_runs_through_the_states_to_the_end(viewer: Any, run: qs.Trajectory) -> None:
    viewer.go_to(0)
    viewer._speed.value = "10x"  # the 1 s run in 0.1 s
    viewer.play()
    deadline = time.monotonic() + 30
    while viewer.playing and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not viewer.playing and viewer.index == len(run.states) - 1


def test_the_world_comes_from_the_scene_file_the_run_names(run: qs.Trajectory) -> None:
    pytest.importorskip("viser")
    with pytest.raises(qs.SceneError, match="names no scene file"):
        qs.view(run, port=0)
    shown = qs.view(dataclasses.replace(run, scene_file=str(TIP)), port=0)
    try:
        assert [b.name for b in shown.world.bodies] == ["box"]
    finally:
        shown.stop()
    wrong = qs.load_world(ROOT / "examples" / "robots" / "planar_hand.yaml")
    with pytest.raises(qs.SceneError, match="not the scene it was run on"):
        qs.view(run, wrong, port=0)  # type: ignore[call-overload]


def _recording(page: str) -> dict[str, Any]:
    """The recording viser's static client plays, decoded from the exported page (zstd, then msgpack)."""
    msgspec = pytest.importorskip("msgspec")
    zstandard = pytest.importorskip("zstandard")
    found = re.search(r'__VISER_EMBED_DATA__="([^"]+)"', page)
    assert found, "no recording in the page"
    packed = base64.b64decode(found.group(1))
    inner = zstandard.ZstdDecompressor().decompress(packed[8:], max_output_size=int.from_bytes(packed[:8], "little"))
    length = int.from_bytes(inner[:8], "little")
    document: dict[str, Any] = msgspec.msgpack.decode(inner[8 : 8 + length])
    return document


def test_the_export_records_every_state_in_simulated_time(viewer: Any, run: qs.Trajectory, tmp_path: Path) -> None:
    viewer.go_to(3)
    page = viewer.export_html(tmp_path / "run.html").read_text()
    assert viewer.index == 3  # the live view is back where it was
    recording = _recording(page)
    assert recording["durationSeconds"] == pytest.approx(1.1)  # the 1 s run, its last frame held 10 %
    labels = [(t, m["props"]["text"]) for t, m in recording["messages"] if m.get("type") == "LabelMessage"]
    assert [text for _, text in labels] == [f"t = {s.time:.4g} s: {s.status}" for s in run.steps]
    assert [t for t, _ in labels] == pytest.approx(list(run.times))
    boxes = [m for _, m in recording["messages"] if m.get("type") == "MeshMessage" and m.get("name") == "/frame/bodies/box"]
    assert len(boxes) == len(run.states)


def test_a_long_run_is_exported_at_even_times(run: qs.Trajectory, world: qs.World, tmp_path: Path) -> None:
    """300 states (the six recorded ones repeated over 3 s) are exported as 240 frames, the last state included."""
    pytest.importorskip("viser")
    from quasistatic.viz.timeline import MAX_EXPORT_FRAMES

    count = 300
    times = np.linspace(0.0, 3.0, count)
    states = tuple(dataclasses.replace(run.states[i % 6], time=float(t)) for i, t in enumerate(times))
    steps = tuple(dataclasses.replace(run.steps[i % 6], time=float(t)) for i, t in enumerate(times))
    shown = qs.view(dataclasses.replace(run, states=states, steps=steps), world, port=0)
    try:
        recording = _recording(shown.export_html(tmp_path / "long.html").read_text())
    finally:
        shown.stop()
    labels = [(t, m["props"]["text"]) for t, m in recording["messages"] if m.get("type") == "LabelMessage"]
    assert len(labels) == MAX_EXPORT_FRAMES == 240
    assert labels[0] == (0.0, "t = 0 s: solved") and labels[-1][0] == pytest.approx(3.0) and labels[-1][1] == "t = 3 s: solved"
    assert recording["durationSeconds"] == pytest.approx(3.3)


def test_the_command_exports_a_run_and_needs_its_scene(tmp_path: Path) -> None:
    pytest.importorskip("viser")
    target, refused = tmp_path / "run.html", tmp_path / "refused.html"
    commands = [
        ["view", str(RUN), "--scene", str(TIP), "--export", str(target)],
        ["view", str(RUN), "--export", str(refused)],
        ["view", str(RUN), "--method", "fast"],
        ["view", str(TIP), "--scene", str(TIP), "--export", str(refused)],
    ]
    with ThreadPoolExecutor(max_workers=2) as pool:  # four processes, mostly imports: two at a time
        done, orphan, solved, scene_only = pool.map(
            lambda args: subprocess.run([str(COMMAND), *args], capture_output=True, text=True, timeout=300), commands
        )
    assert done.returncode == 0 and done.stdout.strip() == f"wrote {target}: 6 states, completed", (done.stdout, done.stderr)
    assert _recording(target.read_text())["durationSeconds"] == pytest.approx(1.1)
    lines = orphan.stderr.strip().splitlines()
    assert orphan.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: ") and "give --scene" in lines[0]
    assert solved.returncode == 2 and solved.stderr.startswith("error: --method 'fast': a trajectory is drawn")
    assert scene_only.returncode == 2 and "--scene" in scene_only.stderr and len(scene_only.stderr.strip().splitlines()) == 1
    assert not refused.exists()


# --------------------------------------------------------------------------- in a notebook


def test_a_notebook_shows_the_verdict_the_events_and_the_run_as_a_gif(run: qs.Trajectory) -> None:
    Image = pytest.importorskip("PIL.Image")
    pytest.importorskip("matplotlib")
    page = dataclasses.replace(run, scene_file=str(TIP))._repr_html_()
    assert "<p><b>completed</b>: ran the whole 1 s</p>" in page and "6 states to t = 1 s; every step proven" in page
    rows = re.findall(r"<tr><td>([^<]+)</td><td>([^<]+)</td><td>([^<]+)</td><td>([^<]+)</td></tr>", page)
    event = run.events[0]
    assert rows == [(f"{event.time:.6g}", "mode change", "box / table", "box on table: rolling, separating -&gt; rolling")]
    gif = re.search(r'src="data:image/gif;base64,([^"]+)"', page)
    assert gif, page[:500]
    with Image.open(io.BytesIO(base64.b64decode(gif.group(1)))) as image:
        assert image.format == "GIF" and image.n_frames == len(run.states)


def test_a_notebook_says_why_the_run_is_not_drawn_and_what_is_unproven(run: qs.Trajectory, monkeypatch: pytest.MonkeyPatch) -> None:
    steps = tuple(dataclasses.replace(s, certified=False) if i == 2 else s for i, s in enumerate(run.steps))
    page = dataclasses.replace(run, steps=steps)._repr_html_()  # run on a World built in Python: no scene file
    assert "NOT proven: 1 of 6 steps uncertified" in page and "<img" not in page
    assert "no animation" in page and "names no scene file" in page
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if the figures extra were not installed
    page = dataclasses.replace(run, scene_file=str(TIP))._repr_html_()
    assert "<img" not in page and "pip install &quot;quasistatic[figures]&quot;" in page and "<table>" in page


def test_scene_frames_draw_the_urdf_visual_meshes_and_runs_draw_collision_shapes() -> None:
    """A robot in a single answer is drawn with its URDF's visual meshes; a run's states with its collision shapes (small recordings)."""
    from quasistatic.adapters.robot import installed_model_folders
    from quasistatic.viz.scene3d import ArrowScales, draw_frame

    if not installed_model_folders():
        pytest.skip("example-robot-data is not installed")
    from quasistatic.tools.bench.pipeline import allegro_grasp

    class Recorder:
        """Stands in for viser's scene API: keeps the meshes drawn."""

        def __init__(self) -> None:
            self.meshes: dict[str, tuple[np.ndarray, np.ndarray]] = {}

        def add_mesh_simple(self, name: str, vertices: np.ndarray, faces: np.ndarray, **_: object) -> None:
            self.meshes[name] = (np.asarray(vertices), np.asarray(faces))

        def __getattr__(self, _: str) -> object:
            return lambda *args, **kwargs: None

    world, _ = allegro_grasp()
    scene = world.scene()
    solution = qs.solve(scene)
    recorder = Recorder()
    drawn = draw_frame(recorder, scene, solution.motion, ArrowScales.of(solution, scene, world), world)
    hand = world.robots[0]
    assert len(drawn.robot_links) == len(hand.visuals) == 21
    triangles = sum(len(recorder.meshes[name][1]) for name in drawn.robot_links)
    assert triangles == sum(len(v.faces) for v in hand.visuals if v.faces is not None) > 20_000
