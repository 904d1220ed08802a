"""The turning run of the benchmark (``examples/sim/tip_box_planar.yaml``, dt 0.05 s, to its ``unstable`` end)
saved byte for byte as ``main`` saved it before the step was made faster (``tests/data/tip_box_planar_run.jsonl.gz``,
written at commit 2a7070a, NumPy 2 on x86-64; its header's ``scene_file`` made relative): every step is proven
anew there (the box turns, so no step takes the previous answer again), and a faster proof, assembly or
integration must give the same statuses, modes, twists, forces, poses and events to the last bit. Regenerate the
file only for a change that is meant to alter the run, and say why in the commit.
"""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import quasistatic as qs

ROOT = Path(__file__).resolve().parents[1]
SAVED = ROOT / "tests" / "data" / "tip_box_planar_run.jsonl.gz"


def test_the_turning_run_is_the_run_saved_before_the_speed_work_byte_for_byte(tmp_path: Path) -> None:
    run = qs.simulate(ROOT / "examples" / "sim" / "tip_box_planar.yaml", duration=10.0, dt=0.05, ambiguous="stop")
    assert run.status == "unstable" and run.certified and len(run.steps) > 100  # the box turns until it falls
    saved = gzip.decompress(SAVED.read_bytes()).decode("utf-8").splitlines()
    written = run.save(tmp_path / "run.jsonl").read_text(encoding="utf-8").splitlines()
    assert _header(written[0]) == _header(saved[0])
    assert written[1:] == saved[1:]  # every state and step, as written


def _header(line: str) -> dict[str, object]:
    """The run's first line without ``scene_file`` (where this checkout keeps the example, an absolute path)."""
    header = json.loads(line)
    header.pop("scene_file")
    return header
