"""What every solver backend takes (:class:`Options`) and returns (:class:`BackendResult`)."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..laws import RawMotion
from ..solution import Certificate, Diagnosis, Mode, Status

__all__ = ["Options", "BackendResult", "Range", "SearchProgress", "force_claim"]

Range = tuple[float, float | None]
"""A value's range ``(lo, hi)``; ``hi`` None when unbounded."""


@dataclass(frozen=True)
class SearchProgress:
    """How far a certified search has got: motions found, branch-and-bound nodes, seconds since it started."""

    motions: int
    nodes: int
    seconds: float


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
    progress : callable or None
        Called with a :class:`SearchProgress` after each step of a long search (for a status line).
    """

    max_solutions: int = 16
    modes: tuple[Mode | None, ...] | None = None
    time_limit: float = 60.0
    started: float | None = field(default=None, compare=False)
    progress: Callable[[SearchProgress], None] | None = field(default=None, compare=False)

    def start_clock(self) -> Options:
        """These options with the time limit counting from now, unless it already runs (a backend calls it on entry).

        A backend that calls a helper (the exact-cone search calling the paper's
        program) passes its running clock on: the time limit is for the whole solve.
        """
        return self if self.started is not None else dataclasses.replace(self, started=time.monotonic())

    def report(self, motions: int, nodes: int) -> None:
        """Tell the ``progress`` callback, if any, how far the search has got."""
        if self.progress is not None:
            elapsed = 0.0 if self.started is None else time.monotonic() - self.started
            self.progress(SearchProgress(motions, nodes, elapsed))

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
    claims_forces : bool
        The message goes on with what is known of the first motion's forces (:func:`force_claim`),
        decided only when it is read (:meth:`full_message`; ``solve`` defers it to ``Solution.message``),
        then with ``after_claim``.
    after_claim : str
        What the message says after that claim (the exact-cone proof of a refined motion).
    """

    status: Status
    message: str
    motions: tuple[RawMotion, ...] = ()
    certified: bool = True
    diagnosis: Diagnosis | None = None
    certificate: Certificate | None = None
    search_complete: bool | None = None
    notes: tuple[tuple[str, Any], ...] = ()
    claims_forces: bool = False
    after_claim: str = ""

    def with_notes(self, **notes: Any) -> BackendResult:
        """The same result with more notes."""
        return dataclasses.replace(self, notes=tuple({**dict(self.notes), **notes}.items()))

    def full_message(self) -> str:
        """The message with its claim about the forces, decided now when :attr:`claims_forces`."""
        if not self.claims_forces:
            return self.message + self.after_claim
        return self.message + force_claim(bool(self.motions) and self.motions[0].forces_indeterminate) + self.after_claim


def force_claim(indeterminate: bool) -> str:
    """What a solved motion's message says of its forces: every component of every contact force, friction
    included, is unique, or not."""
    return "; the contact forces are indeterminate" if indeterminate else " with unique contact forces"
