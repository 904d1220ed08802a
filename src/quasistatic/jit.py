"""Optional just-in-time compilation: numba when it is installed, plain Python otherwise.

numba is the optional extra ``fast`` (``pip install quasistatic[fast]``). The
kernels decorated here are ordinary numpy functions; without numba they run
unchanged, only slower.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from typing import TypeVar, cast

__all__ = ["HAVE_NUMBA", "njit"]

F = TypeVar("F", bound=Callable[..., object])

HAVE_NUMBA = importlib.util.find_spec("numba") is not None


def njit(function: F) -> F:
    """``numba.njit(cache=True)(function)`` when numba is importable, else ``function`` itself.

    The compiled dispatcher keeps the original as ``.py_func``; compilation
    happens on the first call (and is cached on disk next to the source).
    """
    if not HAVE_NUMBA:
        return function
    import numba

    return cast(F, numba.njit(cache=True)(function))
