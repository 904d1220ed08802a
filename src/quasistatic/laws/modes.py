"""Contact modes at a twist: which contacts roll, slide or separate."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..model import FloatArray
from ..solution import Mode
from ..tolerances import MODE_SPEED
from .assemble import Problem

__all__ = ["contact_modes", "slips", "ModeMasks"]


def slips(problem: Problem, q: FloatArray) -> FloatArray:
    """Tangential relative velocities (m, d - 1) at the scene-relative twist ``q``."""
    return np.einsum("mtn,n->mt", problem.Jt, q) - problem.bt


def contact_modes(problem: Problem, q: FloatArray) -> tuple[Mode, ...]:
    """Each contact's mode at the scene-relative twist ``q`` (the same thresholds as the report)."""
    modes: list[Mode] = []
    for u_i in problem.velocities(q):
        if u_i[-1] > MODE_SPEED:
            modes.append("separating")
        elif np.linalg.norm(u_i[:-1]) > MODE_SPEED:
            modes.append("sliding")
        else:
            modes.append("rolling")
    return tuple(modes)


@dataclass(frozen=True)
class ModeMasks:
    """Which contacts are closed, rolling and sliding under given modes, (m,) booleans each.

    A frictionless contact carries only a normal force and may slip freely:
    it is closed unless separating, and neither rolling nor sliding.
    """

    closed: npt.NDArray[np.bool_]
    rolling: npt.NDArray[np.bool_]
    sliding: npt.NDArray[np.bool_]

    @classmethod
    def of(cls, problem: Problem, modes: tuple[Mode, ...] | npt.NDArray[np.object_]) -> ModeMasks:
        names = np.array(modes, dtype=object)
        frictional = problem.mu > 0
        return cls(names != "separating", (names == "rolling") & frictional, (names == "sliding") & frictional)
