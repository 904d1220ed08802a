"""Optional just-in-time compilation: numba when it is installed, plain Python otherwise.

numba is the optional extra ``fast`` (``pip install quasistatic[fast]``). The
kernels decorated here are ordinary numpy functions; without numba they run
unchanged, only slower. A kernel whose loops numba compiles best but plain
Python runs slowly names a whole-array twin (``@njit(python=twin)``): the same
arithmetic in numpy calls, used when numba is missing (measured 3-7x slower
than the loops once compiled, 5-50x faster than them as plain Python).
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from typing import TypeVar, cast, overload

__all__ = ["HAVE_NUMBA", "njit"]

F = TypeVar("F", bound=Callable[..., object])

HAVE_NUMBA = importlib.util.find_spec("numba") is not None


@overload
def njit(function: F) -> F: ...
@overload
def njit(*, python: F) -> Callable[[F], F]: ...


def njit(function: F | None = None, *, python: F | None = None) -> F | Callable[[F], F]:
    """``numba.njit(cache=True)(function)`` when numba is importable; else ``python`` if given, else ``function`` itself.

    The compiled dispatcher keeps the original as ``.py_func``; compilation
    happens on the first call (and is cached on disk next to the source).
    ``python``: the kernel's whole-array twin for plain Python (same inputs, same results to round-off).
    """

    def decorate(kernel: F) -> F:
        if not HAVE_NUMBA:
            return kernel if python is None else python
        import numba

        return cast(F, numba.njit(cache=True)(kernel))

    return decorate if function is None else decorate(function)
