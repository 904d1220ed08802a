"""What every solver backend takes (:class:`Options`) and returns (:class:`BackendResult`)."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any

from ..laws import RawMotion
from ..solution import Certificate, Diagnosis, Mode, Status

__all__ = ["Options", "BackendResult", "Range"]

Range = tuple[float, float | None]
"""A value's range ``(lo, hi)``; ``hi`` None when unbounded."""


@dataclass(frozen=True)
class Options:
    """Solver options shared by all backends.

    Attributes
    ----------
    max_solutions : int
        Most distinct motions listed for ``ambiguous``.
    modes : tuple of mode names or None, optional
        Prescribed contact modes (None entries are free): the mode-specified solve.
    time_limit : float
        Seconds a backend's whole solve may take (every search it runs
        together) before it reports ``failed``.
    started : float or None
        ``time.monotonic()`` when the backend started its clock
        (:meth:`start_clock`); None before.
    """

    max_solutions: int = 16
    modes: tuple[Mode | None, ...] | None = None
    time_limit: float = 60.0
    started: float | None = field(default=None, compare=False)

    def start_clock(self) -> Options:
        """These options with the time limit counting from now, unless it already runs (a backend calls it on entry).

        A backend that calls a helper (the exact-cone search calling the paper's
        program) passes its running clock on: the time limit is for the whole solve.
        """
        return self if self.started is not None else dataclasses.replace(self, started=time.monotonic())

    def remaining(self) -> float:
        """Seconds left of ``time_limit`` [s] (negative once it has passed; all of it before the clock starts)."""
        return self.time_limit if self.started is None else self.time_limit - (time.monotonic() - self.started)


@dataclass(frozen=True)
class BackendResult:
    """A backend's verdict in scene-relative units.

    Attributes
    ----------
    status : Status
    message : str
        One sentence a person can act on.
    motions : tuple of RawMotion
        One motion for ``solved``, every distinct one for ``ambiguous``, none otherwise
        (a ``failed`` answer may attach the motion it could not certify). A motion whose
        forces are indeterminate carries its normal-force ranges.
    certified : bool
        True when the verdict is proven: ``solved`` unique, ``ambiguous`` with every listed
        motion a motion, ``jammed`` and ``unstable`` with a certificate.
    diagnosis : Diagnosis or None
        Why no motion exists (``jammed``/``unstable``), as a value to test (never the message text).
    certificate : Certificate or None
        The proof behind the verdict, when there is one to show.
    search_complete : bool or None
        For a search over motions: whether the list is complete.
    notes : tuple of (name, value) pairs
        Solver-specific remarks for people (pivots, stages); no logic may depend on them.
    """

    status: Status
    message: str
    motions: tuple[RawMotion, ...] = ()
    certified: bool = True
    diagnosis: Diagnosis | None = None
    certificate: Certificate | None = None
    search_complete: bool | None = None
    notes: tuple[tuple[str, Any], ...] = ()

    def with_notes(self, **notes: Any) -> BackendResult:
        """The same result with more notes."""
        return dataclasses.replace(self, notes=tuple({**dict(self.notes), **notes}.items()))
