"""What C libraries print: kept off the user's terminal, and kept for the error message when they fail.

SCIP prints its internal errors (``[solve.c:4216] ERROR: ...``) and urdfdom its
parse errors straight to file descriptor 2, where Python's ``sys.stderr``
redirection cannot see them. :func:`captured_stderr` points descriptor 2 at a
temporary file while the library runs, so a successful answer comes without
noise and a failure can quote the library's own words.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from typing import IO

__all__ = ["captured_stderr", "first_lines"]

_KEPT_BYTES = 4096  # of the captured text: enough for the first error lines


@contextlib.contextmanager
def captured_stderr() -> Iterator[Callable[[], str]]:
    """Redirect file descriptor 2 to a temporary file for the block; yields a function returning what was written."""
    sys.stderr.flush()
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(2)
        os.dup2(sink.fileno(), 2)
        try:
            yield lambda: _read_back(sink)
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)


def _read_back(sink: IO[bytes]) -> str:
    sink.flush()
    sink.seek(0)
    return sink.read(_KEPT_BYTES).decode("utf-8", "replace")


def first_lines(captured: str, count: int = 2) -> str:
    """The first ``count`` non-empty lines a library printed, joined by '; ' ('Error:' prefixes and source locations dropped)."""
    lines = [line.strip().removeprefix("Error:").strip() for line in captured.splitlines() if line.strip()]
    kept = [line for line in lines if not line.startswith("at line")]
    return "; ".join(kept[:count])
