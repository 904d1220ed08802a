"""The one verb: ``solve(scene)``. Assembles, dispatches to a backend, then audits every motion.

Pipeline: Scene ─▶ :func:`~quasistatic.laws.assemble` ─▶ a backend from the
registry ─▶ :func:`_audited`: each raw motion converted to physical units
(:mod:`quasistatic.laws.motion`) and audited on the original scene data
(:mod:`quasistatic.check`) ─▶ :class:`Solution`. A motion that fails its
audit is never reported as a success.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from functools import partial

import numpy as np

from .adapters import AnyWorld, Detection, PlanarWorld, World
from .check import DEFAULT_TOLERANCE, ForceFunctionals, MotionGeometry, audited_motion, audited_step
from .derivative import SolvedScene
from .errors import QuasistaticError, SolverError
from .laws import DeferredForces, Problem, RawMotion, WorldForceSet, assemble, free_directions, physical_twists, to_world
from .model import FloatArray, Scene
from .solution import Attempt, CompliantStep, Later, Mode, Motion, Solution, UnprovenExtreme
from .solvers import BACKENDS, Backend, BackendResult, Options, SearchProgress, compliant_forces, compliant_step, get_backend, too_large
from .solvers.reuse import Reuse

Range = tuple[float, float | None]

__all__ = ["solve", "METHODS", "Reuse", "audited_raw_motion", "with_detection"]

METHODS = ("auto", *BACKENDS)
_MODE_NAMES = ("rolling", "sliding", "separating")


def solve(
    scene: Scene | Problem | AnyWorld,
    method: str = "auto",
    *,
    certify: bool = True,
    modes: Sequence[Mode | None] | None = None,
    all_solutions: bool | None = None,
    max_solutions: int = 16,
    tolerance: float = DEFAULT_TOLERANCE,
    time_limit: float = 60.0,
    progress: Callable[[SearchProgress], None] | None = None,
    reuse: Reuse | None = None,
) -> Solution:
    """Predict the quasi-static motion of the free bodies of a scene.

    Parameters
    ----------
    scene : Scene, Problem, World or PlanarWorld
        A validated scene (or one already assembled, to solve it again cheaply), or a
        World of shapes and robots, whose contacts are found first (the answer's message
        then says when a body touches nothing, and how far the nearest surface is).
    method : str
        ``auto`` (default) or a backend name from :data:`METHODS`. ``auto``
        solves frictionless scenes by LP and frictional ones by ``certified``
        (cheap certificates, then the certified search; ``scip`` with
        prescribed modes) or, with ``certify=False``, by the fast path first,
        falling back to the certified search when it finds no audited motion
        and proves no ``jammed`` or ``unstable``.
    certify : bool
        True (default): ``solved`` means proven unique and ``ambiguous`` lists
        every motion. False: with ``method="auto"``, accept the first audited
        motion the fast path finds; the Solution then says
        ``certified=False``. An explicitly named method answers as it can,
        and ``Solution.certified`` says whether that answer is proven.
    modes : sequence of {"rolling", "sliding", "separating", None}, optional
        Prescribe contact modes, one entry per contact (None leaves it free).
    all_solutions : bool, optional
        The earlier name of ``certify``; when given it wins. True with a method
        that finds one motion (``fast``, ``paper``) is an error.
    max_solutions : int
        Most distinct motions listed when the answer is ``ambiguous``.
    tolerance : float
        Audit threshold on every scene-relative residual [-].
    time_limit : float
        Seconds a certified search may take [s].
    progress : callable, optional
        Called with a :class:`~quasistatic.solvers.SearchProgress` (motions found, nodes,
        seconds) after each step of the certified search, e.g. to show a status line.
    reuse : Reuse, optional
        A memory of the last certified answer (a simulation keeps one per run): laws equal to its own
        bit for bit take that answer again instead of proving it anew; every motion is still audited
        on this scene.

    Returns
    -------
    Solution
        Every motion in it has been audited on the original scene data.
    """
    if isinstance(scene, World | PlanarWorld):
        detection = scene.detect()
        solution = solve(
            scene.scene(detection),
            method,
            certify=certify,
            modes=modes,
            all_solutions=all_solutions,
            max_solutions=max_solutions,
            tolerance=tolerance,
            time_limit=time_limit,
            progress=progress,
            reuse=reuse,
        )
        solution = dataclasses.replace(solution, source=SolvedScene(solution.scene, scene.robots))  # joint positions too
        return with_detection(solution, detection)
    started = time.perf_counter()
    problem = scene if isinstance(scene, Problem) else assemble(scene)
    checked = _check_modes(modes, problem)
    options = Options(max_solutions, checked, time_limit, progress=progress)
    names = _choose(method, problem, checked is not None, certify if all_solutions is None else all_solutions, bool(all_solutions))
    tried: list[Attempt] = []
    for name in names:
        backend = get_backend(name)
        if not backend.frictional and not problem.is_frictionless:
            raise QuasistaticError(
                f"method {name!r} is frictionless but contacts {_frictional(problem)} have mu > 0; "
                "use method 'auto', or set 'friction: none' to drop friction on purpose"
            )
        result = _run(backend, problem, options) if reuse is None else _recalled_or_run(reuse, backend, problem, options)
        solution = _audited(problem, result, name, tolerance, options, tuple(tried), started)
        solution = _compliant(problem, solution, result, tolerance, options.time_limit)
        # A certifying method's verdict stands unless the audit turned its motion down; the fast path's when solved,
        # or when it proved that no motion exists (its complete fallback's certified jammed/unstable).
        rejected = solution.status == "failed" and result.status != "failed"
        proven = backend.certifies or (solution.certified and solution.status in ("jammed", "unstable"))
        if name == names[-1] or (not rejected if proven else solution.ok):
            return solution
        tried.append(Attempt(name, solution.message))
    raise AssertionError("unreachable: the last method always returns")


def _run(backend: Backend, problem: Problem, options: Options) -> BackendResult:
    """A backend's answer; anything a library underneath raises becomes a :class:`SolverError` naming the method.

    Backends report statuses and raise only when something crashed (SCIP or HiGHS on
    extreme numbers, a numerical library's internal error): the user gets the library's
    own exception, with the original chained as its cause.
    """
    oversized = too_large(problem, backend.name)  # dense matrices past the memory limit: an honest failed
    if oversized is not None:
        return oversized
    try:
        return backend.solver(problem, options)
    except QuasistaticError:
        raise
    except Exception as exc:
        raise SolverError(backend.name, f"{type(exc).__name__}: {exc}") from exc


def _recalled_or_run(reuse: Reuse, backend: Backend, problem: Problem, options: Options) -> BackendResult:
    """The answer ``reuse`` kept for these very laws, else the backend's (kept in turn when certified and complete)."""
    kept, key = reuse.recalled(backend.name, problem, options)
    if kept is not None:
        return kept
    result = _run(backend, problem, options)
    reuse.keep(key, result)
    return result


def _choose(method: str, problem: Problem, modes_given: bool, certify: bool, insist: bool) -> tuple[str, ...]:
    """Methods to try in order; a later one runs only when the earlier one found no audited motion.

    ``insist``: every motion was asked for by name (``all_solutions=True``), which a one-motion method refuses.
    """
    if method != "auto":
        backend = get_backend(method)
        if modes_given and not backend.prescribes_modes:
            raise ValueError(f"modes: method {method!r} cannot prescribe contact modes; use method 'auto' or 'scip'")
        if insist and not backend.lists_all_motions:
            raise ValueError(f"all_solutions: method {method!r} finds one motion; use method 'auto' or 'scip'")
        return (method,)
    if problem.is_frictionless and not modes_given:
        return ("lp",)
    if modes_given:
        return ("scip",)
    if certify:
        return ("certified", "scip")  # scip only if the audit rejects a cheap certificate's motion
    return ("fast", "scip")


def _frictional(problem: Problem) -> list[int]:
    return [i for i, mu in enumerate(problem.mu) if mu > 0]


def with_detection(solution: Solution, detection: Detection) -> Solution:
    """The answer with what contact detection found missing: which body touches nothing, and the nearest gap."""
    lines = detection.notes()
    if not lines:
        return solution
    message = f"{solution.message} ({'; '.join(lines)})"
    return dataclasses.replace(solution, message=message, notes=(*solution.notes, ("contact_detection", list(lines))))


def _check_modes(modes: Sequence[Mode | None] | None, problem: Problem) -> tuple[Mode | None, ...] | None:
    if modes is None:
        return None
    modes = tuple(modes)
    if len(modes) != problem.n_contacts:
        raise ValueError(f"modes: expected {problem.n_contacts} entries (one per contact), got {len(modes)}")
    for i, mode in enumerate(modes):
        if mode is not None and mode not in _MODE_NAMES:
            raise ValueError(f"modes[{i}]: {mode!r} is not one of rolling, sliding, separating (or None)")
    return modes


def audited_raw_motion(problem: Problem, raw: RawMotion, tolerance: float = DEFAULT_TOLERANCE) -> Motion:
    """A backend's raw motion in physical units, audited on the original scene data."""
    scales = problem.scales
    geometry = problem.scene.derived("motion_geometry", lambda scene: MotionGeometry(scene, problem.scales))
    T, forces = to_world(problem, raw.q, raw.c)
    ranges: list[Range] | Callable[[], list[Range]] | None = None
    force_set: ForceFunctionals | Later[ForceFunctionals | None] | None = None
    indeterminate: Later[bool] | None = None
    if raw.deferred is not None:  # decided when read: the ranges and the set are read only when it is indeterminate
        deferred = raw.deferred
        indeterminate = Later(deferred.indeterminate)
        ranges = partial(_physical_ranges_of, deferred.normal_ranges, scales.force)
        force_set = Later(partial(_deferred_set, problem, deferred))
    elif raw.force_ranges is not None:
        ranges = _physical_ranges(raw.force_ranges, scales.force)
    elif raw.lazy_ranges is not None:
        ranges = partial(_physical_ranges_of, raw.lazy_ranges, scales.force)
    if raw.force_set is not None:
        force_set = WorldForceSet(problem, raw.force_set)
    extremes, audits, unproven = [], [], []
    for k, extreme in enumerate(raw.extremes):  # an extreme is a motion too: audited as one, with its forces
        twists = physical_twists(problem, extreme)
        own = raw.c if raw.extremes_share_forces else raw.extreme_forces[k] if k < len(raw.extreme_forces) else None
        if own is None:  # no forces to audit it with: not a motion anyone has shown
            unproven.append(UnprovenExtreme(twists, None))
            continue
        at_extreme = audited_motion(geometry, scales, *to_world(problem, extreme, own), tolerance=tolerance)
        if at_extreme.audit.passed:
            extremes.append(twists)
            audits.append(at_extreme.audit)
        elif raw.extremes_share_forces:
            return at_extreme  # the evidence: this pattern's continuum is not what it claims
        else:
            unproven.append(UnprovenExtreme(twists, at_extreme.audit))
    return audited_motion(
        geometry,
        scales,
        T,
        forces,
        ranges=ranges,
        extreme_twists=tuple(extremes),
        extreme_audits=tuple(audits),
        unproven_extremes=tuple(unproven),
        continuum=raw.continuum,
        unbounded=raw.unbounded,
        free_directions=free_directions(problem, raw.free_axes),
        force_set=force_set,
        indeterminate=indeterminate,
        tolerance=tolerance,
    )


def _deferred_set(problem: Problem, deferred: DeferredForces) -> ForceFunctionals | None:
    """The world force set of a motion whose forces are indeterminate; None when they are unique."""
    return WorldForceSet(problem, deferred.force_set()) if deferred.indeterminate() else None


def _compliant(problem: Problem, solution: Solution, result: BackendResult, tolerance: float, time_limit: float) -> Solution:
    """With springs in the scene: a solved motion's compliant forces; with a closing time, the step the rigid model lacks."""
    scene = problem.scene
    if not scene.compliant:
        if scene.closing_time is not None:
            return _compliance_note(solution, "closing_time is given but nothing has a stiffness to take up the closing")
        return solution
    if solution.status == "solved" and result.motions:
        return _with_compliance(problem, solution, result.motions[0].q, tolerance, time_limit)
    if solution.status in ("jammed", "ambiguous") and scene.closing_time is not None:
        return _with_step(problem, solution, tolerance, time_limit)
    return solution


def _with_step(problem: Problem, solution: Solution, tolerance: float, time_limit: float) -> Solution:
    """The rigid verdict with the compliant step beside it: what the springs do as the movers advance (audited)."""
    scene, scales = problem.scene, problem.scales
    assert scene.closing_time is not None
    found = compliant_step(problem, scene.closing_time, time_limit)
    if found.c is None or found.displacement is None:
        return _compliance_note(solution, f"step: {found.reason}")
    _, forces = to_world(problem, np.zeros(problem.n_dof), found.c)
    k, d = scene.twist_size, scene.dimension
    units = np.r_[np.full(d, scales.length), np.ones(k - d)]  # the displacement's length entries, then its rotations [rad]
    displacements = {body.name: found.displacement[i * k : (i + 1) * k] * units for i, body in enumerate(scene.bodies)}
    step = audited_step(scene, scales, displacements, forces, "", tolerance)
    text = _step_text(step, found.determined)
    step = dataclasses.replace(step, message=text)
    return dataclasses.replace(solution, message=f"{solution.message}; {text}", compliant_step=step)


def _step_text(step: CompliantStep, determined: bool) -> str:
    h = f"with compliance, as the movers advance for {step.closing_time:g}"
    limit = [f"#{i}" for i, state in enumerate(step.states) if state == "at friction limit"]
    if limit:
        slip = "they would slip, which the static step does not model (no answer)"
        return f"{h}, contacts {', '.join(limit)} reach their friction limit: {slip}"
    if not step.audit.passed:
        return f"{h}: the step failed its audit ({', '.join(_step_failures(step))}); it is not an answer"
    loaded = ", ".join(f"#{i} {f:.6g}" for i, f in enumerate(step.normal_forces) if step.states[i] != "open")
    free = "" if determined else " (the loaded contacts leave the displacement free along some direction: the smallest is shown)"
    return f"{h} the springs hold the bodies with normal forces {loaded or 'none'}{free}"


def _step_failures(step: CompliantStep) -> list[str]:
    audit = step.audit
    residuals = {"equilibrium": audit.equilibrium, "cone": audit.cone, "compatibility": audit.compatibility}
    return [name for name, value in residuals.items() if not value <= audit.tolerance]


def _with_compliance(problem: Problem, solution: Solution, q: FloatArray, tolerance: float, time_limit: float) -> Solution:
    """The solved motion with its compliant forces (least elastic energy), audited; the rigid answer when they fail.

    Why compliance did not fix the forces (a rigid contact, a failed program, an audit) goes in the notes.
    """
    found = compliant_forces(problem, q, time_limit)
    if found.c is None:
        return _compliance_note(solution, f"not applied: {found.reason}")
    if not found.unique:
        rigid = ", ".join(f"#{i}" for i in found.rigid) or "none"
        return _compliance_note(solution, f"leaves the forces indeterminate: rigid loaded contacts {rigid} share the load freely")
    motion = audited_raw_motion(problem, RawMotion(q, found.c), tolerance)
    if not motion.audit.passed:
        laws = ", ".join(motion.audit.failures())
        return _compliance_note(solution, f"not applied: its forces failed the audit ({laws}); the rigid forces are reported")
    energy = found.energy * problem.scales.force * problem.scales.length
    message = solution.message
    if solution.forces_indeterminate:
        message = (
            message.replace("; the contact forces are indeterminate", "")
            + "; compliance determines the contact forces (least elastic energy)"
        )
    return dataclasses.replace(
        solution,
        message=message,
        motion=motion,
        forces_indeterminate=False,
        compliant_forces=True,
        notes=(*solution.notes, ("compliance", f"elastic energy {energy:.6g} (force x length)")),
    )


def _compliance_note(solution: Solution, text: str) -> Solution:
    return dataclasses.replace(solution, notes=(*solution.notes, ("compliance", text)))


def _first_indeterminate(result: BackendResult) -> bool:
    return result.motions[0].forces_indeterminate


def _physical_ranges(ranges: Sequence[Range], force: float) -> list[Range]:
    return [(lo * force, None if hi is None else hi * force) for lo, hi in ranges]


def _physical_ranges_of(lazy: Callable[[], Sequence[Range]], force: float) -> list[Range]:
    return _physical_ranges(lazy(), force)


def _audited(
    problem: Problem, result: BackendResult, method: str, tolerance: float, options: Options, fallback: tuple[Attempt, ...], started: float
) -> Solution:
    """Turn raw motions into audited ones; a motion that fails its audit is never a success."""
    motions = [audited_raw_motion(problem, raw, tolerance) for raw in result.motions]
    indeterminate: bool | Later[bool] = False
    if result.motions and result.status != "failed":  # decided when read (often never: a simulation step, a batch)
        indeterminate = Later(partial(_first_indeterminate, result))
    message: str | Later[str] = Later(result.full_message) if result.claims_forces else result.full_message()
    solution = Solution(
        result.status,
        message,
        method,
        str(problem.friction),
        motion=motions[0] if motions else None,
        solutions=tuple(motions) if result.status == "ambiguous" else (),
        forces_indeterminate=indeterminate,
        certified=result.certified and result.status != "failed",
        diagnosis=result.diagnosis,
        certificate=result.certificate,
        search_complete=result.search_complete,
        prescribed_modes=options.modes,
        fallback=fallback,
        notes=result.notes,
        seconds=time.perf_counter() - started,
        source=SolvedScene(problem.scene),
    )
    failed = [m for m in motions if not m.audit.passed]
    if not failed:
        return solution
    laws = ", ".join(sorted({law for m in failed for law in m.audit.failures()}))
    message = f"failed: {method} returned a motion that violates the laws ({laws}); it is not reported as a solution"
    return dataclasses.replace(
        solution, status="failed", message=message, motion=failed[0], solutions=(), forces_indeterminate=False, certified=False
    )
