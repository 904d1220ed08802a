"""The catalogue (``catalogue.py``) run over every method that applies: a cross-method test matrix.

For each (case, method) pair, with the method's claims derived from the
registry (``catalogue.Method``):

- a frictionless method on a frictional case must refuse it with an error;
- a method that claims the case's status must return it, with the
  hand-derived numbers: twists, modes, normal forces (or their ranges),
  power, and for ``ambiguous`` every kind of motion that must be listed;
- a method that cannot claim it (a method that finds one motion, on a case
  with no motion or several) must return that status or ``failed``; on an
  ``ambiguous`` case it may return one motion, never certified, which must be
  one of the case's kinds. It never contradicts the case.

Every motion returned must pass its audit, and the laws are checked again
here from the scene data alone (``laws_hold``): each body's forces and
moments balance, forces lie in their friction cones, no contact penetrates,
the modes are those the velocities say, and sliding friction opposes the slip.
"""

from __future__ import annotations

import numpy as np
import pytest

import quasistatic as qs
from catalogue import (
    ABS,
    BY_NAME,
    CASES,
    KNOWN_BUGS,
    METHODS,
    REL,
    Case,
    Claims,
    Expected,
    Method,
    describe,
    describe_all,
    laws_hold,
    matches,
    methods,
    same,
    scale_of,
)
from quasistatic.solvers import BACKENDS


def _pairs() -> list[object]:
    pairs = []
    for case in CASES:
        for method in METHODS:
            marks = []
            if (case.name, method.id) in KNOWN_BUGS:
                raises, reason = KNOWN_BUGS[case.name, method.id]
                marks.append(pytest.mark.xfail(raises=raises, reason=reason, strict=True))
            if method.name == "paper" and case.paper_slow:
                marks.append(pytest.mark.skip(reason=f"paper_slow: {case.paper_slow}"))
            pairs.append(pytest.param(case, method, id=f"{case.name}-{method.id}", marks=marks))
    return pairs


@pytest.mark.parametrize(("case", "method"), _pairs())
def test_case(case: Case, method: Method) -> None:
    """The method answers the case as derived by hand, or (where it cannot claim that answer) says ``failed``."""
    if not method.applies(case):
        with pytest.raises(qs.QuasistaticError, match=r"mu > 0"):
            method.solve(case.scene)
        return
    sol = method.solve(case.scene)
    if method.can_claim(case):
        assert sol.status == case.status, sol.message
    elif case.needs_all_motions:  # a method that finds one motion may return one of several, unproven
        assert sol.status in ("ambiguous", "solved", "failed"), sol.message
    else:
        assert sol.status in (case.status, "failed"), sol.message
    claims = method.claims(case.frictional)
    if sol.status == "solved" and case.status == "solved":
        check_solved(case, claims, sol)
    elif sol.status == "solved":
        check_one_of_several(case, sol)
    elif sol.status == "ambiguous":
        check_listed(case, sol)
    elif sol.status != "failed":
        check_no_motion(case, claims, sol)


# --------------------------------------------------------------------------- what each answer must show


def check_solved(case: Case, claims: Claims, sol: qs.Solution) -> None:
    """The unique motion of a ``solved`` case, proven unique by a certifying method."""
    assert sol.motion is not None and sol.solutions == ()
    if claims.certifies and not case.exact_cones:
        assert sol.certified, sol.message
    (expected,) = case.motions
    assert matches(sol.motion, expected, exact=True), describe(sol.motion, expected)
    check_ranges(sol, expected, claims)
    check_motion(case.scene, sol.motion)


def check_one_of_several(case: Case, sol: qs.Solution) -> None:
    """One motion of an ``ambiguous`` case: one of its kinds, never claimed to be the only one."""
    assert not sol.certified, "one motion of several must not be certified unique"
    kinds = (*case.motions, *case.also)
    assert sol.motion is not None and any(matches(sol.motion, kind, exact=False) for kind in kinds), describe(sol.motion, *kinds)
    check_motion(case.scene, sol.motion)


def check_listed(case: Case, sol: qs.Solution) -> None:
    """Every kind of motion the case must list is listed, and every listed motion is one of its kinds."""
    assert sol.certified, sol.message
    assert sol.solutions and sol.motion is sol.solutions[0]
    kinds = (*case.motions, *case.also)
    for kind in case.motions:
        assert any(matches(m, kind, exact=True) for m in sol.solutions), describe_all(sol.solutions, kind)
    for motion in sol.solutions:
        assert any(matches(motion, kind, exact=False) for kind in kinds), describe(motion, *kinds)
        check_motion(case.scene, motion)


