"""`quasistatic animate`: a simulated run drawn frame by frame, checked as a person would see it."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.viz import MODE_COLOURS

pytest.importorskip("coal")
pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")

TIP = Path(__file__).resolve().parents[1] / "examples" / "sim" / "tip_box.yaml"


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-c", "from quasistatic.cli import main; main()", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def run_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run") / "tip.npz"
    result = run_cli("simulate", str(TIP), "--duration", "1.0", "--dt", "0.25", "--out", str(out))
    assert result.returncode == 0, result.stderr
    return out


def colour_present(frame: np.ndarray, hex_colour: str, tolerance: int = 40) -> bool:
    target = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)])
    return bool(np.any(np.all(np.abs(frame.astype(int) - target) <= tolerance, axis=-1)))


def test_animate_writes_a_gif_with_a_frame_per_state_showing_the_modes(run_file: Path, tmp_path: Path) -> None:
    gif = tmp_path / "tip.gif"
    result = run_cli("animate", str(run_file), "-o", str(gif), "--view", "xz")
    assert result.returncode == 0, result.stderr
    states = len(qs.Trajectory.load(run_file).states)
    with Image.open(gif) as image:
        assert image.n_frames == states
        image.seek(image.n_frames - 1)
        last = np.asarray(image.convert("RGB"))
        image.seek(0)
        first = np.asarray(image.convert("RGB"))
    assert last.std() > 10  # not blank
    # The box pivots on the table (rolling) while the fingertip slides up its face.
    assert colour_present(last, MODE_COLOURS["rolling"]) and colour_present(last, MODE_COLOURS["sliding"])
    assert not np.array_equal(first, last)  # the box has moved


def test_animate_needs_the_scene_and_says_so(run_file: Path, tmp_path: Path) -> None:
    trajectory = qs.Trajectory.load(run_file)
    orphan = tmp_path / "orphan.npz"
    qs.Trajectory(trajectory.states, trajectory.steps, trajectory.status, trajectory.message).save(orphan)
    result = run_cli("animate", str(orphan), "-o", str(tmp_path / "x.gif"))
    assert result.returncode == 2 and result.stderr.startswith("error:") and "--scene" in result.stderr
    wrong = Path(__file__).resolve().parents[1] / "examples" / "robots" / "planar_hand.yaml"
    result = run_cli("animate", str(run_file), "-o", str(tmp_path / "x.gif"), "--scene", str(wrong))
    assert result.returncode == 2 and "not the scene it was run on" in result.stderr


@pytest.mark.parametrize(("args", "words"), [(["-o", "x.avi"], ".gif or .mp4"), (["-o", "x.gif", "--view", "top"], "--view")])
def test_animate_bad_options_are_one_error_line(run_file: Path, tmp_path: Path, args: list[str], words: str) -> None:
    result = run_cli("animate", str(run_file), *[str(tmp_path / a) if a.startswith("x.") else a for a in args])
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0]


def test_mp4_without_ffmpeg_is_one_clear_line(run_file: Path, tmp_path: Path) -> None:
    if shutil.which("ffmpeg") is not None:
        pytest.skip("ffmpeg is installed: the .mp4 is written instead")
    result = run_cli("animate", str(run_file), "-o", str(tmp_path / "x.mp4"))
    assert result.returncode == 2 and "ffmpeg" in result.stderr and len(result.stderr.strip().splitlines()) == 1
