"""One catalogue of small cases with answers derived by hand, and the methods that apply to each.

Each :class:`Case` is a scene (built from a dict by :func:`quasistatic.load_scene`),
the derivation of its answer in words (``source``: statics and the
minimum-power principle, worked by hand) and the answer itself: the status,
and for ``solved`` the motion (twists, modes, normal forces), for
``ambiguous`` the kinds of motion that must be listed, for ``jammed`` and
``unstable`` the :class:`quasistatic.Diagnosis`. No expected number was taken
from the library.

:class:`Method` describes a solve method by what it can claim, derived from
the registry :data:`quasistatic.solvers.BACKENDS` (never from a hand-written
list of names), plus ``auto`` as a user calls it and ``auto`` asked for speed
(``certify=False``: the fast path's first motion). ``tests/test_catalogue.py``
runs every case over every method; :func:`methods` gives other test files the
methods with given capabilities, :func:`matches` compares a motion with a
derivation and :func:`laws_hold` checks the laws from the scene data alone.

Conventions: g = 9.81 m/s^2 along -y (2-D, and the frictionless 3-D scenes)
or -z (the frictional 3-D scene); angles counter-clockwise; a contact normal
points into ``body`` and its force acts on ``body``; twists are ``[vx, vy, wz]``
(2-D) or ``[v, omega]`` (3-D) of the com; a ``nan`` twist entry is free (it
varies over a continuum of motions).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

import quasistatic as qs
from quasistatic.solvers import BACKENDS

__all__ = [
    "ABS",
    "BY_NAME",
    "CASES",
    "FREE",
    "G",
    "KNOWN_BUGS",
    "METHODS",
    "REL",
    "Case",
    "Claims",
    "Expected",
    "Method",
    "laws_hold",
    "matches",
    "methods",
    "same",
    "scale_of",
]

G = 9.81
REL, ABS = 1e-6, 1e-9  # relative agreement with a derivation (of the quantity's scale in the case), absolute floor
FREE = math.nan
"""A twist coordinate that varies over a continuum of motions (not checked)."""

Check = Callable[[qs.Motion], None]


# --------------------------------------------------------------------------- what a case expects


@dataclass(frozen=True)
class Expected:
    """One motion (or one kind of motion) derived by hand.

    Attributes
    ----------
    twists : mapping body -> tuple of float
        Each free body's twist; ``FREE`` (nan) where a continuum leaves it free.
    modes : tuple of str or None
        Each contact's mode, in scene order (None: not determined, e.g. inside a continuum).
    normal_forces : tuple of (float or None) or None
        Each contact's normal force [N]; None where the forces do not determine it.
    normal_force_ranges : tuple of (lo, hi or None) or None
        When the normal forces are indeterminate: each contact's range over every
        force distribution consistent with the motion (hi None: unbounded).
    friction_indeterminate : bool
        The normal forces are unique but the friction forces are not (two contacts share a load
        along the line through them): the forces are indeterminate all the same.
    continuum, unbounded : bool
        The motion stands for a continuum of motions (that extends to infinity).
    extremes : tuple of mappings body -> tuple of float
        The extreme twists of a bounded continuum along its free coordinates.
    power_input : float or None
        Power the movers deliver [W].
    check : callable or None
        Further hand-derived relations on the motion (slips, force relations); raises AssertionError.
    """

    twists: Mapping[str, Sequence[float]]
    modes: tuple[str, ...] | None = None
    normal_forces: tuple[float | None, ...] | None = None
    normal_force_ranges: tuple[tuple[float, float | None], ...] | None = None
    friction_indeterminate: bool = False
    continuum: bool = False
    unbounded: bool = False
    extremes: tuple[Mapping[str, Sequence[float]], ...] = ()
    power_input: float | None = None
    check: Check | None = None


@dataclass(frozen=True)
class Case:
    """A small scene with a hand-derived answer.

    Attributes
    ----------
    name : str
    scene : Scene
        Built from a dict by ``qs.load_scene``.
    source : str
        Where the expected answer comes from: the derivation in words.
    status : {"solved", "ambiguous", "jammed", "unstable"}
    motions : tuple of Expected
        ``solved``: the one motion. ``ambiguous``: the kinds of motion that must be listed.
    also : tuple of Expected
        ``ambiguous``: further kinds that are motions too and may be listed (a method
        that finds one motion may return any kind of ``motions + also``).
    diagnosis : Diagnosis or None
        ``jammed``/``unstable``: why no motion exists.
    farkas : tuple of float or None
        ``jammed`` (kinematic): Farkas multipliers per contact, up to a positive scale, that a
        ``farkas`` certificate must carry.
    paper_slow : str or None
        Why the ``paper`` method (a global bilinear program) is too slow here: its pair is skipped with this
        reason (it would only end ``failed`` at its time limit).
    """

    name: str
    scene: qs.Scene
    source: str
    status: str
    motions: tuple[Expected, ...] = ()
    also: tuple[Expected, ...] = ()
    diagnosis: qs.Diagnosis | None = None
    farkas: tuple[float, ...] | None = None
    paper_slow: str | None = None

    def __post_init__(self) -> None:
        assert len(self.source) > 80, f"{self.name}: derive the answer in 'source'"
        assert (self.status in ("jammed", "unstable")) == (self.diagnosis is not None), self.name
        assert (len(self.motions) == 1) if self.status == "solved" else True, self.name
        assert bool(self.motions) == (self.status in ("solved", "ambiguous")), self.name

    def __str__(self) -> str:
        return self.name

    @cached_property
    def frictional(self) -> bool:
        """Some contact has friction (mu > 0 under a friction model other than ``none``)."""
        return not qs.assemble(self.scene).is_frictionless

    @property
    def exact_cones(self) -> bool:
        """Friction on exact 3-D cones: the certified search runs on an inscribed pyramid and refines its motions to
        the circle, so its ``solved`` is not proven unique for the circle (README, ``friction: exact``)."""
        return self.frictional and not self.scene.friction.is_polyhedral(self.scene.dimension)

    @property
    def needs_all_motions(self) -> bool:
        """Only a method that lists every motion claims ``ambiguous``; one that finds one motion may return one of them."""
        return self.status == "ambiguous"

    @property
    def needs_no_motion_proof(self) -> bool:
        """Only a method that proves no motion exists claims ``jammed``/``unstable``; the others report ``failed``."""
        return self.status in ("jammed", "unstable")

    @property
    def needs_certifying(self) -> bool:
        """The answer is reachable only by a certifying method (a ``solved`` one is found by every method)."""
        return self.needs_all_motions or self.needs_no_motion_proof


# --------------------------------------------------------------------------- the methods


@dataclass(frozen=True)
class Claims:
    """What a method claims on one kind of scene (frictional or frictionless).

    Attributes
    ----------
    certifies : bool
        Its ``solved`` is proven unique (``sol.certified``) where the laws are polyhedral (frictionless,
        2-D, a pyramid): on exact 3-D cones no method proves uniqueness (``Case.exact_cones``).
    proves_no_motion : bool
        It claims ``jammed``/``unstable``, with a diagnosis, whenever no motion exists.
    lists_all_motions : bool
        It claims ``ambiguous`` listing every kind of motion whenever there are several.
    """

    certifies: bool
    proves_no_motion: bool
    lists_all_motions: bool


@dataclass(frozen=True)
class Method:
    """A way to call ``qs.solve``, with what it claims on frictional and on frictionless scenes.

    Attributes
    ----------
    id : str
        Test id: the method name, or ``auto-first`` for ``auto`` with ``certify=False``.
    name : str
        What ``solve(method=...)`` takes.
    frictional : bool
        Handles contacts with mu > 0 (a frictionless method refuses them with an error).
    on_frictional, on_frictionless : Claims
        What it claims on each kind of scene.
    options : mapping
        Further keyword arguments of ``solve``.
    """

    id: str
    name: str
    frictional: bool
    on_frictional: Claims
    on_frictionless: Claims
    options: Mapping[str, Any] = field(default_factory=dict)

    def __str__(self) -> str:
        return self.id

    def applies(self, case: Case) -> bool:
        return self.frictional or not case.frictional

    def claims(self, frictional: bool) -> Claims:
        return self.on_frictional if frictional else self.on_frictionless

    def can_claim(self, case: Case) -> bool:
        """Whether this method claims the case's status (else it answers ``failed``, or one motion of several)."""
        claims = self.claims(case.frictional)
        if case.needs_all_motions:
            return claims.lists_all_motions
        if case.needs_no_motion_proof:
            return claims.proves_no_motion
        return True

    def solve(self, scene: qs.Scene | qs.Problem, **options: Any) -> qs.Solution:
        return qs.solve(scene, method=self.name, **{**self.options, **options})


