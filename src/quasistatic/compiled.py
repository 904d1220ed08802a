"""The compiled extension ``quasistatic._lemke``: Lemke's method in C, for installs without numba.

``pip install .`` builds it with the machine's C compiler (setuptools only: no
numpy headers); it is optional, so an install without a compiler still works
and runs the numpy twin instead. ``HAVE_EXTENSION`` says whether it was built.
:func:`lemke` takes the arguments of the numba kernel
(``solvers/numerics/lemke.py::lemke``), makes them C-contiguous float64, and
returns what the kernel returns; the C code pivots by the kernel's rules.
"""

from __future__ import annotations

import numpy as np

try:
    import quasistatic._lemke as extension
except ImportError:  # built without a C compiler: callers fall back to numpy
    extension = None

__all__ = ["HAVE_EXTENSION", "lemke"]

HAVE_EXTENSION = extension is not None


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
