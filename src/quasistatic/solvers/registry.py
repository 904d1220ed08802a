"""Solver backends by name, with what each can do. Optional ones are checked without importing them.

A new method is one module in this package with one front-door function
``(Problem, Options) -> BackendResult``, and one entry in :data:`BACKENDS`.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

from ..errors import BackendUnavailableError
from ..laws import Problem
from .result import BackendResult, Options

__all__ = ["Backend", "BACKENDS", "Solver", "get_backend"]

Solver = Callable[[Problem, Options], BackendResult]


@dataclass(frozen=True)
class Backend:
    """A registered solver: where it lives, what it needs and what it can do.

    Attributes
    ----------
    name : str
        The method's name, as ``solve(method=...)`` takes it.
    module, function : str
        The front door: ``function`` in the module ``module`` (relative to this package).
    summary : str
        One line for people.
    frictional : bool
        Handles contacts with ``mu > 0`` (else every contact must be frictionless).
    certifies : bool
        Its ``solved`` is proven unique, its ``jammed``/``unstable`` proven (for ``scip``
        with exact 3-D cones, ``solved`` is unique for the searched pyramid only:
        each Solution's ``certified`` says which).
    lists_all_motions : bool
        Reports every motion, a continuum as one entry (``all_solutions`` may be asked of it).
    prescribes_modes : bool
        Takes prescribed contact modes (the mode-specified solve).
    requires : str or None
        Top-level module that must be importable (an optional dependency).
    install_hint : str
        The command that installs what ``requires`` names.
    """

    name: str
    module: str
    function: str
    summary: str
    frictional: bool = True
    certifies: bool = True
    lists_all_motions: bool = False
    prescribes_modes: bool = False
    requires: str | None = None
    install_hint: str = ""

    @property
    def available(self) -> bool:
        """Whether its optional dependency is installed (checked without importing it)."""
        return self.requires is None or importlib.util.find_spec(self.requires) is not None

    @cached_property
    def solver(self) -> Solver:
        """The front-door function, imported on first use.

        Raises
        ------
        BackendUnavailableError
            With the install hint, when ``requires`` is missing.
        """
        if not self.available:
            raise BackendUnavailableError(self.name, self.install_hint)
        module = importlib.import_module(self.module, package=__package__)
        solver: Solver = getattr(module, self.function)
        return solver


BACKENDS: dict[str, Backend] = {
    b.name: b
    for b in (
        Backend(
            "lp",
            ".lp",
            "solve_frictionless",
            "frictionless LP, the paper's velocity/force formulation (Lemke's method on small problems, HiGHS otherwise)",
            frictional=False,
            lists_all_motions=True,
        ),
        Backend(
            "scip",
            ".scip",
            "solve_certified",
            "certified: SCIP mixed-integer search over every contact mode, complete list of motions",
            lists_all_motions=True,
            prescribes_modes=True,
            requires="pyscipopt",
            install_hint="pip install pyscipopt",
        ),
        Backend(
            "certified",
            ".certified",
            "solve_cheap_certified",
            "certified, as scip, cheap certificates first: Lemke's motion proven unique by kinematics, "
            "else the SCIP search started from it (the default for frictional scenes)",
            lists_all_motions=True,
            prescribes_modes=True,
            requires="pyscipopt",
            install_hint="pip install pyscipopt",
        ),
        Backend(
            "paper",
            ".paper",
            "solve_paper",
            "the paper's minimum-power program (bilinear, SCIP global optimum); one motion, uniqueness not checked",
            certifies=False,
            requires="pyscipopt",
            install_hint="pip install pyscipopt",
        ),
        Backend(
            "fast",
            ".fast",
            "solve_fast",
            "fast path: Lemke's method on the polyhedral LCP (numba), exact 3-D cones by re-aligned edges, "
            "a complete method where Lemke ends on a ray; finds one motion, proves only that none exists",
            certifies=False,
        ),
    )
}


def get_backend(name: str) -> Backend:
    """A backend by name; raises ValueError naming the known ones."""
    try:
        return BACKENDS[name]
    except KeyError:
        known = ", ".join(["auto", *BACKENDS])
        raise ValueError(f"unknown method {name!r}; known methods: {known}") from None