NOTHING = Claims(certifies=False, proves_no_motion=False, lists_all_motions=False)


def _backend_claims(backend: Any) -> Claims:
    """A registered backend's claims, the same on every scene it takes. A frictionless backend solves a
    linear program whose optimal motions form one convex set, which it describes completely: it lists
    every motion (``solve`` accepts ``all_solutions`` for it)."""
    lists = backend.certifies and (backend.lists_all_motions or not backend.frictional)
    return Claims(certifies=backend.certifies, proves_no_motion=backend.certifies, lists_all_motions=lists)


def _registry_methods() -> list[Method]:
    """Every available registered backend, then ``auto`` (as a user calls it) and ``auto-first``
    (``certify=False``), whose claims follow from the registry and from how ``auto`` chooses (``solve``'s
    docstring): a frictionless scene goes to a frictionless backend when one is registered; a frictional
    one to a certifying backend that lists every motion, or with ``certify=False`` to the backends that
    find one motion first and to that certifying one when they find none."""
    backends = [b for b in BACKENDS.values() if b.available]
    methods = [Method(b.name, b.name, b.frictional, _backend_claims(b), _backend_claims(b)) for b in backends]
    frictional = any(b.frictional for b in backends)
    listing = next((_backend_claims(b) for b in backends if b.frictional and b.certifies and b.lists_all_motions), NOTHING)
    frictionless = next((_backend_claims(b) for b in backends if not b.frictional), listing)
    methods.append(Method("auto", "auto", frictional, listing, frictionless))
    one_motion_first = any(b.frictional and not b.certifies for b in backends)
    first = Claims(False, listing.proves_no_motion, False) if one_motion_first else listing
    methods.append(Method("auto-first", "auto", frictional, first, frictionless, {"certify": False}))
    return methods


METHODS: list[Method] = _registry_methods()


def methods(
    *,
    frictional: bool,
    certifying: bool | None = None,
    all_motions: bool | None = None,
    no_motion: bool | None = None,
) -> list[Method]:
    """The methods that take scenes with (``frictional=True``) or without friction, with the given claims on them.

    ``certifying``: proves ``solved`` unique; ``all_motions``: lists every motion; ``no_motion``: proves
    ``jammed``/``unstable``; None: either. Derived from the registry, never a list of names.
    """
    chosen = []
    for method in METHODS:
        claims = method.claims(frictional)
        if frictional and not method.frictional:
            continue
        if certifying is not None and claims.certifies != certifying:
            continue
        if all_motions is not None and claims.lists_all_motions != all_motions:
            continue
        if no_motion is not None and claims.proves_no_motion != no_motion:
            continue
        chosen.append(method)
    return chosen


# --------------------------------------------------------------------------- scene helpers


def _floats(array: Any) -> list[float]:
    return [float(x) for x in np.asarray(array, dtype=float).ravel()]


def contact(body: str, other: str, point: Any, normal: Any, mu: float = 0.0, **extra: Any) -> dict[str, Any]:
    return {"body": body, "other": other, "point": _floats(point), "normal": _floats(normal), "mu": mu, **extra}


def scene_data(dimension: int, bodies: dict, movers: dict, contacts: list, *, up: int | None = None, **extra: Any) -> dict[str, Any]:
    """A scene dict with gravity g along -y (2-D) or along -z (3-D; ``up=1`` for -y)."""
    gravity = [0.0] * dimension
    gravity[dimension - 1 if up is None else up] = -G
    return {"quasistatic": 1, "dimension": dimension, "gravity": gravity, "bodies": bodies, "movers": movers, "contacts": contacts, **extra}


def _case(name: str, data: dict[str, Any], source: str, status: str, *motions: Expected, **extra: Any) -> Case:
    return Case(name, qs.load_scene(data), " ".join(source.split()), status, tuple(motions), **extra)


def _close(got: float, want: float, rel: float = 1e-6, abs_: float = 1e-9) -> bool:
    return abs(got - want) <= max(rel * abs(want), abs_)


def _twist(x: Sequence[float]) -> dict[str, tuple[float, ...]]:
    return {"block": tuple(float(v) for v in x)}


# --------------------------------------------------------------------------- comparing a motion with its derivation


def same(got: float, want: float, scale: float = 0.0) -> bool:
    """Equal to REL of the larger of ``want`` and the quantity's scale in the case (e.g. the largest force)."""
    return abs(got - want) <= REL * max(abs(want), scale) + ABS


def scale_of(values: Sequence[float | None]) -> float:
    return max([abs(v) for v in values if v is not None and not math.isnan(v)] + [0.0])


def _twist_matches(got: Mapping[str, np.ndarray], want: Mapping[str, Sequence[float]]) -> bool:
    if set(got) != set(want):
        return False
    scale = scale_of([v for values in want.values() for v in values])
    for name, values in want.items():
        for g, w in zip(np.asarray(got[name], dtype=float), values, strict=True):
            if not math.isnan(w) and not same(float(g), w, scale):
                return False
    return True


def _within_extremes(got: Mapping[str, np.ndarray], extremes: Sequence[Mapping[str, Sequence[float]]]) -> bool:
    """Each coordinate of ``got`` lies between the extreme twists of a bounded continuum."""
    for name in got:
        stack = np.array([e[name] for e in extremes], dtype=float)
        lo, hi = stack.min(axis=0), stack.max(axis=0)
        if np.any(got[name] < lo - ABS) or np.any(got[name] > hi + ABS):
            return False
    return True


def matches(motion: qs.Motion, kind: Expected, *, exact: bool) -> bool:
    """Whether ``motion`` is of the hand-derived ``kind``.

    ``exact``: it also has the kind's shape (a single motion, or a continuum bounded or not with the
    given extreme twists); otherwise it may be one motion inside a continuum kind.
    """
    if not _twist_matches(motion.twists, kind.twists):
        return False
    if kind.modes is not None and motion.modes != kind.modes:
        return False
    if kind.normal_forces is not None:
        forces, scale = [c.normal_force for c in motion.contacts], scale_of(kind.normal_forces)
        if any(w is not None and not same(g, w, scale) for g, w in zip(forces, kind.normal_forces, strict=True)):
            return False
    if kind.power_input is not None and not same(motion.power.input, kind.power_input):
        return False
    if kind.extremes and not _within_extremes(motion.twists, kind.extremes):
        return False
    if kind.check is not None:
        try:
            kind.check(motion)
        except AssertionError:
            return False
    if exact:
        if (motion.continuum, motion.unbounded) != (kind.continuum, kind.unbounded):
            return False
        for extreme in motion.extreme_twists:
            if not _twist_matches(extreme, kind.twists):
                return False
        if kind.extremes:
            got = sorted(tuple(np.concatenate([e[n] for n in sorted(e)])) for e in motion.extreme_twists)
            want = sorted(tuple(np.concatenate([np.asarray(e[n], dtype=float) for n in sorted(e)])) for e in kind.extremes)
            if len(got) != len(want) or not np.allclose(got, want, rtol=0, atol=REL * scale_of(np.ravel(want).tolist()) + ABS):
                return False
    return True


def describe(motion: qs.Motion, *kinds: Expected) -> str:
    got = {n: np.round(t, 9).tolist() for n, t in motion.twists.items()}
    forces = [round(c.normal_force, 6) for c in motion.contacts]
    shape = "continuum" if motion.continuum else "motion"
    return f"got {shape} {got} {motion.modes} forces {forces} power {motion.power.input:.6g}; expected one of {kinds}"


def describe_all(motions: Sequence[qs.Motion], kind: Expected) -> str:
    return "\n".join([f"no listed motion is {kind}", *(describe(m) for m in motions)])


# --------------------------------------------------------------------------- the laws, from the scene data alone


def _cross(r: np.ndarray, f: np.ndarray) -> np.ndarray:
    return np.atleast_1d(np.cross(r, f)) if len(r) == 3 else np.array([r[0] * f[1] - r[1] * f[0]])


def _point_velocity(twist: np.ndarray, origin: np.ndarray, point: np.ndarray) -> np.ndarray:
    d = len(point)
    v, w = twist[:d], twist[d:]
    r = point - origin
    return v + (np.cross(w, r) if d == 3 else w[0] * np.array([-r[1], r[0]]))


