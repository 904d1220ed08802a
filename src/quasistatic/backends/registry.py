"""Backends by name. Optional ones are checked without importing them."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import BackendUnavailableError
from ..problem import Problem
from .base import BackendResult, Options

__all__ = ["Backend", "BACKENDS", "get_backend"]

Solver = Callable[[Problem, Options], BackendResult]


@dataclass(frozen=True)
class Backend:
    """A registered solver: where it lives and what it needs."""

    name: str
    module: str
    function: str
    summary: str
    requires: str | None = None  # top-level module that must be importable
    install_hint: str = ""
    frictionless_only: bool = False

    def load(self) -> Solver:
        if self.requires and importlib.util.find_spec(self.requires) is None:
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
            frictionless_only=True,
        ),
        Backend(
            "scip",
            ".scip",
            "solve_certified",
            "certified: SCIP mixed-integer search over every contact mode, complete list of motions",
            requires="pyscipopt",
            install_hint="pip install pyscipopt",
        ),
        Backend(
            "paper",
            ".paper",
            "solve_paper",
            "the paper's minimum-power program (bilinear, SCIP global optimum); one motion, uniqueness not checked",
            requires="pyscipopt",
            install_hint="pip install pyscipopt",
        ),
        Backend(
            "fast",
            ".fast",
            "solve_fast",
            "fast path: Lemke's method on the polyhedral LCP (numba), exact 3-D cones by re-aligned edges; "
            "finds one motion, proves nothing",
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
