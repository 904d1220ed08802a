"""Large scenes answer honestly within bounded memory (slow suite: ``pytest -m slow``).

A box resting on 10,000 frictional support points: the certified search's
dense matrices would take 12 GiB (2-D) to 75 GiB (3-D), and it could not
certify even 16 points in 25 s. The answer must be an honest ``failed``
(never a certified claim), its rest motion audited on the original data,
and the solve must stay under 2 GB of peak memory, measured in a fresh
process (``ru_maxrss``) so nothing else of the test run counts.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

_SCRIPT = """
import json, resource, sys
import numpy as np
import quasistatic as qs

dimension, side, push = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
half = 0.05
grid = np.linspace(-half, half, side)
if dimension == 3:
    points = [[x, y, 0.0] for x in grid for y in grid]
    up, com, still, finger = [0.0, 0.0, 1.0], [0.0, 0.0, half], [0.0] * 6, [push, 0.0, 0.0, 0.0, 0.0, 0.0]
else:
    points = [[x, 0.0] for x in np.linspace(-half, half, side * side)]
    up, com, still, finger = [0.0, 1.0], [0.0, half], [0.0] * 3, [push, 0.0, 0.0]
contacts = [qs.Contact("box", "table", point=p, normal=up, mu=0.5) for p in points]
movers = [qs.Mover("table", twist=still)]
if push:
    movers.append(qs.Mover("finger", twist=finger))
    side_point, inward = [-half] + [0.0] * (dimension - 2) + [0.03], [1.0] + [0.0] * (dimension - 1)
    contacts.append(qs.Contact("box", "finger", point=side_point, normal=inward, mu=0.5))
scene = qs.Scene(dimension=dimension, bodies=(qs.Body("box", mass=1.0, com=com),), movers=tuple(movers), contacts=tuple(contacts))
solution = qs.solve(scene, time_limit=25.0)
motion = solution.motion
print(json.dumps({
    "status": solution.status,
    "certified": solution.certified,
    "message": solution.message,
    "audit": None if motion is None else motion.audit.passed,
    "twist": None if motion is None else float(np.max(np.abs(motion.twists["box"]))),
    "contacts": len(solution.contacts),
    "peak_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
}))
"""

_LIMIT = 2 * 10**9  # bytes of peak memory


def _solve_in_fresh_process(dimension: int, side: int, push: float) -> dict[str, object]:
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, str(dimension), str(side), str(push)], capture_output=True, text=True, timeout=600, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


@pytest.mark.slow
@pytest.mark.parametrize("dimension", [2, 3])
def test_box_resting_on_10000_frictional_points(dimension: int) -> None:
    """At rest under gravity: ``failed`` (the search was not run, uniqueness unproven), rest shown and audited."""
    out = _solve_in_fresh_process(dimension, 100, 0.0)
    assert out["status"] == "failed" and out["certified"] is False, out["message"]
    assert "not run" in str(out["message"]) and "can stay at rest" in str(out["message"])
    assert out["audit"] is True
    assert out["twist"] == 0.0
    assert out["contacts"] == 10_000
    assert int(out["peak_bytes"]) < _LIMIT  # type: ignore[call-overload]


@pytest.mark.slow
def test_box_pushed_on_10000_frictional_points() -> None:
    """Pushed by a finger: ``failed`` with no motion claimed (rest is no answer when a mover moves)."""
    out = _solve_in_fresh_process(3, 100, 0.001)
    assert out["status"] == "failed" and out["certified"] is False, out["message"]
    assert out["audit"] is None
    assert int(out["peak_bytes"]) < _LIMIT  # type: ignore[call-overload]