def laws_hold(scene: qs.Scene, motion: qs.Motion) -> None:
    """Statics, cones, kinematics, modes and maximum dissipation, recomputed from the scene alone.

    Each body's forces and moments balance; each force lies in its exact friction cone (a pyramid is
    inscribed in it); no contact penetrates and a loaded one does not open; each reported mode is the
    one the relative velocity says; a sliding contact's friction lies on the cone exactly opposite the
    slip (for a pyramid: opposes it).

    Forces act on ``body`` and, reversed, on ``other`` when it is a free body; a mover's point moves
    with its twist about its origin (the world origin when not given), a robot link's point at the
    contact's jacobian times the robot's joint velocities.
    """
    d = scene.dimension
    frictionless = scene.friction.kind == "none"
    pyramid = scene.friction.kind == "pyramid"
    com = {b.name: np.asarray(b.com, dtype=float) for b in scene.bodies}
    total = {b.name: np.zeros(3 if d == 2 else 6) for b in scene.bodies}
    for b in scene.bodies:
        total[b.name][:d] += b.mass * np.asarray(scene.gravity)
        if b.wrench is not None:
            total[b.name] += np.asarray(b.wrench)
    force_scale = max(
        [abs(b.mass) * float(np.linalg.norm(scene.gravity)) for b in scene.bodies] + [c.normal_force for c in motion.contacts] + [1e-12]
    )
    speeds = (
        [float(np.max(np.abs(t))) for t in motion.twists.values()]
        + [float(np.max(np.abs(r.joint_velocities), initial=0.0)) for r in scene.robots]
        + [float(np.max(np.abs(m.twist))) for m in scene.movers if m.twist is not None]
    )
    speed = max([*speeds, 0.0])
    length = max([float(np.max(np.abs(c.point))) for c in scene.contacts] + [float(np.max(np.abs(x))) for x in com.values()] + [1e-3])
    for data, result in zip(scene.contacts, motion.contacts, strict=True):
        n, p, f = np.asarray(data.normal, dtype=float), np.asarray(data.point, dtype=float), np.asarray(result.force, dtype=float)
        total[data.body] += np.concatenate([f, _cross(p - com[data.body], f)])
        if data.other in total:
            total[data.other] -= np.concatenate([f, _cross(p - com[data.other], f)])
        # cone
        f_n = float(f @ n)
        f_t = f - f_n * n
        mu = 0.0 if frictionless else data.mu
        assert f_n >= -REL * force_scale, (data, f_n)
        assert np.linalg.norm(f_t) <= mu * f_n + REL * force_scale, (data, f, mu)
        # kinematics and modes
        v_body = _point_velocity(np.asarray(motion.twists[data.body]), com[data.body], p)
        if data.other in com:
            v_other = _point_velocity(np.asarray(motion.twists[data.other]), com[data.other], p)
        elif scene.mover(data.other).robot is not None:  # a robot link: its point moves at jacobian . joint velocities
            robot = scene.robot(scene.mover(data.other).robot or "")
            v_other = np.asarray(data.jacobian, dtype=float) @ np.asarray(robot.joint_velocities, dtype=float)
        else:
            mover = scene.mover(data.other)
            twist = np.zeros(3 if d == 2 else 6) if mover.twist is None else np.asarray(mover.twist, dtype=float)
            origin = np.zeros(d) if mover.origin is None else np.asarray(mover.origin, dtype=float)
            v_other = _point_velocity(twist, origin, p)
        u = v_body - v_other
        u_n = float(u @ n)
        u_t = u - u_n * n
        tol = ABS + REL * speed * max(1.0, length)  # [m/s]
        assert u_n >= -tol, (data, u)
        assert abs(f_n * u_n) <= force_scale * tol, (data, f_n, u_n)
        mode = "separating" if u_n > tol else "rolling" if np.linalg.norm(u_t) <= tol else "sliding"
        assert result.mode == mode, (data, result.mode, mode, u)
        if mode == "sliding" and mu > 0 and pyramid:  # a pyramid's friction sits at a vertex or face: it opposes the slip
            assert float(f_t @ u_t) <= REL * force_scale * float(np.linalg.norm(u_t)), (data, f_t, u_t)
        elif mode == "sliding" and mu > 0:  # maximum dissipation: friction on the cone, opposite the slip
            target = -mu * f_n * u_t / np.linalg.norm(u_t)
            assert np.linalg.norm(f_t - target) <= REL * force_scale, (data, f_t, target)
    for name, wrench in total.items():
        forces, moments = wrench[:d], wrench[d:]
        assert np.linalg.norm(forces) <= REL * force_scale, (name, wrench)
        assert np.linalg.norm(moments) <= REL * force_scale * max(1.0, length), (name, wrench)


# =========================================================================== frictional, 2-D

# --------------------------------------------------------------------------- a block on a slope

W, H, M, MU = 0.2, 0.1, 1.0, 0.5  # block width along the slope, height, mass, friction
Y_PUSH = 0.02  # pusher contact height above the slope


def slope_data(alpha_deg: float, push: float | None = None, w: float = W, h: float = H, mu: float = MU) -> dict[str, Any]:
    """Block (w x h, mass M) on a fixed slope at alpha, two corner contacts, friction mu.

    With ``push`` (m/s along the slope, + uphill), a frictionless pusher touches the face that leads
    the motion, Y_PUSH above the slope.
    """
    a = math.radians(alpha_deg)
    t, n = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
    contacts = [contact("block", "slope", -w / 2 * t, n, mu), contact("block", "slope", w / 2 * t, n, mu)]
    movers: dict[str, Any] = {"slope": None}
    if push is not None:
        side = -1.0 if push > 0 else 1.0
        contacts.append(contact("block", "pusher", side * w / 2 * t + Y_PUSH * n, -side * t))
        movers["pusher"] = {"twist": [*_floats(push * t), 0.0]}
    return scene_data(2, {"block": {"mass": M, "com": _floats(h / 2 * n)}}, movers, contacts)


def _slope_rest() -> Case:
    a = math.radians(20.0)
    n1 = M * G * (math.cos(a) + H / W * math.sin(a)) / 2
    n2 = M * G * (math.cos(a) - H / W * math.sin(a)) / 2
    return _case(
        "slope-rest-20",
        slope_data(20.0),
        """Block at rest on a 20 deg slope, mu = 0.5: tan 20 deg = 0.364 < mu and < w/h = 2, so it
        neither slides nor tips. Slope frame (x uphill): total friction M g sin a = 3.355 N uphill,
        total normal M g cos a = 9.218 N; moments about the com (corners at x = -+w/2, y = -h/2):
        (N2 - N1) w/2 + F h/2 = 0 with F = M g sin a, so N1 - N2 = F h/w = 1.678 N:
        N1 = M g (cos a + (h/w) sin a)/2 = 5.448 N (downhill corner), N2 = 3.770 N. Both rolling.
        The friction is shared: F1 + F2 = F fixes only the sum (both act along the line of the
        corners, so the moments do not split it), and any split within the cones holds: the forces
        are indeterminate, with fixed normal forces.""",
        "solved",
        Expected(_twist([0, 0, 0]), ("rolling", "rolling"), (n1, n2), power_input=0.0, friction_indeterminate=True),
    )


def _slope_unstable(name: str, w: float, h: float, mu: float, why: str) -> Case:
    return _case(
        name,
        slope_data(30.0, w=w, h=h, mu=mu),
        f"""A block rests on a slope at a iff tan a <= min(mu, w/h) (sliding, tipping). At 30 deg,
        tan a = 0.577: {why} No force in the friction cones balances the weight.""",
        "unstable",
        diagnosis=qs.Diagnosis.NO_EQUILIBRIUM,
    )


def _slope_push(speed: float) -> Case:
    """Pushed along a 20 deg slope at |speed| = 0.01 m/s, up (speed > 0) or down."""
    a = math.radians(20.0)
    s = 1.0 if speed > 0 else -1.0
    weight_n, weight_t = M * G * math.cos(a), M * G * math.sin(a)
    push = M * G * (s * math.sin(a) + MU * math.cos(a))
    difference = s * (MU * H * weight_n - (H - 2 * Y_PUSH) * push) / W  # N2 - N1
    n1, n2 = (weight_n - difference) / 2, (weight_n + difference) / 2
    direction = "up" if s > 0 else "down"
    return _case(
        f"slope-push-{direction}-20",
        slope_data(20.0, push=speed),
        f"""A frictionless pusher moves the block {direction} a 20 deg slope (mu = 0.5) at 0.01 m/s.
        The block translates with the pusher (pusher rolling), both supports slide, friction
        mu N_i opposing the slip. Along the slope P = M g (s sin a + mu cos a) with s = +1 up,
        -1 down: {push:.4f} N; normal N1 + N2 = M g cos a. Moments about the com (supports at
        (-+w/2, -h/2), pusher at (-s w/2, {Y_PUSH} - h/2)): N2 - N1 = s (mu h M g cos a - (h - 2 {Y_PUSH}) P)/w,
        so N1 = {n1:.4f} N, N2 = {n2:.4f} N. Friction dissipates P v - M g v sin a s > 0.""",
        "solved",
        Expected(
            _twist([speed * math.cos(a), speed * math.sin(a), 0.0]),
            ("sliding", "sliding", "rolling"),
            (n1, n2, push),
            power_input=push * abs(speed),
            check=lambda motion: _dissipates(motion, push * abs(speed) - s * weight_t * abs(speed)),
        ),
    )


