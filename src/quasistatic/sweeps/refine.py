"""Boundaries between phases, located by bisection between grid neighbours whose phases differ."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .result import PhaseKind, SweepPoint, SweepResult

__all__ = ["Interval", "boundary_intervals", "narrowed"]


@dataclass(frozen=True)
class Interval:
    """Two points that differ in one parameter and in phase: a boundary lies between them.

    Attributes
    ----------
    low, high : tuple of float
        The two points' parameter values.
    low_phase, high_phase : str
        Their phases.
    """

    low: tuple[float, ...]
    high: tuple[float, ...]
    low_phase: str
    high_phase: str

    def midpoint(self) -> tuple[float, ...]:
        return tuple((a + b) / 2 for a, b in zip(self.low, self.high, strict=True))


def boundary_intervals(result: SweepResult, phase: PhaseKind) -> list[Interval]:
    """Every pair of grid neighbours (along each parameter) whose phases differ, in grid order."""
    grid = np.empty(len(result.grid), dtype=object)
    grid[:] = list(result.grid)
    points = grid.reshape(result.shape)
    intervals = []
    for axis in range(points.ndim):
        low = np.moveaxis(points, axis, 0)[:-1].ravel()
        high = np.moveaxis(points, axis, 0)[1:].ravel()
        for a, b in zip(low, high, strict=True):
            if a.phase(phase) != b.phase(phase):
                intervals.append(Interval(a.values, b.values, a.phase(phase), b.phase(phase)))
    return intervals


def narrowed(intervals: Sequence[Interval], middles: Sequence[SweepPoint], phase: PhaseKind) -> list[Interval]:
    """The halves that still hold a change of phase once each interval's midpoint is solved (both halves when
    the midpoint has a third phase)."""
    out = []
    for interval, middle in zip(intervals, middles, strict=True):
        label = middle.phase(phase)
        if label != interval.low_phase:
            out.append(Interval(interval.low, middle.values, interval.low_phase, label))
        if label != interval.high_phase:
            out.append(Interval(middle.values, interval.high, label, interval.high_phase))
    return out
