"""SciPy's optimizers, imported on their first call.

Importing ``scipy.optimize`` costs a process 0.2-0.6 s of CPU, and most solves (and every command's option
checks) never call it; the solvers call these instead of importing it at module level.
"""

from __future__ import annotations

import functools
from types import ModuleType
from typing import Any

import numpy as np

__all__ = ["nnls", "least_squares", "minimize"]


@functools.cache
def _scipy_optimize() -> ModuleType:
    import scipy.optimize

    return scipy.optimize


def nnls(A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """``scipy.optimize.nnls``: the non-negative ``x`` least-squares closest to ``A x = b``, and the residual's norm."""
    x, residual = _scipy_optimize().nnls(A, b)
    return x, float(residual)


def least_squares(*args: Any, **kwargs: Any) -> Any:
    """``scipy.optimize.least_squares``, with its arguments and result."""
    return _scipy_optimize().least_squares(*args, **kwargs)


def minimize(*args: Any, **kwargs: Any) -> Any:
    """``scipy.optimize.minimize``, with its arguments and result."""
    return _scipy_optimize().minimize(*args, **kwargs)
