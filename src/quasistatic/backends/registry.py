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
            "frictionless LP (HiGHS), the paper's velocity/force formulation",
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
    )
}


def get_backend(name: str) -> Backend:
    """A backend by name; raises ValueError naming the known ones."""
    try:
        return BACKENDS[name]
    except KeyError:
        known = ", ".join(["auto", *BACKENDS])
        raise ValueError(f"unknown method {name!r}; known methods: {known}") from None
