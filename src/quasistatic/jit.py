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
from typing import Any, TypeVar, cast, overload

__all__ = ["HAVE_NUMBA", "njit", "c_function", "cfunc_address"]

F = TypeVar("F", bound=Callable[..., object])

HAVE_NUMBA = importlib.util.find_spec("numba") is not None


@overload
def njit(function: F) -> F: ...
@overload
def njit(*, python: F | None) -> Callable[[F], F]: ...


def njit(function: F | None = None, *, python: F | None = None) -> F | Callable[[F], F]:
    """``numba.njit(cache=True)(function)`` when numba is importable; else ``python`` if given, else ``function`` itself.

    The compiled dispatcher keeps the original as ``.py_func``; compilation
    happens on the first call (and is cached on disk next to the source).
    ``python``: the kernel's whole-array (or compiled) twin for plain Python (same inputs, same results to round-off);
    ``None``: the kernel itself.
    """

    def decorate(kernel: F) -> F:
        if not HAVE_NUMBA:
            return kernel if python is None else python
        import numba

        return cast(F, numba.njit(cache=True)(kernel))

    return decorate if function is None else decorate(function)


def c_function(symbol: str, signature: str, address: int) -> Any:
    """The C function at ``address`` as kernels call it, by the name ``symbol`` (numba installed only).

    ``signature``: numba's, e.g. ``"int64(int64, CPointer(float64))"``; a kernel passes an
    array as ``a.ctypes``. Kernels call the function by name, not by address as with a ctypes
    function, so numba can cache them on disk: the name is bound to this process's address
    here, which must happen before any kernel that calls it is compiled or loaded (an unbound
    name crashes the process), so a module calls this at import, before its kernels.
    """
    import llvmlite.binding
    import numba
    from numba.core import sigutils

    llvmlite.binding.add_symbol(symbol, address)
    arguments, result = sigutils.normalize_signature(signature)
    return numba.types.ExternalFunction(symbol, result(*arguments))


def cfunc_address(signature: str, function: Callable[..., object]) -> int:
    """The address of ``function`` compiled by numba as a C function of ``signature`` (cached on disk like the kernels)."""
    import numba

    compiled = numba.cfunc(signature, cache=True)(function)  # compiled now: the signature is given
    return cast(int, compiled.address)