def _dissipates(motion: qs.Motion, dissipation: float) -> None:
    assert motion.power.dissipation > 0
    assert _close(motion.power.dissipation, dissipation), (motion.power.dissipation, dissipation)


# --------------------------------------------------------------------------- a box pushed low or high

BW, BH, BM, BMU, V = 0.2, 0.4, 2.0, 0.5, 0.01


def pushed_box_data(h: float) -> dict[str, Any]:
    return scene_data(
        2,
        {"block": {"mass": BM, "com": [0.0, BH / 2]}},
        {"floor": None, "pusher": {"twist": [V, 0.0, 0.0]}},
        [
            contact("block", "floor", [-BW / 2, 0.0], [0.0, 1.0], BMU),
            contact("block", "floor", [BW / 2, 0.0], [0.0, 1.0], BMU),
            contact("block", "pusher", [-BW / 2, h], [1.0, 0.0]),
        ],
    )


def _box_low() -> Case:
    weight = BM * G
    return _case(
        "box-push-low",
        pushed_box_data(0.15),
        """A 0.2 x 0.4 box (2 kg, mu = 0.5) pushed at 0.01 m/s by a frictionless pusher at h = 0.15
        < w/(2 mu) = 0.2: it translates, both floor contacts sliding, P = mu m g = 9.81 N. Moments
        about the com (0, 0.2): rear corner -0.1 N1 - 0.2 (0.5 N1) = -0.2 N1, front corner
        0.1 N2 - 0.1 N2 = 0, pusher -(h - 0.2) P: N1 = (0.2 - h) P / 0.2 = 2.4525 N, N2 = m g - N1 = 17.1675 N.""",
        "solved",
        Expected(
            _twist([V, 0, 0]), ("sliding", "sliding", "rolling"), (2.4525, weight - 2.4525, BMU * weight), power_input=BMU * weight * V
        ),
    )


def _box_high() -> Case:
    return _case(
        "box-push-high",
        pushed_box_data(0.25),
        """The same box pushed at h = 0.25 > 0.2 tips about its front corner (0.1, 0). The pusher point
        (-0.1, 0.25) must move at v in x: -w (0.25) = v, w = -v/h = -0.04 rad/s; the com velocity
        w x (com - corner) = (0.008, 0.004); the pusher point moves up at 0.008 along the frictionless
        pusher (sliding), the rear corner lifts (separating), the front one rolls. Moments about the
        corner: P h = m g w/2, P = 7.848 N; vertical balance: N_front = m g = 19.62 N, whose friction
        7.848 N <= mu m g = 9.81 N keeps it rolling.""",
        "solved",
        Expected(_twist([0.008, 0.004, -0.04]), ("separating", "rolling", "sliding"), (0.0, BM * G, 7.848), power_input=7.848 * V),
    )


# --------------------------------------------------------------------------- two fingers

GRASP_M, GRASP_A = 0.5, 0.05  # box mass, half-width


def grasp_data(mu: float, dy: float = 0.0) -> dict[str, Any]:
    """Box (half-width 0.05, 0.5 kg, com at the origin) between two fingers moving up at 0.01 m/s, no squeeze."""
    up = {"twist": [0.0, 0.01, 0.0]}
    return scene_data(
        2,
        {"block": {"mass": GRASP_M, "com": [0.0, 0.0]}},
        {"left": up, "right": up},
        [
            contact("block", "left", [-GRASP_A, -dy / 2], [1.0, 0.0], mu),
            contact("block", "right", [GRASP_A, dy / 2], [-1.0, 0.0], mu),
        ],
    )


def _squeezed_at_least(least: float) -> Check:
    def check(motion: qs.Motion) -> None:
        left, right = (c.normal_force for c in motion.contacts)
        assert _close(left, right), (left, right)  # x balance
        assert left >= least * (1 - 1e-6), (left, least)

    return check


def _grasp_lift() -> Case:
    squeeze = GRASP_M * G / (2 * 0.5)
    return _case(
        "grasp-lift-mu05",
        grasp_data(0.5),
        """Two level fingers (mu = 0.5) rise at 0.01 m/s beside a 0.5 kg box. x balance: both squeeze
        with the same N; moments about the com: the two friction forces are equal, m g/2 each. The lift
        (both rolling, twist (0, 0.01, 0)) needs m g/2 <= mu N, i.e. any N >= m g/(2 mu) = 4.905 N; the
        box slipping down (both sliding, friction on the cone) needs N = 4.905 N exactly, at any slip
        speed and turning rate (an unbounded continuum); the fingers' normals along x keep vx = 0. Both
        satisfy the laws: ambiguous, listing both. With N = 4.905 N one finger may also roll while the
        other slides (continua too).""",
        "ambiguous",
        Expected(_twist([0.0, 0.01, 0.0]), ("rolling", "rolling"), check=_squeezed_at_least(squeeze)),
        Expected(_twist([0.0, FREE, FREE]), ("sliding", "sliding"), (squeeze, squeeze), continuum=True, unbounded=True),
        also=(
            Expected(_twist([0.0, FREE, FREE]), ("rolling", "sliding"), (squeeze, squeeze)),
            Expected(_twist([0.0, FREE, FREE]), ("sliding", "rolling"), (squeeze, squeeze)),
        ),
    )


def _grasp_unstable(name: str, mu: float, dy: float, why: str) -> Case:
    return _case(
        name,
        grasp_data(mu, dy),
        f"""Two fingers rise beside a 0.5 kg box (half-width 0.05). {why} No squeeze holds the box.""",
        "unstable",
        diagnosis=qs.Diagnosis.NO_EQUILIBRIUM,
    )


# --------------------------------------------------------------------------- a finger dragging a box


def _finger_drags() -> Case:
    least = 0.2 * 1.0 * G / (0.8 - 0.2)  # N_f at which both frictions are at their limits
    total, friction = 1.0 * G + least, 0.8 * least  # table load, finger friction at that N_f
    data = scene_data(
        2,
        {"block": {"mass": 1.0, "com": [0.0, 0.05]}},
        {"table": None, "finger": {"twist": [0.01, 0.0, 0.0]}},
        [
            contact("block", "table", [-0.1, 0.0], [0.0, 1.0], 0.2),
            contact("block", "table", [0.1, 0.0], [0.0, 1.0], 0.2),
            contact("block", "finger", [0.0, 0.1], [0.0, -1.0], 0.8),
        ],
    )

    def dragged(motion: qs.Motion) -> None:
        assert motion.contacts[2].normal_force >= least * (1 - 1e-6)

    def stays(motion: qs.Motion) -> None:
        assert motion.contacts[2].normal_force <= least * (1 + 1e-6)

    return _case(
        "finger-drags-box",
        data,
        """A finger (mu_f = 0.8) on top of a box (0.2 x 0.1, 1 kg) on a table (mu_s = 0.2) moves
        sideways at 0.01 m/s. The rigid squeeze N_f is indeterminate: the finger drags the box
        (finger rolling, supports sliding, twist (0.01, 0, 0)) iff mu_f N_f >= mu_s (m g + N_f),
        i.e. N_f >= 3.27 N; the box stays (finger sliding over it, supports rolling) iff
        N_f <= 3.27 N. Both are listed. At N_f = 3.27 N exactly both frictions are at their limits and
        the box may also slide at any speed between 0 and the finger's (every contact sliding): a
        bounded continuum, which may be listed too. Its forces are determined: the finger's friction
        mu_f N_f = 2.616 N acts 0.05 above the com, the table's 0.05 below; moments about the com:
        0.1 (N_front - N_rear) = 0.05 (2.616) + 0.05 (2.616), so N_rear = 5.232 N, N_front = 7.848 N.""",
        "ambiguous",
        Expected(_twist([0.01, 0.0, 0.0]), ("sliding", "sliding", "rolling"), check=dragged),
        Expected(_twist([0.0, 0.0, 0.0]), ("rolling", "rolling", "sliding"), check=stays),
        also=(
            Expected(
                _twist([FREE, 0.0, 0.0]),
                ("sliding",) * 3,
                ((total - friction) / 2, (total + friction) / 2, least),
                continuum=True,
                extremes=(_twist([0.0, 0.0, 0.0]), _twist([0.01, 0.0, 0.0])),
            ),
        ),
    )


