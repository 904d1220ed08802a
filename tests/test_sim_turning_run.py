"""The turning run of the benchmark (``examples/sim/tip_box_planar.yaml``, dt 0.05 s, to its ``unstable`` end)
saved byte for byte as ``main`` saved it before the step was made faster (``tests/data/tip_box_planar_run.jsonl.gz``,
written at commit 2a7070a, NumPy 2 on x86-64; its header's ``scene_file`` made relative): every step is proven
anew there (the box turns, so no step takes the previous answer again), and a faster proof, assembly or
integration must give the same statuses, modes, texts and events, and the same twists, forces and poses. Numbers are
compared to ``SAME_BITS_OR_ROUNDING`` (1e-9 relative), not to the last bit, so that another NumPy or BLAS, which
may round a sum differently, does not fail a run that did not change; on the machine that wrote it they agree to
the last bit. Regenerate the file only for a change that is meant to alter the run, and say why in the commit.
"""

from __future__ import annotations

import gzip
import json
import math
from pathlib import Path
from typing import Any

import quasistatic as qs

ROOT = Path(__file__).resolve().parents[1]
SAVED = ROOT / "tests" / "data" / "tip_box_planar_run.jsonl.gz"
SAME_BITS_OR_ROUNDING = 1e-9  # relative; absolute 1e-12 of the scene's SI units (metres, newtons, m/s) near zero


def test_the_turning_run_is_the_run_saved_before_the_speed_work_byte_for_byte(tmp_path: Path) -> None:
    run = qs.simulate(ROOT / "examples" / "sim" / "tip_box_planar.yaml", duration=10.0, dt=0.05, ambiguous="stop")
    assert run.status == "unstable" and run.certified and len(run.steps) > 100  # the box turns until it falls
    saved = gzip.decompress(SAVED.read_bytes()).decode("utf-8").splitlines()
    written = run.save(tmp_path / "run.jsonl").read_text(encoding="utf-8").splitlines()
    assert len(written) == len(saved) and _header(written[0]) == _header(saved[0])
    for number, (line, saved_line) in enumerate(zip(written[1:], saved[1:], strict=True), 2):
        assert _same(json.loads(line), json.loads(saved_line)), f"line {number} differs:\n{line[:400]}\n{saved_line[:400]}"


def _same(value: Any, saved: Any) -> bool:
    """Equal structure, keys, texts and flags; numbers equal to ``SAME_BITS_OR_ROUNDING``."""
    if isinstance(value, dict):
        return isinstance(saved, dict) and value.keys() == saved.keys() and all(_same(value[k], saved[k]) for k in value)
    if isinstance(value, list):
        return isinstance(saved, list) and len(value) == len(saved) and all(_same(a, b) for a, b in zip(value, saved, strict=True))
    if isinstance(value, float) and not isinstance(saved, bool) and isinstance(saved, (int, float)):
        return math.isclose(value, saved, rel_tol=SAME_BITS_OR_ROUNDING, abs_tol=1e-3 * SAME_BITS_OR_ROUNDING)
    return type(value) is type(saved) and value == saved


def _header(line: str) -> dict[str, object]:
    """The run's first line without ``scene_file`` (where this checkout keeps the example, an absolute path)."""
    header = json.loads(line)
    header.pop("scene_file")
    return header
