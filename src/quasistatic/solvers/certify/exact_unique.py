"""A proof, on the exact circular cones, that a 3-D motion is the only one.

The certified search is complete for an inscribed pyramid; a motion refined
from it satisfies the exact laws, but the circle may hold others. This
module proves there are none, in two parts that together cover every twist.

Near the motion. Fix its contact modes; then the exact laws are smooth square
equations (:mod:`quasistatic.laws.fixed_modes`). Around each sliding
contact's slip angle take an arc of half-width ``r``. Every exact solution
with these modes whose slips lie in the arcs has its twist in a polyhedron
(closed contacts shut, rolling ones still, sliding ones' slips inside their
arcs, separating ones open), bounded by a box in closed form where its
equalities leave a line, else by LPs. Its forces solve the equilibrium,
linear in them, with each sliding contact's friction direction inside its
arc: an interval residual bound (:func:`quasistatic.interval.linear_solutions`)
boxes them. Krawczyk's test (:func:`quasistatic.interval.krawczyk`, interval
arithmetic rounded outwards) proves the equations have exactly one zero in
that box, which is the motion, or in its meet with Krawczyk's operator
(which holds every zero of the box). ``r`` shrinks by the test's scaled
contraction norm until it passes (the box must be small where the sliding
contacts' friction turns fast). Where the rows alone pin the twist, that
decides it, however indeterminate the forces.

Everywhere else. Every exact solution lies in some leaf of the sector
relaxation of :mod:`.wedge` (per contact: separating, rolling, or sliding
with its slip in one sector). The sectors of each sliding contact start with
its arc as one sector; the mode branch and bound of
:func:`~.patterns.relaxation_excluded` then excludes every leaf but those
inside the arcs with the motion's modes (covered above) and those whose rows
leave the motion's twist alone, halving the sectors of a leaf that survives,
as the wedge proof does. A surviving leaf whose twist is an exact motion, or
from whose twist Newton's method on the fixed-mode laws with the leaf's modes
reaches one (the relaxation's point is a vertex of its twist rows, seldom a
motion itself), ends the proof: a second motion exists.

Next to the arcs. The relaxation cannot tell slips just outside a narrow arc
from the motion's: its LPs meet rows to ``LP_FEASIBILITY``, which an
ill-conditioned grasp turns into more than the arc, so a leaf with the
motion's modes next to the arc survives every halving. Such a leaf is
excluded by Krawczyk's operator instead: a box holds every zero of the
fixed-mode laws with slips in its sectors (twists by its rows, forces by the
residual bound), is met with the operator centred at its middle (which holds
every zero of the box) until empty or until its twists miss one of the leaf's
rows, its sectors halved where that fails; every leaf inside its sectors is
then passed over.

Both parts hold to the tolerances of their LPs (``LP_FEASIBILITY``, which
the twist box is widened by) and of the branch and bound's checked Farkas
vectors; the arithmetic of Krawczyk's test is rigorous.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ...interval import Interval, KrawczykTest, krawczyk, linear_solutions, matmul, point, unit_vectors
from ...laws import ModeMasks, Problem, RawMotion, contact_modes
from ...laws.fixed_modes import FixedModeLaws
from ...tolerances import DISTINCT_TWIST, FIXED_MODE_RESIDUAL, JACOBIAN_RANK, LP_FEASIBILITY, SAME_TWIST
from ..numerics.highs import optimise_each, solve_lp
from ..numerics.line_extent import line_axis_extents
from ..result import Options
from .patterns import CLOSED_LEAF, SEPARATING_LEAF, PassedRegions, TreeShape, relaxation_excluded
from .wedge import split_sectors

__all__ = ["Uniqueness", "PausedProof", "prove_unique_exact", "resume_unique_exact", "EXACT_UNIQUENESS_PROOF"]

EXACT_UNIQUENESS_PROOF = (
    "Krawczyk's interval test near the motion, and a sector relaxation of the exact laws excluding every other "
    "mode pattern and slip direction (mode branch and bound, LPs and Farkas vectors)"
)
FIRST_ARC = 2.0**-8  # half-width [rad] of the first arc tried around each sliding contact's slip
LAST_ARC = 2.0**-24  # the narrowest arc tried before the near part gives up
WIDENINGS = 4  # bisections towards the last arc that failed, once a narrower one passed (seed 111: 3.5x wider)
NARROWINGS = 2  # Krawczyk's test tried again on a box narrowed by its operator (the first arc then passes on 8 #1)
FAR_SECTOR = np.pi / 3  # widest sector outside the arcs (narrower than a half-turn; measured against pi/2, pi/4 and pi/6: fastest)
FINEST_FRACTION = 1.0 / 64  # a sector is not halved below this fraction of the arc
LEAF_NEWTON_STEPS = 20  # Newton steps from a surviving leaf's twist towards an exact motion with its modes
EXCLUDED_LEAVES = 12  # leaves next to the arcs excluded by Krawczyk's operator, at most (each: a round again;
# measured: seeds 28 and 221 take 5 and 8; seed 16 does not close with 64)
LEAF_PIECES = 8  # pieces a leaf's sectors are cut into, at most, for that exclusion (those that pass take 1-3)
LEAF_NARROWINGS = 8  # meets of a piece's box with Krawczyk's operator, at most
FAR_ARC = 0.7 * np.pi  # widest arc of sectors a closed contact's first split gives in the far part's tree: two
# sectors of FAR_SECTOR (measured: 16 % fewer nodes than pi / 2 over the 12 bench grasps and 240 random scenes, the
# same verdicts; the wedge proof keeps pi / 2, where this took 5 % more)
FAR_ROUNDS = 8  # most refinements of the sectors (measured on 73 motions: proofs took 1-4, failures ran to 7-16)


Extents = tuple[np.ndarray, np.ndarray]  # least and greatest values, one entry per unknown


@dataclass(frozen=True)
class Uniqueness:
    """Whether the motion was proven the only one; if not, another exact motion's twist when one was met, and why.
    ``paused``: where a proof asked to pause stopped before it decided (:func:`resume_unique_exact` continues it)."""

    proven: bool
    other: np.ndarray | None = None
    reason: str = ""
    rounds: int = 0
    paused: PausedProof | None = None


def prove_unique_exact(
    problem: Problem, motion: RawMotion, options: Options, is_motion: Callable[[np.ndarray], bool], pause_after: int | None = None
) -> Uniqueness:
    """Prove that ``motion`` (an exact 3-D motion, checked by the caller) is the only one, within ``options``' clock.

    ``is_motion`` tells whether a twist is an exact motion (it is asked of a surviving leaf's twist).
    ``pause_after``: a first, cheap attempt: where the near part's first arc fails, or the far part has run that
    many rounds without closing (before it examines the last one's surviving leaf), the proof stops undecided with
    its state (:attr:`Uniqueness.paused`), which :func:`resume_unique_exact` continues; None: run to the end.
    """
    modes = np.array(contact_modes(problem, motion.q), dtype=object)
    masks = ModeMasks.of(problem, modes)
    laws = FixedModeLaws(problem, masks)
    x = laws.start(motion.q, motion.c, nonnegative=False)
    slips = problem.velocities(motion.q)[:, :2]
    angles = np.arctan2(slips[:, 1], slips[:, 0])
    residual = laws.enclosure(point(x))  # never None: the motion's sliding contacts slip
    arc = _near_arc(problem, laws, masks, x, angles, None if residual is None else residual[0], first_only=pause_after is not None)
    if arc is None and pause_after is not None:
        return Uniqueness(False, reason="paused: the near part's first arc failed", paused=PausedProof(problem, motion, None))
    if arc is None:
        return Uniqueness(False, reason="the fixed-mode equations are not proven to have one zero near the motion")
    near = None if residual is None else _NearMotion(problem, laws, x, residual[0])
    return _FarPart(problem, motion, masks, angles, arc, near, _far_order(masks, motion.c)).run(options, is_motion, pause_after)


def resume_unique_exact(paused: PausedProof, options: Options, is_motion: Callable[[np.ndarray], bool]) -> Uniqueness:
    """The proof :func:`prove_unique_exact` paused, run to the end from where it stopped (the far part's sectors,
    exclusions, Farkas vectors, passed regions, rounds and surviving leaf; the near part in full where its first
    arc failed). A paused proof is resumed once: its far part advances in place."""
    if paused.far is None:
        return prove_unique_exact(paused.problem, paused.motion, options, is_motion)
    return paused.far.run(options, is_motion, None)


def _near_arc(
    problem: Problem,
    laws: FixedModeLaws,
    masks: ModeMasks,
    x: np.ndarray,
    angles: np.ndarray,
    residual: Interval | None,
    first_only: bool = False,
) -> float | None:
    """The widest arc tried (from :data:`FIRST_ARC`) whose box holds only the motion; None if none does
    (``residual``: the laws' enclosure at the motion ``x``; ``first_only``: None where the first arc fails).

    The box holds one twist when the rows pin it (every contact rolling or separating, say: the forces may
    still be indeterminate, even unbounded); otherwise Krawczyk's test decides, and an arc whose box fails is
    shrunk by the test's contraction norm (four times it, at least halved) before the next try. An arc that
    passes after one that failed is widened towards it (:func:`_widened`): the far part closes sooner, or only,
    with a wider arc (its relaxation cannot tell slips just outside a narrow arc from the motion's).
    """
    sigma = np.linalg.svd(laws.jacobian(x), compute_uv=False)
    singular = sigma[-1] <= JACOBIAN_RANK * sigma[0]  # indeterminate forces: no box passes, only pinned twists

    def verdict(arc: float) -> _ArcVerdict:
        return _arc_verdict(problem, laws, masks, x, angles, arc, None if singular else residual)

    arc, failed = FIRST_ARC, None
    while arc >= LAST_ARC:
        tried = verdict(arc)
        if tried.proven:
            return arc if failed is None else _widened(verdict, arc, failed)
        if tried.shrink == 0.0 or first_only:
            return None
        failed = arc
        arc /= tried.shrink
    return None


class _ArcVerdict(NamedTuple):
    """Whether an arc's box holds only the motion; if not, how much narrower the next arc should be (0: none passes)."""

    proven: bool
    shrink: float = 0.0


def _arc_verdict(
    problem: Problem, laws: FixedModeLaws, masks: ModeMasks, x: np.ndarray, angles: np.ndarray, arc: float, residual: Interval | None
) -> _ArcVerdict:
    """The near part's test on one arc (see :func:`_near_arc`); ``residual``: the laws' enclosure at the motion,
    None where the forces are indeterminate (then only pinned twists pass)."""
    twist = _twist_box(problem, masks, _arc_rays(masks, angles, arc))
    if twist is not None and np.max(twist[1] - twist[0]) <= DISTINCT_TWIST:
        return _ArcVerdict(True)  # one twist (the forces need not be unique)
    if residual is None:
        return _ArcVerdict(False)
    box = None if twist is None else _local_box(laws, x, twist, unit_vectors(angles - arc, angles + arc))
    if box is None or not (np.all(box.lo <= x) and np.all(x <= box.hi)):
        return _ArcVerdict(False, 2.0)
    test = _narrowed_krawczyk(laws, x, residual, box)
    if test is None:
        return _ArcVerdict(False, 2.0)
    if test.unique:
        return _ArcVerdict(True)
    return _ArcVerdict(False, max(2.0, 4.0 * min(test.contraction, 1e6)))


def _widened(verdict: Callable[[float], _ArcVerdict], passed: float, failed: float) -> float:
    """The widest arc found between one that passed and a wider one that failed, by :data:`WIDENINGS` geometric
    bisections (Krawczyk's contraction grows with the arc, so the arcs that pass are about those below one)."""
    for _ in range(WIDENINGS):
        middle = float(np.sqrt(passed * failed))
        if verdict(middle).proven:
            passed = middle
        else:
            failed = middle
    return passed


def _narrowed_krawczyk(laws: FixedModeLaws, x: np.ndarray, residual: Interval, box: Interval) -> KrawczykTest | None:
    """Krawczyk's test on ``box``, then again on its meet with Krawczyk's operator (which holds every zero of the
    box, so a pass there proves the box's zero unique) while that meet holds ``x``, :data:`NARROWINGS` times at
    most; None where a slip may vanish in the box."""
    for _ in range(1 + NARROWINGS):
        enclosure = laws.enclosure(box)
        if enclosure is None:
            return None
        test = krawczyk(x, box, residual, enclosure[1])
        if test.unique or test.image is None:
            return test
        box = Interval(np.maximum(box.lo, test.image.lo), np.minimum(box.hi, test.image.hi))
        if not (np.all(box.lo <= x) and np.all(x <= box.hi)):
            return test
    return test


def _local_box(laws: FixedModeLaws, x: np.ndarray, twist: Extents, directions: Interval) -> Interval | None:
    """A box (in the fixed-mode unknowns) holding every exact solution with these modes and slips in the arcs,
    given the box of their twists and of their slip directions; None where the forces are not proven bounded."""
    margin = LP_FEASIBILITY * (1.0 + np.maximum(np.abs(twist[0]), np.abs(twist[1]))) + SAME_TWIST
    forces = _force_box(laws, x, directions)
    if forces is None:
        return None
    return Interval(np.concatenate([twist[0] - margin, forces.lo]), np.concatenate([twist[1] + margin, forces.hi]))


def _extents(A: np.ndarray, lower: np.ndarray, upper: np.ndarray, count: int, col_lower: np.ndarray | None = None) -> Extents | None:
    """Least and greatest value of each of the first ``count`` unknowns over ``lower <= A x <= upper``; None if unbounded or empty."""
    units = np.eye(A.shape[1])[:count]
    results = optimise_each([(u, maximize) for u in units for maximize in (False, True)], A, lower, upper, col_lower)
    if any(r.status != "optimal" for r in results):
        return None
    values = np.array([r.objective for r in results]).reshape(count, 2)
    return values[:, 0], values[:, 1]


Rays = list[tuple[float, float] | None]  # per contact: the angles [rad] its slip lies between, None if it does not slide


def _arc_rays(masks: ModeMasks, angles: np.ndarray, arc: float) -> Rays:
    """Each sliding contact's arc of half-width ``arc`` around its slip angle."""
    return [(float(a) - arc, float(a) + arc) if sliding else None for a, sliding in zip(angles, masks.sliding, strict=True)]


def _twist_box(problem: Problem, masks: ModeMasks, rays: Rays) -> Extents | None:
    """Twist extents: closed contacts shut, rolling ones still, separating ones open, sliding slips between their
    rays (read off in closed form where the equalities leave a line, else by LPs)."""
    A, lower, upper = _twist_rows(problem, masks.closed, masks.rolling, rays)
    equal = lower == upper  # every other row is only bounded below
    on_line = line_axis_extents(A[equal], lower[equal], A[~equal], lower[~equal])
    if on_line is None:
        return _extents(A, lower, upper, problem.n_dof)
    if on_line.empty or on_line.free:
        return None
    ends = np.array(on_line.extremes)  # the segment's ends (one, where they are within SAME_TWIST)
    return ends.min(axis=0), ends.max(axis=0)


def _twist_rows(problem: Problem, shut: np.ndarray, still: np.ndarray, rays: Rays) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Twist rows ``lower <= A q <= upper``: each contact shut (else open), still, or slipping between two rays."""
    rows, lower, upper = [], [], []
    for i in range(problem.n_contacts):
        Jn, bn, Jt, bt = problem.Jn[i], float(problem.bn[i]), problem.Jt[i], problem.bt[i]
        rows.append(Jn)
        lower.append(bn)
        upper.append(bn if shut[i] else np.inf)
        if still[i]:
            rows += [Jt[0], Jt[1]]
            lower += [bt[0], bt[1]]
            upper += [bt[0], bt[1]]
        elif (between := rays[i]) is not None:
            for row, value in _between_rays(Jt, bt, *between):
                rows.append(row)
                lower.append(value)
                upper.append(np.inf)
    return np.array(rows), np.array(lower), np.array(upper)


def _between_rays(Jt: np.ndarray, bt: np.ndarray, lo: float, hi: float) -> list[tuple[np.ndarray, float]]:
    """Rows ``row . q >= value`` saying the slip ``Jt q - bt`` lies between the rays at angles ``lo`` and ``hi``."""
    after_lo = np.array([-np.sin(lo), np.cos(lo)])  # a(lo) x v >= 0
    before_hi = np.array([np.sin(hi), -np.cos(hi)])  # v x a(hi) >= 0
    return [(side @ Jt, float(side @ bt)) for side in (after_lo, before_hi)]


def _force_box(laws: FixedModeLaws, x: np.ndarray, directions: Interval) -> Interval | None:
    """A box holding the fixed-mode force unknowns of every solution whose sliding contacts slip within
    ``directions`` (m, 2); None where the forces are not proven unique for each such slip.

    The equilibrium ``E f = -g`` is linear in them, and ``E`` depends on the slip directions alone: with ``C``
    the pseudo-inverse of ``E`` at the motion, every such ``f`` solves the square ``C E f = -C g``, whose
    solutions over the directions' ``E`` an interval residual bound encloses (no LP).
    """
    C = np.linalg.pinv(laws.jacobian(x)[: laws.n, laws.n :])
    return linear_solutions(matmul(C, laws.force_matrix(directions)), matmul(C, point(-laws.g)))


@dataclass(frozen=True)
class PausedProof:
    """A proof :func:`prove_unique_exact` paused: its problem and motion, and the far part as it stopped (None where
    the near part's first arc failed: the near part then runs again in full)."""

    problem: Problem
    motion: RawMotion
    far: _FarPart | None


class _FarPart:
    """Every leaf of the sector relaxation outside the arcs (or with other modes) excluded, refining the sectors.

    The state lives here between rounds, so a paused proof resumes where it stopped: the sectors, the leaves
    Krawczyk's operator excluded, the last round's Farkas vectors (tried first on the next) and passed regions
    (:class:`~.patterns.PassedRegions`: each round resumes where the last stopped), the rounds and refinements so
    far, and the last round's surviving leaf and twist where it is not examined yet.

    ``order``: the contacts as the tree splits them (:func:`_far_order`), in arcs of :data:`FAR_ARC`. A node
    whose twists are all the motion's (its rows pin them: a rolling contact whose force may reach the circle,
    say) holds no other motion; the branch and bound passes it over (``twist=q``). A surviving leaf with the
    motion's modes that ``near`` proves holds no zero of the fixed-mode laws (:meth:`_NearMotion.excludes`) is
    passed over from then on, with every leaf inside its sectors, and the round is run again unrefined.
    """

    def __init__(
        self,
        problem: Problem,
        motion: RawMotion,
        masks: ModeMasks,
        angles: np.ndarray,
        arc: float,
        near: _NearMotion | None,
        order: list[int],
    ) -> None:
        self.problem, self.motion, self.q, self.masks, self.arc, self.near = problem, motion, motion.q, masks, arc, near
        self.shape = TreeShape(order, FAR_ARC)
        self.sectors = [_first_sectors(float(angles[i]), arc) if masks.sliding[i] else _even_sectors() for i in range(problem.n_contacts)]
        self.wanted = np.where(masks.closed, CLOSED_LEAF, SEPARATING_LEAF)
        self.arc_end = [float(first[0]) + 2.0 * arc * (1.0 + 1e-12) for first in self.sectors]  # the arcs' sectors end there
        self.excluded: list[np.ndarray] = []  # slip angle bounds (m, 2) of leaves with the motion's modes holding no zero
        self.rounds = self.refinements = 0
        self.farkas: tuple[np.ndarray, ...] = ()  # the last round's, tried first on the next
        self.passed: PassedRegions | None = None  # what the rounds before excluded: the next resumes where the last stopped
        self.survivor: tuple[tuple[int, ...], np.ndarray] | None = None  # the last round's leaf and twist, not yet examined

    def run(self, options: Options, is_motion: Callable[[np.ndarray], bool], pause_after: int | None) -> Uniqueness:
        """Rounds until the proof is decided, or paused once ``pause_after`` rounds have run undecided."""
        while options.remaining() > 0.0 and self.refinements < FAR_ROUNDS:
            survivor, self.survivor = self.survivor, None
            if survivor is None:
                found = self._round(options)
                if isinstance(found, Uniqueness):
                    return found
                survivor = found
                if pause_after is not None and self.rounds >= pause_after:
                    self.survivor = survivor
                    paused = PausedProof(self.problem, self.motion, self)
                    return Uniqueness(False, reason=f"paused after {self.rounds} round(s)", rounds=self.rounds, paused=paused)
            leaf, twist = survivor
            other = _other_motion(self.problem, self.q, leaf, twist, is_motion)
            if other is not None:
                return Uniqueness(False, other=other, reason="another exact motion exists", rounds=self.rounds)
            if self._exclude(leaf, options):
                continue  # the same sectors again, this leaf passed over
            self.refinements += 1
            if not split_sectors(self.sectors, leaf, FINEST_FRACTION * self.arc):
                return Uniqueness(False, reason="a leaf of the sector relaxation survives at the finest sectors", rounds=self.rounds)
        return Uniqueness(False, reason=f"out of time or of refinements ({self.refinements})", rounds=self.rounds)

    def _round(self, options: Options) -> Uniqueness | tuple[tuple[int, ...], np.ndarray]:
        """One branch and bound over the current sectors: proven, failed, or its surviving leaf and a twist of it."""
        self.rounds += 1
        proof = relaxation_excluded(
            self.problem, self.sectors, options.remaining, self._covered, self.q, self.farkas, self.passed, self.shape
        )
        self.farkas, self.passed = proof.farkas, proof.passed
        options.report(1, proof.nodes)  # a long proof shows on the CLI's status line
        if proof.excluded:
            return Uniqueness(True, rounds=self.rounds)
        if proof.sectors is None or proof.q is None:
            return Uniqueness(False, reason="the sector relaxation's branch and bound gave no answer", rounds=self.rounds)
        return proof.sectors, proof.q

    def _bounds(self, leaf: tuple[int, ...]) -> np.ndarray | None:
        """The leaf's sectors as angle bounds (m, 2) (zero rows where no contact slides), if it has the motion's modes."""
        sliding = self.masks.sliding
        if any(k < 0 if sliding[i] else k != self.wanted[i] for i, k in enumerate(leaf)):
            return None
        return np.array([self.sectors[i][k : k + 2] if sliding[i] else (0.0, 0.0) for i, k in enumerate(leaf)])

    def _covered(self, leaf: tuple[int, ...]) -> bool:
        sliding = self.masks.sliding
        if all(k >= 0 and self.sectors[i][k + 1] <= self.arc_end[i] if sliding[i] else k == self.wanted[i] for i, k in enumerate(leaf)):
            return True  # inside the arcs, with the motion's modes
        ends = None if not self.excluded else self._bounds(leaf)
        return ends is not None and any(bool(np.all((box[:, 0] <= ends[:, 0]) & (ends[:, 1] <= box[:, 1]))) for box in self.excluded)

    def _exclude(self, leaf: tuple[int, ...], options: Options) -> bool:
        """Whether a surviving leaf with the motion's modes is proven to hold no zero (then passed over)."""
        ends = self._bounds(leaf)
        if self.near is None or ends is None or len(self.excluded) >= EXCLUDED_LEAVES or options.remaining() <= 0.0:
            return False
        if self.near.excludes(self.masks, ends):
            self.excluded.append(ends)
            return True
        return False


def _far_order(masks: ModeMasks, forces: np.ndarray) -> list[int]:
    """The contacts the motion rolls at, then those it slides at, then those it opens, least loaded first in each
    (``forces``: (m, 3), normal last), as the pyramid's proof orders them: closed rows bound the twists soonest.
    Measured (far part's nodes, with rounds resumed): 8,183 on the five solved bench grasps of 4-8 contacts where
    the contacts as numbered take 9,620; 45,794 over the 12 grasps and 240 random scenes of 2-4 contacts, 44,844
    as numbered (most loaded first in each group: 8,774 and 40,332)."""
    rank = np.where(~masks.closed, 2, np.where(masks.sliding, 1, 0))
    return [int(i) for i in np.lexsort((np.asarray(forces)[:, -1], rank))]


@dataclass(frozen=True)
class _NearMotion:
    """The motion ``x`` in the fixed-mode unknowns of ``laws`` (its modes) and the laws' enclosure there, for
    Krawczyk's exclusion of leaves next to the arcs (:meth:`excludes`)."""

    problem: Problem
    laws: FixedModeLaws
    x: np.ndarray
    residual: Interval

    def excludes(self, masks: ModeMasks, ends: np.ndarray) -> bool:
        """Whether no zero of the fixed-mode laws other than the motion has its sliding contacts' slips within
        ``ends`` (m, 2) [rad]. The sectors are cut in halves (the widest first) where a piece's test fails,
        :data:`LEAF_PIECES` pieces at most; each piece's test is :meth:`_piece_excluded`."""
        pieces, tried = [ends], 0
        while pieces:
            piece = pieces.pop()
            tried += 1
            if tried > LEAF_PIECES:
                return False
            if self._piece_excluded(masks, piece):
                continue
            widths = np.where(masks.sliding, piece[:, 1] - piece[:, 0], 0.0)
            i = int(np.argmax(widths))
            middle = 0.5 * (piece[i, 0] + piece[i, 1])
            low, high = piece.copy(), piece.copy()
            low[i, 1], high[i, 0] = middle, middle
            pieces += [high, low]
        return True

    def _piece_excluded(self, masks: ModeMasks, ends: np.ndarray) -> bool:
        """Whether the piece holds no zero but the motion's. Its box (twists by its rows, forces by the residual
        bound over its slip directions) holds every zero of the piece; Krawczyk's operator centred at the box's
        middle holds every zero of the box, so the box is met with it, :data:`LEAF_NARROWINGS` times at most. The
        piece is excluded once the meet is empty, or its twists miss one of the piece's rows by more than
        ``LP_FEASIBILITY`` (the relaxation's own slack): the box then holds no twist of the piece; or at once where
        no twist meets its rows (:func:`_no_twist`)."""
        rays: Rays = [(float(lo), float(hi)) if sliding else None for (lo, hi), sliding in zip(ends, masks.sliding, strict=True)]
        A, lower, upper = _twist_rows(self.problem, masks.closed, masks.rolling, rays)
        twist = _twist_box(self.problem, masks, rays)
        if twist is None:
            return _no_twist(A, lower, upper)
        box = _local_box(self.laws, self.x, twist, unit_vectors(ends[:, 0], ends[:, 1]))
        n = self.laws.n
        for _ in range(LEAF_NARROWINGS):
            if box is None:
                return False
            values = matmul(A, box[:n])
            if np.any((values.hi < lower - LP_FEASIBILITY) | (values.lo > upper + LP_FEASIBILITY)):
                return True
            box = _narrowed(self.laws, box)
            if box is not None and box.lo.size == 0:
                return True
        return False


def _no_twist(A: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether no twist meets ``lower <= A q <= upper`` with every row loosened by ``LP_FEASIBILITY`` (HiGHS finds
    it infeasible), as the relaxation's leaves are pruned by their twist rows."""
    return solve_lp(np.zeros(A.shape[1]), A, lower - LP_FEASIBILITY, upper + LP_FEASIBILITY, simplex_first=True).status == "infeasible"


def _narrowed(laws: FixedModeLaws, box: Interval) -> Interval | None:
    """``box`` met with Krawczyk's operator centred at its middle (which holds every zero of the box): an empty
    interval (no entries) when the meet is empty; None where the laws are not smooth in the box."""
    centre = box.mid
    enclosure, residual = laws.enclosure(box), laws.enclosure(point(centre))
    image = None if enclosure is None or residual is None else krawczyk(centre, box, residual[0], enclosure[1]).image
    if image is None:
        return None
    lo, hi = np.maximum(box.lo, image.lo), np.minimum(box.hi, image.hi)
    if np.any(lo > hi):
        return Interval(np.zeros(0), np.zeros(0))
    return Interval(lo, hi)


def _other_motion(
    problem: Problem, q: np.ndarray, leaf: tuple[int, ...], twist: np.ndarray, is_motion: Callable[[np.ndarray], bool]
) -> np.ndarray | None:
    """An exact motion's twist, distinct from ``q``, that a surviving leaf (its modes, a twist of it) holds: its
    own twist, or where Newton's method from it on the fixed-mode laws with the leaf's modes goes; None if neither
    is one (``is_motion`` decides; the caller refines and audits what it gets)."""
    candidates = (twist, _leaf_newton(problem, leaf, twist))
    for candidate in candidates:
        if candidate is not None and np.max(np.abs(candidate - q)) > DISTINCT_TWIST and is_motion(candidate):
            return candidate
    return None


def _leaf_newton(problem: Problem, leaf: tuple[int, ...], twist: np.ndarray) -> np.ndarray | None:
    """The twist of a zero of the fixed-mode laws with the leaf's modes (a sector: sliding; closed: rolling;
    separating), by at most :data:`LEAF_NEWTON_STEPS` least-squares Newton steps from ``twist`` with no force;
    None where the residual does not fall to ``FIXED_MODE_RESIDUAL``."""
    names = {CLOSED_LEAF: "rolling", SEPARATING_LEAF: "separating"}
    modes = np.array([names.get(k, "sliding") for k in leaf], dtype=object)
    laws = FixedModeLaws(problem, ModeMasks.of(problem, modes))
    x = laws.start(twist, np.zeros((problem.n_contacts, problem.dimension)), nonnegative=False)
    for _ in range(LEAF_NEWTON_STEPS):
        residual = laws.residual(x)
        if not np.all(np.isfinite(residual)):
            return None
        if np.max(np.abs(residual), initial=0.0) <= FIXED_MODE_RESIDUAL:
            return x[: laws.n].copy()
        x = x - np.linalg.lstsq(laws.jacobian(x), residual, rcond=None)[0]
    return None


def _first_sectors(angle: float, arc: float) -> np.ndarray:
    """Sector bounds from ``angle - arc``: the arc as one sector, then on either side sectors 4x wider each step
    up to :data:`FAR_SECTOR`, and the rest of the turn in sectors of at most that (a leaf next to the arc is the
    last to be excluded: graded sectors save the rounds that halving would take, measured 1-2 fewer)."""
    steps = []
    width = 2.0 * arc
    while (width := min(4.0 * width, FAR_SECTOR)) < FAR_SECTOR:
        steps.append(width)
    rest = 2.0 * np.pi - 2.0 * arc - 2.0 * sum(steps)
    if rest < FAR_SECTOR:
        steps, rest = [], 2.0 * np.pi - 2.0 * arc
    count = int(np.ceil(rest / FAR_SECTOR))
    widths = [2.0 * arc, *steps, *([rest / count] * count), *reversed(steps)]
    bounds = angle - arc + np.concatenate([[0.0], np.cumsum(widths)])
    bounds[-1] = bounds[0] + 2.0 * np.pi  # the whole turn, whatever the rounding of the sum
    return bounds


def _even_sectors() -> np.ndarray:
    count = int(round(2.0 * np.pi / FAR_SECTOR))
    return 2.0 * np.pi * np.arange(count + 1) / count
