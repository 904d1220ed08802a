"""The last certified answer, taken again for laws equal to its own bit for bit (a simulation's next step).

A backend's answer is a function of the scene-relative laws alone (``J``, ``b``, ``g``, ``mu``, the friction
model, the contact frames, the scales, which bodies and contacts they belong to) and of the options that shape a
search. When a step's laws are the previous step's to the last bit, as they are while a pushed body translates
(the scene-relative origin moves with the contacts), the proof that certified the previous answer proves this
one: :class:`Reuse` hands that answer back instead of proving it again. Only certified answers whose list of motions is complete
are kept (``solved``, and ``ambiguous`` listed in full). The caller still converts and audits every motion on
its own scene, so the reused answer is judged anew.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..laws import Problem
from .result import BackendResult, Options

__all__ = ["Reuse", "REUSED_NOTE"]

REUSED_NOTE = "the previous solve's certified answer: its laws equal these bit for bit"


@dataclass
class Reuse:
    """A one-entry memory of certified answers: the last one kept and the exact laws and options it answered.

    ``hits`` counts the answers taken again (for the benchmark and tests).
    """

    key: tuple[Any, ...] | None = None
    result: BackendResult | None = None
    hits: int = 0

    def recalled(self, method: str, problem: Problem, options: Options) -> tuple[BackendResult | None, tuple[Any, ...]]:
        """The kept answer when ``problem`` and ``options`` equal those it answered (else None), and their key, for
        :meth:`keep` after a solve."""
        key = _key(method, problem, options)
        if self.result is None or self.key != key:
            return None, key
        self.hits += 1
        return self.result.with_notes(reused=REUSED_NOTE), key  # noted here, not when kept: most kept answers never return

    def keep(self, key: tuple[Any, ...], result: BackendResult) -> None:
        """Keep ``result`` for the laws of ``key`` (from :meth:`recalled`) when it is certified and complete; anything
        else clears the memory."""
        if result.certified and result.search_complete and result.status in ("solved", "ambiguous"):
            self.key, self.result = key, result
        else:
            self.key, self.result = None, None


def _key(method: str, problem: Problem, options: Options) -> tuple[Any, ...]:
    """Everything a backend's answer depends on: the method, the options that shape a search, the friction model,
    the scales (a certificate's physical units; not the origin, which assembly takes out), the names the rows
    belong to, and the laws' arrays to the last bit (their shapes included)."""
    scene, scales = problem.scene, problem.scales
    return (
        method,
        options.max_solutions,
        options.modes,
        str(problem.friction),
        (scales.length, scales.force, scales.velocity),
        tuple(body.name for body in scene.bodies),
        tuple((contact.body, contact.other) for contact in scene.contacts),
        problem.J.shape,
        problem.frames.tobytes(),
        problem.J.tobytes(),
        problem.b.tobytes(),
        problem.g.tobytes(),
        problem.mu.tobytes(),
    )
