"""A node's own work in the mode branch and bound, against its definition.

The search filters a contact's modes by the ball its twists lie in (``_possible_modes``: a mode stays when some
point of the ball meets each of its rows, loosened by ``LP_FEASIBILITY``) and tries its kept Farkas vectors on the
modes' columns (``_FarkasVectors.excludes``: a vector excludes a set of columns exactly when the set holds none of
its blockers). Both are written for speed (bits, floats, early exits); here each is compared with the definition,
written out in numpy and sets, on a benchmark grasp's pyramid tree and on random bit sets.
"""

from __future__ import annotations

import random

import numpy as np

import quasistatic as qs
from quasistatic.laws.polyhedral import aligned_edges, polyhedral_form
from quasistatic.solvers.certify import patterns
from quasistatic.tolerances import LP_FEASIBILITY
from quasistatic.tools.bench.families import grasp_3d


def _mode_sets(mode: patterns._Mode) -> list[tuple[patterns._Mode, ...]]:
    """Every set of sibling modes of a contact's tree (a node's children), depth first."""
    if not mode.children:
        return []
    return [mode.children, *(siblings for child in mode.children for siblings in _mode_sets(child))]


def _kept_by_definition(rows: patterns._Rows, modes: tuple[patterns._Mode, ...], ball: patterns._Ball) -> tuple[patterns._Mode, ...]:
    slack = rows.bank @ ball.center - rows.rhs
    reach = rows.norms * ball.radius + LP_FEASIBILITY

    def possible(mode: patterns._Mode) -> bool:
        equal, at_least = patterns._indices(mode.equal_bits), patterns._indices(mode.at_least_bits)
        return bool(np.all(np.abs(slack[equal]) <= reach[equal]) and np.all(slack[at_least] >= -reach[at_least]))

    return tuple(mode for mode in modes if mode.separating or possible(mode))


def test_the_mode_filter_keeps_the_modes_some_point_of_the_ball_meets() -> None:
    problem = qs.assemble(grasp_3d(6, 0))
    form = polyhedral_form(problem, aligned_edges(problem, 8))
    layout = patterns._pyramid_layout(form, [list(range(problem.n_contacts))])
    rows = patterns._Rows.of(layout, problem.g, form.n_edges, 100, seed=None, form=form)
    sets = [siblings for root in layout.roots for siblings in _mode_sets(root)]
    rng = np.random.default_rng(7)
    dropped = kept = 0
    for _ in range(80):
        ball = patterns._Ball(rng.normal(scale=0.3, size=problem.n_dof), float(rng.uniform(0.0, 0.5)))
        for modes in sets:
            possible = patterns._possible_modes(rows, modes, ball)
            assert possible == _kept_by_definition(rows, modes, ball)
            dropped += len(modes) - len(possible)
            kept += len(possible)
    assert dropped and kept  # both answers met


def test_a_farkas_vector_excludes_the_modes_whose_columns_hold_none_of_its_blockers() -> None:
    random.seed(3)
    width, contacts = 8, 5
    every = (1 << width * contacts) - 1
    for _ in range(2000):
        contact = random.randrange(contacts)
        block = ((1 << width) - 1) << (width * contact)
        store = patterns._FarkasVectors(np.zeros((1, 1)), np.zeros(1), 0.0)
        store.blockers = [random.getrandbits(width * contacts) & random.getrandbits(width * contacts) for _ in range(random.randint(0, 6))]
        columns = random.getrandbits(width * contacts) | random.getrandbits(width * contacts)
        removes = [random.getrandbits(width * contacts) & block for _ in range(4)]
        modes = tuple(patterns._Mode(np.zeros(0, int), np.zeros(0, int), np.ones(width, bool), removes=r) for r in removes)
        excluded = store.excludes(columns, every & ~block, modes)
        expected = [any(not blockers & columns & ~mode.removes for blockers in store.blockers) for mode in modes]
        assert excluded == expected
