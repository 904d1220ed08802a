"""Finished chunks on disk, so that an interrupted sweep restarts where it stopped.

A sweep's chunks live in ``DIRECTORY/KEY/``, one Parquet file per chunk, where
KEY hashes everything that decides the answers: the scene file's data, the
parameters and their values, and the solve options. A restart with the same
inputs finds the same files and skips them; a changed input gets a new key and
recomputes.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from typing import Any

from .params import SweepParam
from .result import SweepPoint, require_pyarrow

__all__ = ["ChunkStore", "sweep_key"]


def sweep_key(data: Mapping[str, Any], folder: str, params: Sequence[SweepParam], options: Mapping[str, Any]) -> str:
    """A short hash of the scene file's data, its folder, the grid and the solve options."""
    content = {
        "data": data,
        "folder": folder,
        "params": [[p.name, p.values.tolist()] for p in params],
        "options": dict(options),
        "version": version("quasistatic"),
    }
    text = json.dumps(content, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class ChunkStore:
    """The Parquet files of one sweep's finished chunks.

    Attributes
    ----------
    folder : Path
        ``DIRECTORY/KEY``: the chunks of this scene, grid and options.
    """

    folder: Path

    def load(self, name: str) -> list[SweepPoint] | None:
        """The points of a finished chunk, or None when it is not on disk (or was cut off while written)."""
        path = self.folder / f"{name}.parquet"
        if not path.exists():
            return None
        import pyarrow.parquet as pq

        try:
            rows = pq.read_table(path).to_pylist()
        except (OSError, ValueError):
            return None  # a half-written file from an interrupted run: computed again
        return [_point(row) for row in rows]

    def save(self, name: str, points: Sequence[SweepPoint]) -> None:
        """Write a finished chunk (to a temporary name first, so a crash never leaves a truncated chunk)."""
        pa = require_pyarrow()
        import pyarrow.parquet as pq

        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.folder / f"{name}.parquet"
        partial = path.with_suffix(".partial")
        pq.write_table(pa.Table.from_pylist([_row(p) for p in points], schema=_schema(pa)), partial)
        os.replace(partial, path)

    def clear(self) -> None:
        """Remove this sweep's chunks (a run without resume starts afresh)."""
        if self.folder.is_dir():
            for path in self.folder.glob("*.parquet"):
                path.unlink()


def _schema(pa: Any) -> Any:
    return pa.schema(
        [
            ("index", pa.int64()),
            ("values", pa.list_(pa.float64())),
            ("refinement", pa.bool_()),
            ("status", pa.string()),
            ("certified", pa.bool_()),
            ("message", pa.string()),
            ("motions", pa.int64()),
            ("bodies", pa.list_(pa.string())),
            ("twists", pa.list_(pa.list_(pa.float64()))),
            ("forces", pa.list_(pa.list_(pa.float64()))),
            ("modes", pa.list_(pa.string())),
            ("seconds", pa.float64()),
        ]
    )


def _row(point: SweepPoint) -> dict[str, Any]:
    return {
        "index": point.index,
        "values": list(point.values),
        "refinement": point.refinement,
        "status": point.status,
        "certified": point.certified,
        "message": point.message,
        "motions": point.motions,
        "bodies": [name for name, _ in point.twists],
        "twists": [list(t) for _, t in point.twists],
        "forces": [list(f) for f in point.forces],
        "modes": list(point.modes),
        "seconds": point.seconds,
    }


def _point(row: Mapping[str, Any]) -> SweepPoint:
    return SweepPoint(
        index=int(row["index"]),
        values=tuple(row["values"]),
        refinement=bool(row["refinement"]),
        status=row["status"],
        certified=bool(row["certified"]),
        message=row["message"],
        motions=int(row["motions"]),
        twists=tuple((name, tuple(t)) for name, t in zip(row["bodies"], row["twists"], strict=True)),
        forces=tuple(tuple(f) for f in row["forces"]),
        modes=tuple(row["modes"]),
        seconds=float(row["seconds"]),
    )
