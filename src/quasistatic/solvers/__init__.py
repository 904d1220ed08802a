"""Solver backends behind one registry: ``lp``, ``fast``, ``scip``, ``paper``.

Each method has one front-door module here (``lp.py``, ``fast.py``, ``scip.py``,
``paper.py``) taking a :class:`~quasistatic.laws.Problem` and
:class:`Options` and returning a :class:`BackendResult` in scene-relative
units. Their numerics (``numerics/``) and certification helpers
(``certify/``) are private to this package. Imports ``laws`` and ``model``;
never ``check`` (the judge stays independent) nor anything above.
"""

from .compliance import CompliantForces, StepForces, compliant_forces, compliant_step
from .oversize import too_large
from .registry import BACKENDS, Backend, Solver, get_backend
from .result import BackendResult, Options, Range, SearchProgress

__all__ = [
    "BACKENDS",
    "Backend",
    "BackendResult",
    "CompliantForces",
    "Options",
    "Range",
    "SearchProgress",
    "StepForces",
    "Solver",
    "compliant_forces",
    "compliant_step",
    "get_backend",
    "too_large",
]
