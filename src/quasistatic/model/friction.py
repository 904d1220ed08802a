"""Friction models: a choice separate from the numerical method that solves them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import SceneError

__all__ = ["FrictionModel", "parse_friction"]

Kind = Literal["exact", "pyramid", "none"]


@dataclass(frozen=True)
class FrictionModel:
    """How the Coulomb cone ``||c_t|| <= mu c_n`` is represented.

    Attributes
    ----------
    kind : {"exact", "pyramid", "none"}
        ``exact``: the circular cone in 3-D, its two edges in 2-D (exact there too).
        ``pyramid``: an inscribed pyramid with ``edges`` edges (3-D only).
        ``none``: every contact frictionless, whatever its ``mu``.
    edges : int
        Number of pyramid edges (only for ``pyramid``).
    """

    kind: Kind = "exact"
    edges: int = 0

    def __str__(self) -> str:
        return f"pyramid:{self.edges}" if self.kind == "pyramid" else self.kind

    def is_polyhedral(self, dimension: int) -> bool:
        """True when the cone is a polyhedron (LP/LCP-representable) in this dimension."""
        return self.kind != "exact" or dimension == 2

    def tangent_directions(self, dimension: int) -> np.ndarray:
        """Unit edge directions in contact-tangent coordinates, shape (K, dimension - 1).

        Only for polyhedral models; the edges span the friction polygon whose
        vertices lie on the exact cone (the pyramid is inscribed).
        """
        if dimension == 2:
            return np.array([[1.0], [-1.0]])
        if self.kind != "pyramid":
            raise ValueError(f"friction model {self} has no edges in 3-D")
        angles = 2.0 * np.pi * np.arange(self.edges) / self.edges
        return np.column_stack([np.cos(angles), np.sin(angles)])


def parse_friction(text: str, field: str = "friction") -> FrictionModel:
    """Parse ``exact``, ``none`` or ``pyramid:K`` (K >= 3)."""
    if not isinstance(text, str):
        raise SceneError(field, text, "expected 'exact', 'none' or 'pyramid:K'")
    value = text.strip().lower()
    if value in ("exact", "none"):
        return FrictionModel(kind=value)  # type: ignore[arg-type]
    if value.startswith("pyramid:"):
        count = value.split(":", 1)[1]
        if count.isdigit() and int(count) >= 3:
            return FrictionModel(kind="pyramid", edges=int(count))
        raise SceneError(field, text, "pyramid needs an integer number of edges K >= 3, e.g. 'pyramid:8'")
    raise SceneError(field, text, "expected 'exact', 'none' or 'pyramid:K'")