def check_no_motion(case: Case, claims: Claims, sol: qs.Solution) -> None:
    """No motion, and why (the diagnosis); a method that proves it shows its certificate."""
    assert not sol.ok and sol.solutions == () and sol.motion is None
    assert sol.diagnosis is case.diagnosis, (sol.diagnosis, sol.message)
    if claims.proves_no_motion:
        assert sol.certified and sol.certificate is not None, sol.message
    if case.farkas is not None and sol.certificate is not None and sol.certificate.kind is qs.CertificateKind.FARKAS:
        y = np.asarray(sol.certificate.data, dtype=float)
        expected = np.asarray(case.farkas)
        assert y.min() >= -ABS and y @ expected > 0
        np.testing.assert_allclose(y / np.linalg.norm(y), expected / np.linalg.norm(expected), atol=1e-9)


def check_ranges(sol: qs.Solution, expected: Expected, claims: Claims) -> None:
    """Indeterminate normal forces: the reported ones lie in the derived ranges; the ranges themselves are
    reported by a certifying method (and, when reported, equal the derived ones)."""
    ranges = expected.normal_force_ranges
    if ranges is None:
        if claims.certifies or not expected.friction_indeterminate:
            assert sol.forces_indeterminate == expected.friction_indeterminate, [c.normal_force_range for c in sol.contacts]
        if sol.forces_indeterminate:  # only the friction varies: each normal range is the one normal force
            for c in sol.contacts:
                assert c.normal_force_range is not None, sol.message
                lo, hi = c.normal_force_range
                assert hi is not None and same(hi, lo, c.normal_force), c.normal_force_range
        return
    scale = scale_of([x for pair in ranges for x in pair])
    for c, (lo, hi) in zip(sol.contacts, ranges, strict=True):
        assert c.normal_force >= lo - REL * scale - ABS, (c.normal_force, lo, hi)
        assert hi is None or c.normal_force <= hi + REL * scale + ABS, (c.normal_force, lo, hi)
    if claims.certifies:
        assert sol.forces_indeterminate, sol.message
    if sol.forces_indeterminate:
        for c, (lo, hi) in zip(sol.contacts, ranges, strict=True):
            assert c.normal_force_range is not None
            got_lo, got_hi = c.normal_force_range
            assert same(got_lo, lo, scale), (c.normal_force_range, (lo, hi))
            assert (got_hi is None) == (hi is None), (c.normal_force_range, (lo, hi))
            assert hi is None or same(got_hi, hi, scale), (c.normal_force_range, (lo, hi))


# --------------------------------------------------------------------------- the laws, from the scene data alone


def check_motion(scene: qs.Scene, motion: qs.Motion) -> None:
    """The audit passes, and the laws hold when checked here from the scene data and the reported twists and forces."""
    assert motion.audit.passed, motion.audit.failures()
    laws_hold(scene, motion)


# --------------------------------------------------------------------------- the catalogue and the registry


def test_catalogue_covers_every_status_dimension_and_friction() -> None:
    kinds = {(c.status, c.scene.dimension, c.frictional) for c in CASES}
    assert {s for s, _, _ in kinds} == {"solved", "ambiguous", "jammed", "unstable"}
    assert {(d, f) for _, d, f in kinds} == {(2, True), (2, False), (3, True), (3, False)}
    assert 15 <= len(CASES) <= 35


def test_every_registered_backend_is_in_the_matrix() -> None:
    assert {m.name for m in METHODS} == {"auto", *(name for name, b in BACKENDS.items() if b.available)}
    for frictional in (True, False):
        assert methods(frictional=frictional, certifying=True), "some method certifies every kind of scene"
        assert methods(frictional=frictional, no_motion=True) and methods(frictional=frictional, all_motions=True)


@pytest.mark.parametrize("method", [m for m in METHODS if m.name != "auto"], ids=str)
def test_capabilities_are_what_solve_accepts(method: Method) -> None:
    """A backend that does not list every motion refuses ``all_solutions``; one that does not take prescribed
    modes refuses them (the claims above are the registry's, so they must be what ``solve`` does)."""
    backend = BACKENDS[method.name]
    case = BY_NAME["grasp-lift-mu05" if method.frictional else "lift-drifts-sideways"]  # several motions
    problem = qs.assemble(case.scene)
    if method.claims(case.frictional).lists_all_motions:
        assert method.solve(problem, all_solutions=True).status == case.status
    else:
        with pytest.raises(ValueError, match="all_solutions"):
            method.solve(problem, all_solutions=True)
    if not backend.prescribes_modes:
        with pytest.raises(ValueError, match="modes"):
            method.solve(problem, modes=[None] * problem.n_contacts)
