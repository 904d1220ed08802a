"""Which contacts' friction wedges a jam: the explanation a ``wedged`` answer owes its reader.

A ``kinematic`` jam names its blocking contacts through its Farkas multipliers. A ``wedged`` one
has no such vector: the parts could rest, and friction holds them against the commanded motion.
What a person can act on is where that friction is: a set of contacts whose friction alone wedges
the parts (every other contact made frictionless, the answer is still a proven jam), none of which
can be spared (made frictionless too, the answer is no longer a jam: proven for each). A deletion
filter finds one such set: each frictional contact in turn loses its friction and keeps it lost
while the jam stays; each contact kept is then checked once more against the final set.

It re-solves the scene, once per frictional contact and once per contact kept, so it is not part of
``solve``: the command line runs it for the answer it prints, and a simulation for the jam it ends on.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence

from .model import Scene
from .solution import Diagnosis, Solution
from .solve import solve

__all__ = ["wedging_friction", "with_wedging_friction"]


def wedging_friction(scene: Scene, time_limit: float = 60.0) -> tuple[int, ...] | None:
    """Indices of contacts whose friction alone wedges ``scene`` and of which none can be spared; None when ``scene``
    is not a proven wedged jam, or a re-solve could not decide within ``time_limit`` seconds in all."""
    deadline = time.monotonic() + time_limit
    if _jammed(scene, (), deadline) is not True:
        return None
    frictional = [i for i, c in enumerate(scene.contacts) if c.mu > 0.0]
    spared: list[int] = []  # friction taken away, and still jammed
    for contact in frictional:
        verdict = _jammed(scene, [*spared, contact], deadline)
        if verdict is None:
            return None
        if verdict:
            spared.append(contact)
    kept = [i for i in frictional if i not in spared]
    for contact in kept:  # none of the final set can be spared: checked against the final set itself
        if _jammed(scene, [*spared, contact], deadline) is not False:
            return None
    return tuple(kept)


def with_wedging_friction(solution: Solution, scene: Scene, time_limit: float = 60.0) -> Solution:
    """A ``wedged`` jam with the contacts whose friction wedges it in its message and notes (other answers as they are)."""
    if solution.status != "jammed" or solution.diagnosis is not Diagnosis.WEDGED or not solution.certified:
        return solution
    found = wedging_friction(scene, time_limit)
    if found is None:
        text = "which contacts' friction wedges it was not decided within the time limit"
        return dataclasses.replace(solution, notes=(*solution.notes, ("wedging_friction", text)))
    listed = ", ".join(f"#{i} ({scene.contacts[i].body}/{scene.contacts[i].other})" for i in found)
    text = f"friction at contacts {listed} wedges it (it alone jams the parts; without it at any one of them they move)"
    return dataclasses.replace(solution, message=f"{solution.message}; {text}", notes=(*solution.notes, ("wedging_friction", list(found))))


def _jammed(scene: Scene, frictionless: Sequence[int], deadline: float) -> bool | None:
    """Whether ``scene`` with no friction at ``frictionless`` is a proven jam (None: not decided in time)."""
    left = deadline - time.monotonic()
    if left <= 0.0:
        return None
    without = set(frictionless)
    contacts = tuple(dataclasses.replace(c, mu=0.0) if i in without else c for i, c in enumerate(scene.contacts))
    answer = solve(dataclasses.replace(scene, contacts=contacts), time_limit=left)
    if answer.status == "jammed":
        return True if answer.certified else None
    if answer.status == "failed" or not answer.certified:
        return None
    return False