# --------------------------------------------------------------------------- a friction wedge


def wedge_data(mu_floor: float, mu_finger: float) -> dict[str, Any]:
    """A 1 kg box (0.1 m, com (0, 0.05)) on a floor, pushed low on its rear face (0.02 up) by a finger
    moving forward and down at (0.01, -0.01) m/s."""
    return scene_data(
        2,
        {"box": {"mass": 1.0, "com": [0.0, 0.05]}},
        {"floor": {}, "finger": {"twist": [0.01, -0.01, 0.0]}},
        [
            contact("box", "floor", [-0.05, 0.0], [0.0, 1.0], mu_floor),
            contact("box", "floor", [0.05, 0.0], [0.0, 1.0], mu_floor),
            contact("box", "finger", [-0.05, 0.02], [1.0, 0.0], mu_finger),
        ],
    )


WEDGE = """The finger must slide down the box's rear face, so its friction mu_f N pushes the box
down; the floor's friction mu (m g + mu_f N) must not exceed N: the box slides iff mu mu_f < 1,
else friction wedges it."""


def _wedge_slides() -> Case:
    mu, mu_f = 0.9, 1.0
    push = mu * G / (1 - mu * mu_f)
    floor = G + mu_f * push
    difference = mu * floor - push * (mu_f + 0.6)  # N2 - N1
    n1, n2 = (floor - difference) / 2, (floor + difference) / 2
    return _case(
        "wedge-slides",
        wedge_data(mu, mu_f),
        WEDGE
        + f"""With mu = 0.9, mu_f = 1: mu mu_f = 0.9 < 1, the box slides forward at the finger's
        0.01 m/s (all three contacts sliding), N = mu m g / (1 - mu mu_f) = {push:.2f} N, floor total
        m g + mu_f N = {floor:.2f} N. Moments about the com: finger N (0.05 mu_f + 0.03), floor
        -+0.05 N_i - 0.05 mu N_i: N2 - N1 = mu (N1 + N2) - N (mu_f + 0.6), N1 = {n1:.3f} N, N2 = {n2:.3f} N.""",
        "solved",
        Expected({"box": (0.01, 0.0, 0.0)}, ("sliding",) * 3, (n1, n2, push), power_input=push * 0.01 + mu_f * push * 0.01),
    )


def _wedge_slides_3d() -> Case:
    from quasistatic.tools.validation import extrude

    mu, mu_f = 0.9, 1.0
    push = mu * G / (1 - mu * mu_f)
    floor = G + mu_f * push
    difference = mu * floor - push * (mu_f + 0.6)
    n1, n2 = (floor - difference) / 2, (floor + difference) / 2
    rear, front = (n1 / 2 - n2 / 2, n1 / 2 + n2 / 2), (0.0, n2)
    return _case(
        "wedge-slides-3d",
        extrude(wedge_data(mu, mu_f), 0.1),
        """wedge-slides extruded along z (depth 0.1: each contact doubled at z = -+0.05), exact 3-D cones.
        The box slides as in 2-D, twist (0.01, 0, 0, 0, 0, 0), every contact sliding, each pair carrying
        the planar force. Out of the plane, with d_i = N_i(z+) - N_i(z-): the moment about x gives
        d_rear + d_front - mu_f d_finger = 0, about y -mu (d_rear + d_front) + d_finger = 0; since
        mu mu_f != 1, d_finger = 0 (the finger pair carries N/2 each) and d_rear = -d_front is free:
        rear contacts in [(N1 - N2)/2, (N1 + N2)/2], front ones in [0, N2].""",
        "solved",
        Expected(
            {"box": (0.01, 0.0, 0.0, 0.0, 0.0, 0.0)},
            ("sliding",) * 6,
            (None, None, None, None, push / 2, push / 2),
            normal_force_ranges=(rear, rear, front, front, (push / 2, push / 2), (push / 2, push / 2)),
            power_input=push * 0.01 + mu_f * push * 0.01,
        ),
        paper_slow="the paper's bilinear program on six exact 3-D cones does not finish in SCIP's 60 s limit (failed after 120 s)",
    )


def _wedge_jammed() -> Case:
    return _case(
        "wedge-jammed",
        wedge_data(1.2, 1.0),
        WEDGE
        + """With mu = 1.2, mu_f = 1: mu mu_f = 1.2 > 1: the box could rest, but friction
        wedges it against the commanded motion (jammed, wedged).""",
        "jammed",
        diagnosis=qs.Diagnosis.WEDGED,
    )


# =========================================================================== frictional, 3-D


