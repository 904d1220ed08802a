"""The compiled extension ``quasistatic._lemke``: Lemke's method and the fixed-mode laws in C, for installs without numba.

``pip install .`` builds it with the machine's C compiler (setuptools only: no
numpy headers); it is optional, so an install without a compiler still works
and runs the numpy twin instead. ``HAVE_EXTENSION`` says whether it was built.
:func:`lemke` and :func:`fixed_mode_system` take the arguments of the numba
kernels ``solvers/numerics/lemke.py::lemke`` and ``laws/fixed_modes.py::system``,
make them C-contiguous, and return what the kernels return; the C code makes the
kernels' choices in the kernels' order of arithmetic. ``LEMKE_ADDRESS`` is where the
same Lemke's method starts as a plain C function on raw pointers, which the numba
install's kernels call (``solvers/numerics/lemke.py``).
"""

from __future__ import annotations

import importlib
import warnings
from typing import Any, NamedTuple

import numpy as np

API_VERSION = 2  # the _lemke.c these wrappers call (its module attribute api_version)

try:  # by name: a typed import would make mypy read the whole package from this leaf
    extension: Any = importlib.import_module("quasistatic._lemke")
except ImportError:  # built without a C compiler: callers fall back to numpy
    extension = None
if extension is not None and getattr(extension, "api_version", 1) != API_VERSION:
    # An editable install keeps the .so of an older _lemke.c until it is built again: run without it, and say so.
    message = "quasistatic._lemke was built from an older source; run `pip install -e .` again to rebuild it"
    warnings.warn(message, RuntimeWarning, stacklevel=1)
    extension = None

__all__ = ["HAVE_EXTENSION", "LEMKE_ADDRESS", "lemke", "fixed_mode_system", "solve_split_lcp", "NewtonTolerances"]

HAVE_EXTENSION = extension is not None
# quasistatic_lemke(n, M, q, d, max_pivots, tol, z, basis, pivots, work, rows) -> status; 0 when not built
LEMKE_ADDRESS: int = extension.lemke_address if HAVE_EXTENSION else 0


def lemke(M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Lemke's method in C: ``(status, z, pivots, basis)`` as ``solvers/numerics/lemke.py::lemke`` returns them.

    Parameters
    ----------
    M : (n, n) float array
    q, d : (n,) float arrays
    max_pivots : int
    tol : float
        Pivot tolerance and tie width, as the kernel's [-].

    Raises
    ------
    ValueError
        When the shapes disagree (``M`` not ``(n, n)`` or ``d`` not ``(n,)``).
    """
    n = q.shape[0]
    z = np.empty(n)
    basis = np.empty(n, np.int64)
    status, pivots = extension.lemke(
        np.ascontiguousarray(M, np.float64),
        np.ascontiguousarray(q, np.float64),
        np.ascontiguousarray(d, np.float64),
        max_pivots,
        tol,
        z,
        basis,
    )
    return status, z, pivots, basis


def fixed_mode_system(
    J: np.ndarray, b: np.ndarray, mu: np.ndarray, g: np.ndarray, x: np.ndarray, kind: np.ndarray, column: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fixed-mode laws in C: residual (N,), Jacobian (N, N) and forces (m, d), as ``laws/fixed_modes.py::system``.

    ``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,), ``x`` (N,), ``kind`` and
    ``column`` (m,) int as there; ``n`` must be ``J.shape[2]``.

    Raises
    ------
    ValueError
        When the shapes disagree, or a contact's kind or column would put its unknowns outside ``x``.
    """
    if J.ndim != 3 or J.shape[2] != n:
        raise ValueError(f"J must have shape (m, d, n) with n = {n}, not {J.shape}")
    size = x.shape[0]
    residual, jacobian, forces = np.empty(size), np.empty((size, size)), np.empty(J.shape[:2])
    extension.fixed_mode_system(
        *(np.ascontiguousarray(a, np.float64) for a in (J, b, mu, g, x)),
        np.ascontiguousarray(kind, np.int64),
        np.ascontiguousarray(column, np.int64),
        residual,
        jacobian,
        forces,
    )
    return residual, jacobian, forces


class NewtonTolerances(NamedTuple):
    """The tolerances of the fast path's Newton iterations (``quasistatic.tolerances``' values, passed in by the caller)."""

    cone_roundoff: float
    damping: float
    stop: float


def solve_split_lcp(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    exact: bool,
    max_realignments: int,
    dissipation_tol: float,
    mode_tol: float,
    pivot_tol: float,
    feasibility_tol: float,
    pivots_per_row: int,
    newton: NewtonTolerances,
) -> tuple[int, int, np.ndarray, np.ndarray, int, int]:
    """The fast path's kernel in C: ``(status, stage, q, c, pivots, realignments)`` as ``solvers/numerics/lcp.py::solve_split_lcp``.

    Arguments as there (``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,), ``frictional`` (f,) int,
    ``base`` (K,)), and the Newton iterations' tolerances.

    Raises
    ------
    ValueError
        When the shapes disagree, a frictional index is not a contact's, or ``exact`` is asked of 2-D contacts.
    """
    if J.ndim != 3:
        raise ValueError(f"J must have shape (m, d, n), not {J.shape}")
    m, d, n = J.shape
    q, c = np.empty(n), np.empty((m, d))
    status, stage, pivots, realignments = extension.solve_split_lcp(
        *(np.ascontiguousarray(a, np.float64) for a in (J, b, mu, g)),
        np.ascontiguousarray(frictional, np.int64),
        np.ascontiguousarray(base, np.float64),
        exact,
        max_realignments,
        dissipation_tol,
        mode_tol,
        pivot_tol,
        feasibility_tol,
        pivots_per_row,
        *newton,
        q,
        c,
    )
    return status, stage, q, c, pivots, realignments
