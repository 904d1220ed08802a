"""A test helper shared by the mode-proof cross-checks: is a twist in the convex hull of a continuum's extremes."""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls


def near_hull(q: np.ndarray, points: tuple[np.ndarray, ...], tol: float) -> bool:
    """Whether ``q`` is within ``tol`` (largest entry) of the convex hull of ``points`` (weights by NNLS)."""
    P = np.column_stack(points)
    weight = 1e6  # the weights' sum held at 1 far more tightly than the distance
    w, _ = nnls(np.vstack([P, weight * np.ones(P.shape[1])]), np.r_[q, weight])
    return bool(np.max(np.abs(P @ w - q)) <= tol)
