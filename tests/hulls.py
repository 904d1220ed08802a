"""Test helpers shared by the mode-proof cross-checks: is a twist in the convex hull of a continuum's extremes, and is
a listed motion among another method's list."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from scipy.optimize import nnls


def near_hull(q: np.ndarray, points: tuple[np.ndarray, ...], tol: float) -> bool:
    """Whether ``q`` is within ``tol`` (largest entry) of the convex hull of ``points`` (weights by NNLS)."""
    P = np.column_stack(points)
    weight = 1e6  # the weights' sum held at 1 far more tightly than the distance
    w, _ = nnls(np.vstack([P, weight * np.ones(P.shape[1])]), np.r_[q, weight])
    return bool(np.max(np.abs(P @ w - q)) <= tol)


class Listed(Protocol):
    """A listed motion: a twist, or a continuum given by its extremes (and whether it runs to infinity)."""

    @property
    def q(self) -> np.ndarray: ...

    @property
    def extremes(self) -> tuple[np.ndarray, ...]: ...

    @property
    def unbounded(self) -> bool: ...

    @property
    def continuum(self) -> bool: ...


def covered(motion: Listed, others: Sequence[Listed], tol: float) -> bool:
    """A twist: one of ``others`` has it, or a continuum's extremes hold it; a continuum: one with its extremes."""
    if not motion.continuum:
        return any(
            np.max(np.abs(o.q - motion.q)) <= tol if not o.continuum else bool(o.extremes) and near_hull(motion.q, o.extremes, tol)
            for o in others
        )
    return any(
        o.continuum
        and o.unbounded == motion.unbounded
        and len(o.extremes) == len(motion.extremes)
        and all(any(np.max(np.abs(e - f)) <= tol for f in o.extremes) for e in motion.extremes)
        for o in others
    )
