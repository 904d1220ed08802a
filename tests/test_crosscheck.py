"""Cross-checks on random scenes: the certified search vs the paper's program vs the fast path.

Each random scene (see ``random_scenes.py``: one box against a table and
fingertips, 2-D and 3-D, exact friction cones) is solved by

- ``scip``: the certified search, whose every ``solved``/``ambiguous`` motion
  must pass its audit;
- ``paper``: Trinkle & Hunter's minimum-power program solved to global
  optimality (``backends/paper.py``): when ``scip`` says ``solved`` its twist
  must be the same (1e-6 relative, scene-relative units); when ``scip`` says
  ``jammed`` or ``unstable`` it must say the same (in particular it must not
  claim ``solved`` with an audited motion); when ``scip`` says ``ambiguous``
  its motion must be one of those listed (or lie in a listed continuum);
- ``fast`` (when registered): ``solved`` means its twist is one of ``scip``'s
  motions; ``jammed`` or ``unstable`` (proven by its complete fallback) must be
  ``scip``'s verdict; ``failed`` is allowed (it falls back).

The default run takes 100 2-D and 30 3-D scenes; ``pytest -m slow`` sweeps
500 more 2-D and 120 more 3-D ones. Two more tests: ``paper`` agrees with
``scip`` on every validation scene, and the paper's program read literally
(normal forces as free variables) drops friction, which is why ``paper.py``
adds the dual's equilibrium.

Disagreements found and fixed (all in 3-D, all in the certified path's
exact-cone step, ``backends/exact3d.py``, which searches an 8-edge pyramid and
then refines each pyramid motion to the exact cone); each seed below now
passes and guards its fix:

A. Refinement rejected a correct motion (seeds 3, 31, 75, 81, 130, 136, 139):
   two rolling table contacts form a statically indeterminate pair and the
   least-squares forces carry a large internal squeeze outside the cones. The
   forces are now recovered at the refined twist by an LP.
B. The exact modes differ from the pyramid's (seeds 28, 70, 92, 99): a
   contact that slides under the 8-edge pyramid separates or rolls under the
   circle. Refinement now also tries the pyramid's modes with one or two
   sliding contacts rolling or separating, then a 32-edge search.
C. A wedged ``jammed`` proven for the pyramid only (seed 69): a wedge found
   with 8 and 32 edges is now confirmed by the paper's exact program before
   it is reported.

Nothing disagrees in 2-D (600 scenes): there both methods solve the exact
laws, and twists agree to ~1e-10.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.solution import Motion, Solution
from quasistatic.solvers import BACKENDS
from random_scenes import random_scene

TWIST_RTOL = 1e-6  # scene-relative twist agreement required between methods
_ROOT = Path(__file__).resolve().parents[1]

# (dimension, seed): why the methods disagree there, as a strict xfail (none known now).
KNOWN: dict[tuple[int, int], str] = {}


def _cases(dimension: int, seeds: range, slow: bool = False) -> list[object]:
    cases = []
    for seed in seeds:
        marks = [pytest.mark.slow] if slow else []
        if (dimension, seed) in KNOWN:
            marks.append(pytest.mark.xfail(reason=KNOWN[dimension, seed], strict=True))
        cases.append(pytest.param(dimension, seed, marks=marks, id=f"{dimension}d-{seed}"))
    return cases


DEFAULT = _cases(2, range(100)) + _cases(3, range(30))
SWEEP = _cases(2, range(100, 600), slow=True) + _cases(3, range(30, 150), slow=True)


def _twist(problem: qs.Problem, motion: Motion) -> np.ndarray:
    """Stacked scene-relative twist of a motion."""
    units = np.tile(problem.scales.twist_units(problem.dimension), len(problem.scene.bodies))
    return np.concatenate([motion.twists[b.name] for b in problem.scene.bodies]) / units


def _same_twist(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.max(np.abs(a - b)) <= TWIST_RTOL * max(1.0, float(np.max(np.abs(a)))))


def _among(problem: qs.Problem, twist: np.ndarray, certified: Solution) -> bool:
    """True when ``twist`` is one of the certified motions (a listed twist, or inside a listed continuum)."""
    motions = certified.solutions or ((certified.motion,) if certified.motion is not None else ())
    return any(motion.continuum or _same_twist(_twist(problem, motion), twist) for motion in motions)


def _crosscheck(dimension: int, seed: int) -> None:
    problem = qs.assemble(random_scene(dimension, seed))
    certified = qs.solve(problem, method="scip")
    assert certified.status != "failed", certified.message
    if certified.status in ("solved", "ambiguous"):
        assert certified.motion is not None and certified.motion.audit.passed
        assert all(motion.audit.passed for motion in certified.solutions)

    paper = qs.solve(problem, method="paper")
    if certified.status in ("jammed", "unstable"):
        assert paper.status == certified.status, f"scip: {certified.message}; paper: {paper.message}"
    elif certified.status == "solved":
        assert paper.status == "solved", paper.message
        assert paper.motion is not None and certified.motion is not None
        assert _same_twist(_twist(problem, certified.motion), _twist(problem, paper.motion))
    elif paper.status == "solved":  # ambiguous: the paper's global minimiser is one of the motions
        assert paper.motion is not None and _among(problem, _twist(problem, paper.motion), certified)

    if "fast" in BACKENDS:
        fast = qs.solve(problem, method="fast")
        if fast.status == "solved":
            assert fast.motion is not None and fast.motion.audit.passed
            assert certified.status in ("solved", "ambiguous"), f"fast solved where scip says {certified.status}"
            assert _among(problem, _twist(problem, fast.motion), certified)
        elif fast.status in ("jammed", "unstable"):  # proven by the fast path's complete fallback
            assert fast.status == certified.status and fast.certified, f"fast: {fast.message}; scip: {certified.message}"
        else:
            assert fast.status == "failed", fast.message


@pytest.mark.parametrize(("dimension", "seed"), DEFAULT)
def test_crosscheck(dimension: int, seed: int) -> None:
    _crosscheck(dimension, seed)


@pytest.mark.parametrize(("dimension", "seed"), SWEEP)
def test_crosscheck_sweep(dimension: int, seed: int) -> None:
    _crosscheck(dimension, seed)


@pytest.mark.parametrize("dimension", [2, 3])
def test_scenes_are_reproducible(dimension: int) -> None:
    a, b = random_scene(dimension, 7), random_scene(dimension, 7)
    assert [(c.other, tuple(c.point), c.mu) for c in a.contacts] == [(c.other, tuple(c.point), c.mu) for c in b.contacts]


def test_paper_refuses_prescribed_modes() -> None:
    from quasistatic.solvers import Options
    from quasistatic.solvers.paper import solve_paper

    problem = qs.assemble(random_scene(2, 0))
    result = solve_paper(problem, Options(modes=(None,) * problem.n_contacts))
    assert result.status == "failed" and "prescribed modes" in result.message


def test_literal_program_ignores_friction() -> None:
    """Why ``paper`` adds the dual's equilibrium: read literally, eq. 6, 7, 10, 23, 24 drop friction.

    With the normal forces free variables of the program, the minimum puts
    every friction force to zero: a block resting on a 20 degree slope
    (mu = 0.5) runs downhill to the twist bound, while the closed program
    keeps it at rest.
    """
    import pyscipopt

    problem = qs.assemble(qs.load_scene(_ROOT / "validation" / "scenes" / "slope_block_20.yaml"))
    m, d, n = problem.J.shape
    model = pyscipopt.Model()
    model.hideOutput()
    q = [model.addVar(lb=-1e3, ub=1e3) for _ in range(n)]
    c = [[model.addVar(lb=-1e3, ub=1e3) for _ in range(d - 1)] + [model.addVar(lb=0.0, ub=1e3)] for _ in range(m)]
    power = model.addVar(lb=None)
    friction = []
    for i in range(m):
        velocity = [pyscipopt.quicksum(float(problem.J[i, k, j]) * q[j] for j in range(n)) for k in range(d)]
        u = [velocity[k] - float(problem.b[i, k]) for k in range(d)]
        model.addCons(u[-1] >= 0.0)  # (7)
        model.addCons(c[i][0] * c[i][0] <= problem.mu[i] ** 2 * c[i][-1] * c[i][-1])  # (10)
        model.addCons(pyscipopt.quicksum(c[i][k] * u[k] for k in range(d)) <= 0.0)  # (24)
        friction += [c[i][k] * velocity[k] for k in range(d - 1)]
    model.addCons(power >= -pyscipopt.quicksum(float(problem.g[j]) * q[j] for j in range(n)) - pyscipopt.quicksum(friction))
    model.setObjective(power)  # (6)
    model.optimize()
    best = model.getBestSol()
    literal = np.array([model.getSolVal(best, v) for v in q])
    assert np.max(np.abs(literal)) > 999.0  # slides off at the bound: the frictionless answer
    closed = qs.solve(problem, method="paper")
    assert closed.status == "solved" and np.allclose(_twist(problem, closed.motion), 0.0, atol=1e-9)


@pytest.mark.parametrize("path", sorted((_ROOT / "validation" / "scenes").glob("*.yaml")), ids=lambda p: p.stem)
def test_paper_on_validation_scenes(path: Path) -> None:
    """The paper's program agrees with the certified search on every classical validation scene."""
    problem = qs.assemble(qs.load_scene(path))
    certified = qs.solve(problem, method="scip")
    paper = qs.solve(problem, method="paper")
    if certified.status == "ambiguous":
        assert paper.status == "solved" and paper.motion is not None
        assert _among(problem, _twist(problem, paper.motion), certified)
        return
    assert paper.status == certified.status, paper.message
    if certified.status == "solved":
        assert certified.motion is not None and paper.motion is not None
        assert _same_twist(_twist(problem, certified.motion), _twist(problem, paper.motion))
