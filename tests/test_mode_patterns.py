"""Certified answers against every contact-mode pattern: prescribing a pattern never reveals a motion the answer missed.

For a certified answer (``solved`` proven unique, ``ambiguous`` with a complete list, ``jammed``,
``unstable``) every motion of the laws has *some* pattern of contact modes. So solving the scene again
with each of the 3^m patterns prescribed (rolling, sliding or separating per contact) must give either
no motion, or motions the certified answer already lists. This is an independent check: a prescribed
pattern is solved by the fixed-mode laws, not by the search that produced the certificate. Exact 3-D
cones included: their certified answers come from the kinematic bound, the rest proof or the exact-cone
uniqueness proof (Krawczyk's test and the sector relaxation), whose claims hold on the circles themselves.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import quasistatic as qs
from random_scenes import random_scene

MODES = ("rolling", "sliding", "separating")
SAME = 1e-6  # relative twist difference within which two motions are the same [-]


def _certified(solution: qs.Solution) -> bool:
    if not solution.certified:
        return False
    return solution.status != "ambiguous" or solution.search_complete is not False


def _listed(solution: qs.Solution) -> list[qs.Motion]:
    return list(solution.solutions) or ([solution.motion] if solution.motion is not None else [])


def _covered(motion: qs.Motion, listed: list[qs.Motion], scale: float) -> bool:
    """Whether ``motion`` is one of ``listed``: the same twist; next to a listed continuum it is not checked (a
    continuum holds a set of twists whose faces carry other patterns), so the check bites on isolated motions."""
    twist = np.concatenate([motion.twists[name] for name in sorted(motion.twists)])
    for other in listed:
        base = np.concatenate([other.twists[name] for name in sorted(other.twists)])
        if np.linalg.norm(twist - base) <= SAME * scale:
            return True
        if other.continuum:
            return True
    return False


def check_every_pattern(scene: qs.Scene, time_limit: float = 20.0) -> int:
    """Solve ``scene``; if certified, check every prescribed pattern. Returns the number of patterns checked."""
    answer = qs.solve(scene, time_limit=time_limit)
    if not _certified(answer):
        return 0
    listed = _listed(answer) if answer.status in ("solved", "ambiguous") else []
    scale = max((float(np.max(np.abs(t))) for m in listed for t in m.twists.values()), default=0.0) + 1e-3
    checked = 0
    for pattern in itertools.product(MODES, repeat=len(scene.contacts)):
        prescribed = qs.solve(scene, modes=list(pattern), time_limit=time_limit)
        for motion in _listed(prescribed) if prescribed.status in ("solved", "ambiguous") else []:
            assert motion.audit.passed
            assert _covered(motion, listed, scale), (pattern, answer.status, answer.message, motion.twists)
        checked += 1
    return checked


@pytest.mark.parametrize(("dimension", "seed", "patterns"), [(2, 4, 81), (2, 0, 81), (3, 6, 81)])
def test_certified_answers_survive_every_mode_pattern(dimension: int, seed: int, patterns: int) -> None:
    """A solved, a jammed and a 3-D unstable answer (these seeds are certified: the check is not empty)."""
    assert check_every_pattern(random_scene(dimension, seed)) == patterns


@pytest.mark.slow
@pytest.mark.parametrize(("dimension", "seed"), [(2, s) for s in range(40)] + [(3, s) for s in range(200)])
def test_random_certified_answers_survive_every_mode_pattern(dimension: int, seed: int) -> None:
    if check_every_pattern(random_scene(dimension, seed)) == 0:
        pytest.skip("the answer is not certified (an exact-cone motion whose uniqueness proof did not close): nothing is claimed to check")