def puck_data(angle_deg: float = 30.0, friction: str = "exact") -> dict[str, Any]:
    """A puck (1 kg, com 0.05 above the table) on four support points (+-0.05 on x and y), mu = 0.5,
    pushed through its centre by a frictionless finger moving at 0.01 m/s along d = (cos a, sin a, 0)."""
    a = math.radians(angle_deg)
    d = np.array([math.cos(a), math.sin(a), 0.0])
    supports = [[0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [-0.05, 0.0, 0.0], [0.0, -0.05, 0.0]]
    return scene_data(
        3,
        {"block": {"mass": 1.0, "com": [0.0, 0.0, 0.05]}},
        {"table": None, "finger": {"twist": [*_floats(0.01 * d), 0.0, 0.0, 0.0]}},
        [*(contact("block", "table", p, [0, 0, 1], 0.5) for p in supports), contact("block", "finger", [*(-0.05 * d[:2]), 0.05], d)],
        friction=friction,
    )


def _puck() -> Case:
    a = math.radians(30.0)
    d = np.array([math.cos(a), math.sin(a), 0.0])
    push = 0.5 * G
    low = 0.05 * push / 0.05 * d  # N(+x) - N(-x), N(+y) - N(-y)

    def maximum_dissipation(motion: qs.Motion) -> None:
        supports = motion.contacts[:4]
        assert _close(sum(c.normal_force for c in supports), G)
        pressure = sum(
            c.normal_force * np.array(p[:2]) for c, p in zip(supports, [[0.05, 0], [0, 0.05], [-0.05, 0], [0, -0.05]], strict=True)
        )
        assert np.allclose(pressure / G, 0.025 * d[:2], atol=1e-9)  # centre of pressure 0.025 ahead, on the line of d
        for c in supports:  # friction exactly opposite the slip, on the cone
            tangential = c.force[:2]
            assert abs(tangential[0] * d[1] - tangential[1] * d[0]) <= 1e-6 * G, (tangential, d)
            assert tangential @ d[:2] <= 0
            assert _close(float(np.linalg.norm(tangential)), 0.5 * c.normal_force, abs_=1e-6 * G)

    # Null vector (1, -1, 1, -1) over (+x, +y, -x, -y): N(+x) = t, N(-x) = t - low_x, N(+y) = S - t, N(-y) = S - t - low_y
    total = (G + low[0] + low[1]) / 2  # N(+x) + N(+y)
    ranges = ((low[0], total - low[1]), (low[1], total - low[0]), (0.0, total - low[0] - low[1]), (0.0, total - low[0] - low[1]))
    return _case(
        "puck-slip-off-axis-3d",
        puck_data(),
        """Exact 3-D cones, the puck pushed at 30 deg from x: every support's friction opposes its slip,
        so with the puck translating along d every friction force is -mu N_i d, together -mu m g d; the
        frictionless finger pushes along d with P = mu m g = 4.905 N: balance along and across d holds,
        so the puck translates with the finger at 0.01 m/s along d, supports sliding, finger rolling.
        The friction acts 0.05 below the com: its moment is carried by the normal forces, whose centre
        of pressure lies 0.025 m ahead of the com along d (no yaw moment). Four supports, three
        equations: N(+x) - N(-x) = 4.905 d_x, N(+y) - N(-y) = 4.905 d_y, sum = m g, null vector
        (1, -1, 1, -1): ranges N(+x) in [4.248, 5.803], N(+y) in [2.453, 4.007], N(-x), N(-y) in [0, 1.555].""",
        "solved",
        Expected(
            _twist([*(0.01 * d), 0, 0, 0]),
            ("sliding",) * 4 + ("rolling",),
            (None, None, None, None, push),
            normal_force_ranges=(*ranges, (push, push)),
            power_input=push * 0.01,
            check=maximum_dissipation,
        ),
    )


# =========================================================================== frictionless, 2-D

ALPHA = math.radians(30.0)
T = np.array([math.cos(ALPHA), math.sin(ALPHA)])  # uphill along the slope
N = np.array([-math.sin(ALPHA), math.cos(ALPHA)])  # slope normal, into the block
SW, SH, SM = 0.4, 0.2, 2.0  # block width along the slope, height, mass
YF = SH / 4  # finger height above the slope on the downhill face


def frictionless_data(dimension: int = 2, **extra: Any) -> dict[str, Any]:
    return scene_data(dimension, {}, {}, [], up=1, friction="none") | extra


def held_slope_data(speed: float = 0.0, finger: bool = True) -> dict[str, Any]:
    """Block on a fixed frictionless slope at 30 deg; a finger on its downhill face moving uphill at ``speed``.

    Block frame: origin at the middle of its bottom face (the world origin), x along T, y along N.
    Slope contacts at x = -SW/2 and +SW/2, finger at (-SW/2, YF) with normal +T.
    """
    contacts = [contact("block", "slope", -SW / 2 * T, N), contact("block", "slope", SW / 2 * T, N)]
    if finger:
        contacts.append(contact("block", "finger", -SW / 2 * T + YF * N, T))
    return frictionless_data(
        bodies={"block": {"mass": SM, "com": _floats(SH / 2 * N)}},
        movers={"slope": {}, "finger": {"twist": [*_floats(speed * T), 0.0]}},
        contacts=contacts,
    )


HELD = """Statics in the block frame (x along T, y along N, origin at the bottom middle):
along T: F = M g sin a; along N: N1 + N2 = M g cos a; moments about the origin (N1 at (-W/2, 0),
N2 at (W/2, 0), F at (-W/2, YF), gravity (-M g sin a, -M g cos a) at (0, H/2)):
N2 - N1 = 2 F (YF - H/2) / W. All three positive and the contact wrenches independent, so the velocity
LP has a unique optimum with every constraint active."""


def held_slope_forces() -> tuple[float, float, float]:
    """(N1, N2, F) of HELD."""
    f = SM * G * math.sin(ALPHA)
    difference = 2.0 * f * (YF - SH / 2) / SW
    total = SM * G * math.cos(ALPHA)
    return (total - difference) / 2, (total + difference) / 2, f


def _normal_directions(*normals: Any) -> Check:
    """Frictionless: every force lies along its contact normal."""

    def check(motion: qs.Motion) -> None:
        for c, n in zip(motion.contacts, normals, strict=True):
            assert np.allclose(c.force, c.normal_force * np.asarray(n, dtype=float), rtol=1e-6, atol=1e-9)

    return check


def _held_rest() -> Case:
    return _case(
        "held-slope-rest",
        held_slope_data(),
        HELD + " At rest: Jn q = 0 gives q = 0, all three contacts rolling, no power.",
        "solved",
        Expected(_twist([0, 0, 0]), ("rolling",) * 3, held_slope_forces(), power_input=0.0, check=_normal_directions(N, N, T)),
    )


def _held_pushed() -> Case:
    s = 0.05
    forces = held_slope_forces()

    def slips(motion: qs.Motion) -> None:
        _normal_directions(N, N, T)(motion)
        for c in motion.contacts[:2]:
            assert np.allclose(c.slip, s * T, atol=1e-9) and abs(c.normal_velocity) <= 1e-9
        assert np.allclose(motion.contacts[2].slip, 0.0, atol=1e-9)
        assert _close(motion.power.gravity, SM * G * s * math.sin(ALPHA))
        assert abs(motion.power.dissipation) <= 1e-9

    return _case(
        "held-slope-pushed",
        held_slope_data(s),
        HELD
        + """ The finger moves uphill at s = 0.05 m/s: the equilibrium equations do not depend on
        velocities, so the same three constraints stay active: v.N = 0 at both slope points gives w = 0,
        and v.T = s. The block translates at s T; the slope contacts slide (slip s T), the finger rolls.
        Power: F s = M g s sin a, the rate of potential energy; nothing dissipated.""",
        "solved",
        Expected(_twist([*(s * T), 0.0]), ("sliding", "sliding", "rolling"), forces, power_input=forces[2] * s, check=slips),
    )


def _slope_alone() -> Case:
    return _case(
        "frictionless-slope-alone",
        held_slope_data(finger=False),
        """The frictionless slope without the finger: nothing balances M g sin a along the slope. The twist
        (-T, 0) keeps both slope contacts closed (N.d = 0) and lowers the block: the minimum-power LP is
        unbounded, no equilibrium exists.""",
        "unstable",
        diagnosis=qs.Diagnosis.NO_EQUILIBRIUM,
    )


def _topple() -> Case:
    return _case(
        "topple-on-fingertip",
        frictionless_data(
            bodies={"box": {"mass": 1.0, "com": [0.2, 0.1]}},
            movers={"finger": {}},
            contacts=[contact("box", "finger", [0.1, 0.0], [0.0, 1.0])],
        ),
        """One fixed fingertip under a box, 0.1 left of its com: a single vertical force cannot balance the
        weight's moment about the tip. Turning clockwise about the tip keeps the contact closed and
        lowers the com: no quasi-static equilibrium.""",
        "unstable",
        diagnosis=qs.Diagnosis.NO_EQUILIBRIUM,
    )


def _unsupported() -> Case:
    return _case(
        "unsupported-block",
        frictionless_data(bodies={"box": {"mass": 1.0, "com": [0.0, 0.5]}}, contacts=[]),
        """A 1 kg box with no contact at all: nothing balances its weight; the twist d = (0, -1, 0) does
        work M g > 0 without meeting any contact. It falls: no quasi-static equilibrium.""",
        "unstable",
        diagnosis=qs.Diagnosis.NO_EQUILIBRIUM,
    )


BOX_W, BOX_H, BOX_M = 0.4, 0.2, 2.0


def box_on_table_data(*extra_contacts: dict[str, Any], movers: dict[str, Any] | None = None) -> dict[str, Any]:
    """A BOX_W x BOX_H box (2 kg), com at (BOX_W/2, BOX_H/2), on a fixed frictionless table at its two bottom corners."""
    return frictionless_data(
        bodies={"box": {"mass": BOX_M, "com": [BOX_W / 2, BOX_H / 2]}},
        movers={"table": {}, **(movers or {})},
        contacts=[
            contact("box", "table", [0.0, 0.0], [0.0, 1.0]),
            contact("box", "table", [BOX_W, 0.0], [0.0, 1.0]),
            *extra_contacts,
        ],
    )


def _wall_push(y_wall: float, y_finger: float, speed: float) -> dict[str, Any]:
    return box_on_table_data(
        contact("box", "wall", [0.0, y_wall], [1.0, 0.0]),
        contact("box", "finger", [BOX_W, y_finger], [-1.0, 0.0]),
        movers={"wall": {}, "finger": {"twist": [speed, 0.0, 0.0]}},
    )


def _push_into_wall() -> Case:
    return _case(
        "push-into-wall",
        _wall_push(BOX_H / 2, BOX_H / 2, -0.1),
        """A fixed wall on the box's left face, a finger on its right face moving left at s = 0.1, both at
        com height (rotation moves those points only vertically). Wall: vx >= 0. Finger:
        -(vx + s) >= 0, so vx <= -s < 0. No admissible motion: the command is jammed (kinematically; the
        Farkas multipliers (0, 0, 1, 1) prove it).""",
        "jammed",
        diagnosis=qs.Diagnosis.KINEMATIC,
        farkas=(0.0, 0.0, 1.0, 1.0),
    )


def _push_tips() -> Case:
    weight = BOX_M * G
    return _case(
        "push-off-centre-tips",
        _wall_push(0.05, 0.15, -0.1),
        """The wall touches the left face at (0, 0.05), the finger the right face at (0.4, 0.15), moving
        left at 0.1. With q = (vx, vy, w) about the com (0.2, 0.1): table corners vy -+ 0.2 w >= 0, wall
        vx + 0.05 w >= 0, finger -vx + 0.05 w - 0.1 >= 0. Wall and finger together need w >= 1; then
        vy >= 0.2 w >= 0.2. Minimum power M g vy: w = 1, vy = 0.2, and vx is squeezed to -0.05. The box
        turns about the wall point (its velocity is zero: rolling); the left corner slides right at
        0.05, the right corner lifts (separating), the finger slides up its face. Forces of the active
        constraints: N_left = M g = 19.62 N; N_wall = N_finger; moments about the com
        -0.2 N_left + 0.05 (N_wall + N_finger) = 0: 39.24 N each. Power: 39.24 x 0.1 = M g vy = 3.924 W.""",
        "solved",
        Expected(
            {"box": (-0.05, 0.2, 1.0)},
            ("sliding", "separating", "rolling", "sliding"),
            (weight, 0.0, 2 * weight, 2 * weight),
            power_input=weight * 0.2,
        ),
    )


# --------------------------------------------------------------------------- two fingertips lift a box

X1, X2 = 0.1, 0.35  # fingertips under the box (com at x = 0.2)
V1, V2 = 0.1, 0.3  # their upward speeds
R1, R2 = X1 - BOX_W / 2, X2 - BOX_W / 2  # -0.1, +0.15: the com is between them


def two_finger_lift_data(pins: bool) -> dict[str, Any]:
    """Box lifted by two frictionless fingertips under it; optionally two fixed pins at its mid-height, left and right."""
    contacts = [contact("box", "f1", [X1, 0.0], [0.0, 1.0]), contact("box", "f2", [X2, 0.0], [0.0, 1.0])]
    if pins:
        contacts += [contact("box", "pins", [0.0, BOX_H / 2], [1.0, 0.0]), contact("box", "pins", [BOX_W, BOX_H / 2], [-1.0, 0.0])]
    return frictionless_data(
        bodies={"box": {"mass": BOX_M, "com": [BOX_W / 2, BOX_H / 2]}},
        movers={"f1": {"twist": [0.0, V1, 0.0]}, "f2": {"twist": [0.0, V2, 0.0]}, "pins": {}},
        contacts=contacts,
    )


LIFT = """Minimum power: minimise M g vy subject to vy + wz r_i >= v_i (r_i = x_i - x_com; r1 = -0.1 < 0 < r2 = 0.15).
Lowering vy while keeping finger 2 closed needs wz as large as finger 1 allows, so both stay closed
(the box tilts): wz = (v2 - v1)/(r2 - r1) = 0.8 rad/s, vy = v1 - wz r1 = 0.18 m/s. Forces (the dual):
N1 + N2 = M g, N1 r1 + N2 r2 = 0: N1 = M g r2/(r2 - r1) = 0.6 M g, N2 = 0.4 M g. Power
N1 v1 + N2 v2 = M g vy."""


def lift_answer() -> tuple[float, float, float, float]:
    """(vy, wz, N1, N2) of LIFT."""
    wz = (V2 - V1) / (R2 - R1)
    return V1 - wz * R1, wz, BOX_M * G * R2 / (R2 - R1), -BOX_M * G * R1 / (R2 - R1)


def _lift_drifts() -> Case:
    vy, wz, n1, n2 = lift_answer()
    return _case(
        "lift-drifts-sideways",
        two_finger_lift_data(pins=False),
        LIFT
        + """ Frictionless with every normal vertical: vx costs no power and meets no contact. The answer
        is one unbounded continuum in vx; vy, wz and the forces are the same on every motion of it.""",
        "ambiguous",
        Expected({"box": (FREE, vy, wz)}, normal_forces=(n1, n2), continuum=True, unbounded=True, power_input=BOX_M * G * vy),
    )


def _lift_pins() -> Case:
    vy, wz, n1, n2 = lift_answer()

    def slips(motion: qs.Motion) -> None:
        f1, f2, left, right = motion.contacts
        assert _close(left.normal_force, right.normal_force)  # x balance, whatever squeeze is reported
        assert np.allclose([f1.slip, f2.slip], [[wz * BOX_H / 2, 0.0]] * 2, atol=1e-9)
        assert np.allclose(left.slip, [0.0, vy - wz * BOX_W / 2], atol=1e-9)
        assert np.allclose(right.slip, [0.0, vy + wz * BOX_W / 2], atol=1e-9)
        assert np.allclose([c.normal_velocity for c in motion.contacts], 0.0, atol=1e-9)

    return _case(
        "lift-between-pins",
        two_finger_lift_data(pins=True),
        LIFT
        + """ Two fixed frictionless pins at mid-height on the sides fix vx = 0 (vx >= 0 and vx <= 0;
        rotation moves a point at com height only vertically). The pins squeeze with any P = P_left =
        P_right in [0, inf): forces indeterminate. Slips (body point minus mover point): fingers
        (wz H/2, 0), left pin (0, vy - wz W/2), right pin (0, vy + wz W/2): all four slide.""",
        "solved",
        Expected(
            {"box": (0.0, vy, wz)},
            ("sliding",) * 4,
            (n1, n2, None, None),
            normal_force_ranges=((n1, n1), (n2, n2), (0.0, None), (0.0, None)),
            power_input=n1 * V1 + n2 * V2,
            check=slips,
        ),
    )


# --------------------------------------------------------------------------- squeeze: indeterminate forces


def _squeeze(y_left: float, y_right: float) -> Case:
    weight = BOX_M * G
    d = y_right - y_left

    def relation(motion: qs.Motion) -> None:
        table1, table2, left, right = (c.normal_force for c in motion.contacts)
        assert _close(left, right)
        assert _close(table1, weight / 2 + left * d / BOX_W) and _close(table2, weight / 2 - left * d / BOX_W)

    data = box_on_table_data(
        contact("box", "left", [0.0, y_left], [1.0, 0.0]),
        contact("box", "right", [BOX_W, y_right], [-1.0, 0.0]),
        movers={"left": {}, "right": {}},
    )
    rest = Expected({"box": (0.0, 0.0, 0.0)}, ("rolling",) * 4, power_input=0.0, check=relation)
    if d == 0:
        return _case(
            "squeeze-level",
            data,
            """A box on a frictionless table squeezed by two stationary fingers at the same height 0.12.
            Motion: table contacts give vy -+ wz W/2 >= 0; minimum power (M g vy) gives vy = wz = 0; the
            fingers then give vx >= 0 and vx <= 0: rest, all rolling. Forces: P_left = P_right = P, on
            one line of action, so the table's moment balance gives N1 = N2 = M g/2 exactly, while P is
            any value in [0, inf).""",
            "solved",
            Expected(
                rest.twists,
                rest.modes,
                (weight / 2, weight / 2, None, None),
                ((weight / 2, weight / 2), (weight / 2, weight / 2), (0.0, None), (0.0, None)),
                power_input=0.0,
                check=relation,
            ),
        )
    p_max = weight * BOX_W / (2 * d)
    return _case(
        "squeeze-offset",
        data,
        """As squeeze-level but the left finger at 0.05 and the right one at 0.15 (D = 0.1). x balance:
        P_left = P_right = P; moments about the com: N1 - N2 = 2 P D/W, N1 + N2 = M g. N2 >= 0 bounds
        P <= M g W/(2 D) = 39.24 N: P in [0, 39.24], N1 in [M g/2, M g], N2 in [0, M g/2]. The motion is
        still rest (the same kinematic argument).""",
        "solved",
        Expected(
            rest.twists,
            rest.modes,
            (None,) * 4,
            ((weight / 2, weight), (0.0, weight / 2), (0.0, p_max), (0.0, p_max)),
            power_input=0.0,
            check=relation,
        ),
    )


# --------------------------------------------------------------------------- continua of motions


def _receding_finger() -> Case:
    s = 0.1
    half = BOX_M * G / 2
    return _case(
        "box-wall-receding-finger",
        _wall_push(BOX_H / 2, BOX_H / 2, s),
        """Box on the frictionless table, a fixed wall on its left face, a finger on its right face moving
        right at s = 0.1 (both at com height). Table: vy >= |wz| W/2, minimum power gives vy = wz = 0.
        Wall: vx >= 0; finger: vx <= s. Every vx in [0, s] costs the same (zero) power: one bounded
        continuum with extreme twists (0, 0, 0) (the box stays at the wall) and (s, 0, 0) (it follows
        the finger). Table forces M g/2 each, no horizontal force.""",
        "ambiguous",
        Expected(
            {"box": (FREE, 0.0, 0.0)},
            normal_forces=(half, half, 0.0, 0.0),
            continuum=True,
            extremes=({"box": (0.0, 0.0, 0.0)}, {"box": (s, 0.0, 0.0)}),
        ),
    )


def _box_alone() -> Case:
    half = BOX_M * G / 2
    return _case(
        "box-alone-on-table",
        box_on_table_data(),
        """A box alone on a frictionless table: minimum power (M g vy, vy -+ wz W/2 >= 0) gives
        vy = wz = 0, and nothing resists vx: every vx is a motion, one unbounded continuum; the table
        carries M g/2 at each corner.""",
        "ambiguous",
        Expected({"box": (FREE, 0.0, 0.0)}, normal_forces=(half, half), continuum=True, unbounded=True),
    )


# --------------------------------------------------------------------------- two free bodies

MA, WA, HA = 2.0, 0.4, 0.2  # bottom box A
MB, WB, HB = 1.0, 0.2, 0.2  # top box B, flush with A's downhill face
YA, YB = 0.05, 0.05  # stop contact heights above each box's bottom face


def _local(x: float, y: float) -> list[float]:
    """World point of slope coordinates (x along T, y along N)."""
    return _floats(x * T + y * N)


def _stack() -> Case:
    speed = 0.1
    sa, ca = math.sin(ALPHA), math.cos(ALPHA)
    fb = MB * G * sa
    nb2 = (MB * G * ca + 2 * (YB - HB / 2) * fb / WB) / 2
    nb1 = MB * G * ca - nb2
    fa = MA * G * sa
    na2 = (YA * fa + WB * nb2 + MA * G * (WA * ca - HA * sa) / 2) / WA
    na1 = (MA + MB) * G * ca - na2
    data = frictionless_data(
        bodies={"A": {"mass": MA, "com": _local(WA / 2, HA / 2)}, "B": {"mass": MB, "com": _local(WB / 2, HA + HB / 2)}},
        movers={"slope": {}, "stop": {"twist": [*_floats(speed * T), 0.0]}},
        contacts=[
            contact("A", "slope", _local(0.0, 0.0), N),
            contact("A", "slope", _local(WA, 0.0), N),
            contact("A", "stop", _local(0.0, YA), T),
            contact("B", "A", _local(0.0, HA), N),
            contact("B", "A", _local(WB, HA), N),
            contact("B", "stop", _local(0.0, HA + YB), T),
        ],
    )
    twist = (*(speed * T), 0.0)
    return _case(
        "stack-on-slope-pushed",
        data,
        """Box B (1 kg, 0.2 x 0.2) on box A (2 kg, 0.4 x 0.2) on the frictionless 30 deg slope; a stop
        perpendicular to the slope holds both downhill faces (0.05 up each) and moves uphill at 0.1 m/s.
        Slope coordinates, B: FB = MB g sin a; NB1 + NB2 = MB g cos a; moments about B's com:
        NB2 = (MB g cos a + 2 (YB - HB/2) FB/WB)/2. A, loaded by -NB_i N at (0, HA) and (WB, HA):
        FA = MA g sin a; NA1 + NA2 = (MA + MB) g cos a; moments about A's bottom-left corner:
        NA2 = (YA FA + WB NB2 + MA g (WA cos a - HA sin a)/2)/WA. Six contacts, six twist coordinates,
        six positive forces: every constraint is active, both boxes translate with the stop (A slides
        on the slope, B rolls on A, both roll on the stop). Power (FA + FB) s = (MA + MB) g s sin a.""",
        "solved",
        Expected(
            {"A": twist, "B": twist},
            ("sliding", "sliding", "rolling", "rolling", "rolling", "rolling"),
            (na1, na2, fa, nb1, nb2, fb),
            power_input=(fa + fb) * speed,
            check=_normal_directions(N, N, T, N, N, T),
        ),
    )


# =========================================================================== frictionless, 3-D

DEPTH = 0.3


def held_slope_3d_data(speed: float, guides: bool = True) -> dict[str, Any]:
    """``held_slope_data`` extruded along z: each contact at z = -DEPTH/2 and +DEPTH/2; with ``guides`` two
    fixed plates touch the front and back faces at the com (normals +z and -z)."""
    flat = held_slope_data(speed)
    contacts = [{**c, "point": [*c["point"], z], "normal": [*c["normal"], 0.0]} for c in flat["contacts"] for z in (-DEPTH / 2, DEPTH / 2)]
    com = [*flat["bodies"]["block"]["com"], 0.0]
    if guides:
        contacts += [
            contact("block", "guide", [com[0], com[1], -DEPTH / 2], [0.0, 0.0, 1.0]),
            contact("block", "guide", [com[0], com[1], DEPTH / 2], [0.0, 0.0, -1.0]),
        ]
    return frictionless_data(
        3,
        bodies={"block": {"mass": SM, "com": com}},
        movers={"slope": {}, "guide": {}, "finger": {"twist": [*_floats(speed * T), 0.0, 0.0, 0.0, 0.0]}},
        contacts=contacts,
    )


def _held_3d() -> Case:
    s = 0.05
    n1, n2, f = held_slope_forces()

    def pairs(motion: qs.Motion) -> None:
        forces = [c.normal_force for c in motion.contacts]
        assert _close(forces[0] + forces[1], n1) and _close(forces[2] + forces[3], n2)
        assert _close(forces[6], forces[7])

    return _case(
        "held-slope-pushed-3d",
        held_slope_3d_data(s),
        HELD
        + """ In 3-D the held block is extruded along z (depth 0.3, each contact doubled at z = -+0.15), two
        fixed guides on its faces at the com pin vz = 0. It moves as in 2-D, twist (s T, 0, 0, 0, 0),
        s = 0.05. The four slope contacts are indeterminate: three equations (force along N, moments
        about T and z), null vector (+1, -1, -1, +1) over (downhill z-, downhill z+, uphill z-,
        uphill z+); each edge's sum is N1 (downhill), N2 (uphill), and with N2 < N1 the ranges are
        downhill [(N1 - N2)/2, (N1 + N2)/2], uphill [0, N2]. The finger pair is determined (nothing else
        has a moment about N): F/2 each. The guides squeeze with any force in [0, inf); the block slides
        along them and along the slope, and rolls on the finger.""",
        "solved",
        Expected(
            _twist([*(s * T), 0.0, 0.0, 0.0, 0.0]),
            ("sliding",) * 4 + ("rolling",) * 2 + ("sliding",) * 2,
            (None, None, None, None, f / 2, f / 2, None, None),
            normal_force_ranges=(
                ((n1 - n2) / 2, (n1 + n2) / 2),
                ((n1 - n2) / 2, (n1 + n2) / 2),
                (0.0, n2),
                (0.0, n2),
                (f / 2, f / 2),
                (f / 2, f / 2),
                (0.0, None),
                (0.0, None),
            ),
            power_input=f * s,
            check=pairs,
        ),
    )


def _held_3d_drifts() -> Case:
    s = 0.05
    n1, n2, f = held_slope_forces()
    return _case(
        "held-slope-pushed-3d-no-guides",
        held_slope_3d_data(s, guides=False),
        """The 3-D held block (see held-slope-pushed-3d) without its guides: no contact resists vz and gravity
        does not care, so every vz is a motion: one unbounded continuum; the in-plane coordinates are
        those of the 2-D answer (s T, 0) and the finger pair carries F/2 each.""",
        "ambiguous",
        Expected(
            _twist([*(s * T), FREE, 0.0, 0.0, 0.0]),
            normal_forces=(None, None, None, None, f / 2, f / 2),
            continuum=True,
            unbounded=True,
        ),
    )


# =========================================================================== the catalogue

CASES: list[Case] = [
    # frictional, 2-D
    _slope_rest(),
    _slope_unstable("slope-slides-30", W, H, MU, "mu = 0.5 < tan a < w/h = 2: the block slides."),
    _slope_unstable("slope-tips-30", 0.1, 0.2, 0.8, "the tall block has w/h = 0.5 < tan a < mu = 0.8: it tips."),
    _slope_push(0.01),
    _slope_push(-0.01),
    _box_low(),
    _box_high(),
    _grasp_lift(),
    _grasp_unstable(
        "grasp-offset-mu03",
        0.3,
        0.04,
        """The contacts are offset by dy = 0.04 and mu = 0.3: the grasp line's slope dy/(2a) = 0.4 > mu
        leaves both friction cones (Nguyen's force closure fails), so the squeeze cannot be balanced.""",
    ),
    _finger_drags(),
    _wedge_slides(),
    _wedge_jammed(),
    # frictional, 3-D
    _puck(),
    _wedge_slides_3d(),
    # frictionless, 2-D
    _grasp_unstable("grasp-frictionless", 0.0, 0.0, "Frictionless (mu = 0): the horizontal forces carry nothing of the weight."),
    _held_rest(),
    _held_pushed(),
    _slope_alone(),
    _topple(),
    _unsupported(),
    _push_into_wall(),
    _push_tips(),
    _lift_drifts(),
    _lift_pins(),
    _squeeze(0.12, 0.12),
    _squeeze(0.05, 0.15),
    _receding_finger(),
    _box_alone(),
    _stack(),
    # frictionless, 3-D
    _held_3d(),
    _held_3d_drifts(),
]

BY_NAME: dict[str, Case] = {c.name: c for c in CASES}
assert len(BY_NAME) == len(CASES)

# (case, method id): a library bug the pair exposes, run as a strict xfail with the evidence (the exception it raises).
KNOWN_BUGS: dict[tuple[str, str], tuple[type[BaseException], str]] = {}
assert {case for case, _ in KNOWN_BUGS} <= {c.name for c in CASES}
