"""The compiled extensions ``quasistatic._lemke`` and ``quasistatic._kernels``: numba kernels in C, for installs without numba.

``pip install .`` builds them with the machine's C compiler (setuptools only: no
numpy headers); each is optional, so an install without a compiler still works
and runs the numpy twins instead. ``HAVE_EXTENSION`` says whether ``_lemke`` was
built (:func:`lemke`, :func:`fixed_mode_system`: the numba kernels
``solvers/numerics/lemke.py::lemke`` and ``laws/fixed_modes.py::system``),
``HAVE_KERNELS`` whether ``_kernels`` was (:func:`audit_laws`, the audit's
``check/audit.py::_laws_2d`` / ``_laws_3d``; :func:`analyse_frictionless`,
``solvers/lp.py::_analyse``; :func:`to_world` and :func:`drop_roundoff`,
``laws/motion.py::_to_world_kernel`` and ``check/motion.py::_drop_roundoff``; :func:`nonnegative_fit` and :func:`fit_or_farkas`
(``HAVE_FIT_OR_FARKAS``), ``solvers/numerics/nnls.py``; :func:`polygon_vertices` and :func:`polygon_ball`,
``solvers/numerics/polygon.py``; :func:`closed_rows` and :func:`row_bounds`, ``solvers/numerics/closed_set.py``;
:func:`assemble_scene`, ``laws/assemble.py::assemble_numpy``; :func:`stack_rows`,
numpy's ``array`` of small vectors).
Each wrapper takes its kernel's arguments, makes
them C-contiguous, and returns what the kernel returns; the C code makes the
kernels' choices in the kernels' order of arithmetic. ``_lemke`` also runs the fast path's whole kernel
(:func:`solve_split_lcp`), and ``LEMKE_ADDRESS`` is where its Lemke's method starts as a plain C function on raw
pointers, which the numba install's kernels call (``solvers/numerics/lemke.py``).
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

API_VERSION = 7  # the _lemke.c these wrappers call (its module attribute api_version)


def _load(name: str) -> Any:
    """The extension module ``name``, or None where it was not built (no C compiler: callers fall back to numpy)."""
    try:  # by name: a typed import would make mypy read the whole package from this leaf
        return importlib.import_module(name)
    except ImportError:
        return None


extension: Any = _load("quasistatic._lemke")
kernels: Any = _load("quasistatic._kernels")
if extension is not None and getattr(extension, "api_version", 1) != API_VERSION:
    # An editable install keeps the .so of an older _lemke.c until it is built again: run without it, and say so.
    message = "quasistatic._lemke was built from an older source; run `pip install -e .` again to rebuild it"
    warnings.warn(message, RuntimeWarning, stacklevel=1)
    extension = None

__all__ = [
    "HAVE_EXTENSION",
    "HAVE_KERNELS",
    "LEMKE_ADDRESS",
    "lemke",
    "fixed_mode_system",
    "solve_split_lcp",
    "exact_newton",
    "NewtonTolerances",
    "audit_laws",
    "analyse_frictionless",
    "to_world",
    "drop_roundoff",
    "nonnegative_fit",
    "HAVE_FIT_OR_FARKAS",
    "fit_or_farkas",
    "polygon_vertices",
    "polygon_ball",
    "closed_rows",
    "row_bounds",
    "assemble_scene",
    "stack_rows",
    "HAVE_AUDIT_ROWS",
    "audit_rows",
]

HAVE_EXTENSION = extension is not None
HAVE_KERNELS = kernels is not None
# An editable install may keep a _kernels .so built before fit_or_farkas was added: its callers then take its twin.
HAVE_FIT_OR_FARKAS = HAVE_KERNELS and hasattr(kernels, "fit_or_farkas")
# quasistatic_lemke(n, M, q, d, max_pivots, tol, free, z, basis, pivots, work, rows) -> status; 0 when not built
LEMKE_ADDRESS: int = extension.lemke_address if HAVE_EXTENSION else 0


def lemke(M: np.ndarray, q: np.ndarray, d: np.ndarray, max_pivots: int, tol: float, free: int) -> tuple[int, np.ndarray, int, np.ndarray]:
    """Lemke's method in C: ``(status, z, pivots, basis)`` as ``solvers/numerics/lemke.py::lemke`` returns them.

    Parameters
    ----------
    M : (n, n) float array
    q, d : (n,) float arrays
    max_pivots : int
    tol : float
        Pivot tolerance and tie width, as the kernel's [-].
    free : int
        ``z[:free]`` are free: once basic they never leave (as the kernel's).

    Raises
    ------
    ValueError
        When the shapes disagree (``M`` not ``(n, n)`` or ``d`` not ``(n,)``).
    """
    n = q.shape[0]
    z = np.empty(n)
    basis = np.empty(n, np.int64)
    status, pivots = extension.lemke(
        np.ascontiguousarray(M, np.float64),
        np.ascontiguousarray(q, np.float64),
        np.ascontiguousarray(d, np.float64),
        max_pivots,
        tol,
        free,
        z,
        basis,
    )
    return status, z, pivots, basis


def fixed_mode_system(
    J: np.ndarray, b: np.ndarray, mu: np.ndarray, g: np.ndarray, x: np.ndarray, kind: np.ndarray, column: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fixed-mode laws in C: residual (N,), Jacobian (N, N) and forces (m, d), as ``laws/fixed_modes.py::system``.

    ``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,), ``x`` (N,), ``kind`` and
    ``column`` (m,) int as there; ``n`` must be ``J.shape[2]``.

    Raises
    ------
    ValueError
        When the shapes disagree, or a contact's kind or column would put its unknowns outside ``x``.
    """
    if J.ndim != 3 or J.shape[2] != n:
        raise ValueError(f"J must have shape (m, d, n) with n = {n}, not {J.shape}")
    size = x.shape[0]
    residual, jacobian, forces = np.empty(size), np.empty((size, size)), np.empty(J.shape[:2])
    extension.fixed_mode_system(
        *(np.ascontiguousarray(a, np.float64) for a in (J, b, mu, g, x)),
        np.ascontiguousarray(kind, np.int64),
        np.ascontiguousarray(column, np.int64),
        residual,
        jacobian,
        forces,
    )
    return residual, jacobian, forces


class NewtonTolerances(NamedTuple):
    """The tolerances of the fast path's Newton iterations (``quasistatic.tolerances``' values, passed in by the caller)."""

    cone_roundoff: float
    damping: float
    stop: float


def solve_split_lcp(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    frictional: np.ndarray,
    base: np.ndarray,
    exact: bool,
    free_twist: bool,
    gap_covering: float,
    max_realignments: int,
    dissipation_tol: float,
    mode_tol: float,
    pivot_tol: float,
    feasibility_tol: float,
    pivots_per_row: int,
    newton: NewtonTolerances,
) -> tuple[int, int, np.ndarray, np.ndarray, int, int]:
    """The fast path's kernel in C: ``(status, stage, q, c, pivots, realignments)`` as ``solvers/numerics/lcp.py::solve_split_lcp``.

    Arguments as there (``J`` (m, d, n), ``b`` (m, d), ``mu`` (m,), ``g`` (n,), ``frictional`` (f,) int,
    ``base`` (K,)), and the Newton iterations' tolerances.

    Raises
    ------
    ValueError
        When the shapes disagree, a frictional index is not a contact's, or ``exact`` is asked of 2-D contacts.
    """
    if J.ndim != 3:
        raise ValueError(f"J must have shape (m, d, n), not {J.shape}")
    m, d, n = J.shape
    q, c = np.empty(n), np.empty((m, d))
    status, stage, pivots, realignments = extension.solve_split_lcp(
        *(np.ascontiguousarray(a, np.float64) for a in (J, b, mu, g)),
        np.ascontiguousarray(frictional, np.int64),
        np.ascontiguousarray(base, np.float64),
        exact,
        free_twist,
        gap_covering,
        max_realignments,
        dissipation_tol,
        mode_tol,
        pivot_tol,
        feasibility_tol,
        pivots_per_row,
        *newton,
        q,
        c,
    )
    return status, stage, q, c, pivots, realignments


def exact_newton(
    J: np.ndarray,
    b: np.ndarray,
    mu: np.ndarray,
    g: np.ndarray,
    q: np.ndarray,
    c: np.ndarray,
    depth: float,
    patience: int,
    one_switch: bool,
    mode_tol: float,
    tol: float,
    newton: NewtonTolerances,
) -> tuple[bool, np.ndarray, np.ndarray]:
    """Newton's method on the exact 3-D fixed-mode laws in C: ``(converged, q, c)`` as ``solvers/numerics/lcp.py::_newton``.

    ``J`` (m, 3, n), ``b`` (m, 3), ``mu`` (m,), ``g`` (n,), the start ``q`` (n,) and ``c`` (m, 3), the start's
    penetration counted as closed ``depth``, the iterations without progress before a due mode switch ``patience``,
    whether a round switches only the first contact that must switch ``one_switch``, the mode and convergence
    tolerances, and the Newton iterations' tolerances.

    Raises
    ------
    ValueError
        When the shapes disagree.
    """
    if J.ndim != 3 or J.shape[1] != 3:
        raise ValueError(f"J must have shape (m, 3, n), not {J.shape}")
    q_out, c_out = np.empty(J.shape[2]), np.empty(J.shape[:2])
    arrays = (np.ascontiguousarray(a, np.float64) for a in (J, b, mu, g, q, c))
    converged = extension.exact_newton(*arrays, depth, patience, one_switch, mode_tol, tol, *newton, q_out, c_out)
    return bool(converged), q_out, c_out


def audit_laws(
    links: np.ndarray,
    contacts: np.ndarray,
    loads: np.ndarray,
    T: np.ndarray,
    f: np.ndarray,
    facets: np.ndarray,
    directions: np.ndarray,
    facet_scale: float,
    slide_speed: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The audit's laws in C: ``(sums (11,), velocities (m, d), slips (m, d), normal (m, 3))`` as ``check/audit.py::_laws_2d``
    (``T`` (bodies, 3)) or ``_laws_3d`` (``T`` (bodies, 6)) return them, from their arguments.

    Raises
    ------
    ValueError
        When the shapes disagree, or a contact's ``links`` name a body that is not there.
    """
    m, d = len(links), 2 if T.shape[-1] == 3 else 3
    sums, u, slips, normal = np.empty(11), np.empty((m, d)), np.empty((m, d)), np.empty((m, 3))
    kernels.audit_laws(
        np.ascontiguousarray(links, np.int64),
        *(np.ascontiguousarray(a, np.float64) for a in (contacts, loads, T, f, facets, directions)),
        facet_scale,
        slide_speed,
        sums,
        u,
        slips,
        normal,
    )
    return sums, u, slips, normal


def analyse_frictionless(
    Jn: np.ndarray,
    bn: np.ndarray,
    g: np.ndarray,
    q: np.ndarray,
    forces: np.ndarray,
    zero: float,
    motion_rank: float,
    force_rank: float,
    orthogonal: float,
    jacobi_max: int,
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]:
    """The frictionless LP pair's analysis in C: ``(residual, slack, support, tight, closed, motion_unique, forces_unique)``
    as ``solvers/lp.py::_analyse`` returns them; ``orthogonal`` and ``jacobi_max`` are its Jacobi rotations' limits.

    Raises
    ------
    ValueError
        When the shapes disagree (``Jn`` not ``(m, n)``, ``bn`` and ``forces`` not ``(m,)``, ``g`` and ``q`` not ``(n,)``).
    """
    m = len(bn)
    slack, support, tight, closed = np.empty(m), np.empty(m, bool), np.empty(m, bool), np.empty(m, bool)
    residual, motion_unique, forces_unique = kernels.analyse_frictionless(
        *(np.ascontiguousarray(a, np.float64) for a in (Jn, bn, g, q, forces)),
        zero,
        motion_rank,
        force_rank,
        orthogonal,
        jacobi_max,
        slack,
        support,
        tight,
        closed,
    )
    return residual, slack, support, tight, closed, motion_unique, forces_unique


def to_world(q: np.ndarray, c: np.ndarray, frames: np.ndarray, units: np.ndarray, force: float) -> tuple[np.ndarray, np.ndarray]:
    """Physical twists (bodies, k) and world forces (m, d) in C, as ``laws/motion.py::_to_world_kernel`` returns them.

    ``q`` (bodies * k,), ``c`` (m, d), ``frames`` (m, d, d), ``units`` (k,), ``force`` [force].

    Raises
    ------
    ValueError
        When the shapes disagree (``q``'s length not a multiple of ``k``, ``frames`` not ``(m, d, d)``).
    """
    k = len(units)
    T, forces = np.empty((len(q) // max(k, 1), k)), np.empty(c.shape)
    kernels.to_world(*(np.ascontiguousarray(a, np.float64) for a in (q, c, frames, units)), force, T, forces)
    return T, forces


def drop_roundoff(values: np.ndarray, roundoff: np.ndarray) -> np.ndarray:
    """``values`` (rows, c), a C-contiguous float64 array, with entries within ``roundoff[j]`` of zero set to 0 in place, in C.

    Raises
    ------
    ValueError
        When ``values`` is not a writable C-contiguous float64 array, or ``roundoff`` is not ``(c,)``.
    """
    kernels.drop_roundoff(values, np.ascontiguousarray(roundoff, np.float64))
    return values


def nonnegative_fit(A: np.ndarray, keep: np.ndarray, b: np.ndarray, x: np.ndarray, independent: float) -> float:
    """Non-negative least squares on the columns ``keep`` of ``A`` in C, as ``solvers/numerics/nnls.py::nonnegative_fit``:
    ``x`` (N,) filled, ``|A x - b|`` returned.

    ``A`` (m, N) C-contiguous float64, ``keep`` (N,) bool, ``b`` (m,), ``x`` (N,) a writable C-contiguous float64
    array; ``independent``: the kernel's ``INDEPENDENT`` [-].

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, or ``x`` cannot be filled.
    """
    return float(kernels.nonnegative_fit(A, keep, b, x, independent))


def fit_or_farkas(
    A: np.ndarray,
    keep: np.ndarray,
    b: np.ndarray,
    margin: float,
    ceiling: float,
    independent: float,
    x: np.ndarray,
    y: np.ndarray,
    bits: np.ndarray,
) -> int:
    """A non-negative fit, or a Farkas vector, in C, as ``solvers/numerics/nnls.py::fit_or_farkas``: ``x``, ``y`` and
    ``bits`` filled, the outcome (0: the fit balances, 1: ``y`` excludes the kept columns, 2: neither) returned.

    ``A`` (m, N) C-contiguous float64, ``keep`` ((N + 63) // 64,) int64 words (bit ``j`` of word ``j // 64``: column
    ``j``), ``b`` (m,); ``x`` (N,), ``y`` (m,) writable float64 and ``bits`` (words) writable int64;
    ``margin`` [-], ``ceiling`` (the Farkas check's force ceiling) [-], ``independent``: the fit's ``INDEPENDENT`` [-].

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, or an output cannot be filled.
    """
    return int(kernels.fit_or_farkas(A, keep, b, margin, ceiling, independent, x, y, bits))


def polygon_vertices(
    rates: np.ndarray, reserve: np.ndarray, rows: np.ndarray, parallel: float, skew: float, slack: float, vertices: np.ndarray
) -> int:
    """A polygon's vertices in C, as ``solvers/numerics/polygon.py::polygon_vertices``: ``vertices`` filled, their
    count (or -1: unbounded) returned.

    ``rates`` (R, 2), ``reserve`` (R,) C-contiguous float64, ``rows`` (R,) bool, ``vertices`` (pairs, 2) writable.

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, or ``vertices`` has fewer rows than the kept rows have pairs.
    """
    return int(kernels.polygon_vertices(rates, reserve, rows, parallel, skew, slack, vertices))


def polygon_ball(
    q0: np.ndarray,
    directions: np.ndarray,
    vertices: np.ndarray,
    seed: np.ndarray,
    spread: np.ndarray,
    same: float,
    distinct: float,
    center: np.ndarray,
) -> float:
    """The ball around a polygon of twists in C, as ``solvers/numerics/polygon.py::polygon_ball``: ``center`` filled,
    the radius returned (-1: every twist in the seed's box).

    ``q0`` (n,), ``directions`` (2, n), ``vertices`` (V, 2) with ``V >= 1``, ``seed`` (n,) or (0,), ``spread`` (n,)
    C-contiguous float64; ``center`` (n,) writable.

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, there is no vertex, or ``center`` cannot be filled.
    """
    return float(kernels.polygon_ball(q0, directions, vertices, seed, spread, same, distinct, center))


def closed_rows(
    E: np.ndarray,
    e: np.ndarray,
    by_rank: bool,
    rank: float,
    orthogonal: float,
    zero: float,
    sigma: np.ndarray,
    basis: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    spread: np.ndarray,
) -> tuple[int, float]:
    """Closed rows factored by Jacobi rotations in C, as ``solvers/numerics/closed_set.py::closed_rows``: the arrays
    filled, the ranks kept and the squared residual returned.

    ``E`` (k, n), ``e`` (k,) C-contiguous float64; ``sigma`` (n,), ``basis`` (n, n), ``inverse`` (n, k), ``q0`` and
    ``spread`` (n,) writable C-contiguous float64.

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, or an output cannot be filled.
    """
    r, square = kernels.closed_rows(E, e, by_rank, rank, orthogonal, zero, sigma, basis, inverse, q0, spread)
    return int(r), float(square)


def row_bounds(
    bank: np.ndarray,
    rhs: np.ndarray,
    inverse: np.ndarray,
    q0: np.ndarray,
    directions: np.ndarray,
    rows: np.ndarray,
    slack: float,
    reserve: np.ndarray,
    rates: np.ndarray,
) -> None:
    """Bank rows' best slacks and rates over a closed set in C, as ``solvers/numerics/closed_set.py::row_bounds``:
    ``reserve`` and ``rates`` filled at ``rows``.

    ``bank`` (R, n), ``rhs`` (R,), ``inverse`` (n, k), ``q0`` (n,), ``directions`` (f, n) with ``f <= 2`` float64,
    ``rows`` (I,) int64 in ``[0, R)``; ``reserve`` (R,) and ``rates`` (R, 2) writable C-contiguous float64.

    Raises
    ------
    ValueError
        When the shapes or dtypes disagree, a row is out of range, or ``reserve`` or ``rates`` cannot be filled.
    """
    kernels.row_bounds(bank, rhs, inverse, q0, directions, rows, slack, reserve, rates)


def assemble_scene(
    normals: np.ndarray,
    points: np.ndarray,
    coms: np.ndarray,
    owners: np.ndarray,
    others: np.ndarray,
    twists: np.ndarray,
    origins: np.ndarray,
    places: np.ndarray,
    driven: np.ndarray,
    wrenches: np.ndarray,
    masses: np.ndarray,
    gravity: np.ndarray,
    smallest_length: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, tuple[float, float, float]]:
    """A scene's contact laws in C, as ``laws/assemble.py::assemble_numpy`` computes them from its numbers: frames
    (m, d, d), ``J`` (m, d, k bodies), ``b`` (m, d), ``g`` (k bodies,), the scales' origin (d,) and their length,
    force and velocity.

    The contacts' ``normals``, ``points`` (m, d), ``owners`` and ``others`` (their bodies' indices; -1 for a
    mover), the movers' parts (``model/kinematics.py::mover_parts``), the bodies' ``coms`` (bodies, d), ``wrenches``
    (bodies, k) and ``masses``, ``gravity`` (d,), and the least length the scales take for coincident points.

    Raises
    ------
    ValueError
        When the shapes disagree, there is no contact, or a contact's body index is outside the bodies.
    """
    m, d = normals.shape
    k, bodies = (3 if d == 2 else 6), len(coms)
    frames, J, b, out = np.empty((m, d, d)), np.zeros((m, d, k * bodies)), np.empty((m, d)), np.empty(k * bodies + d + 3)
    arrays = (normals, points, coms, owners, others, twists, origins, places, driven, wrenches, masses, gravity)
    try:  # a scene's kept numbers already are C-contiguous of their dtypes (the kernel checks each before it computes)
        kernels.assemble_scene(*arrays, smallest_length, frames, J, b, out)
    except ValueError:  # converted where one is not; the kernel's other refusals are raised again
        types = (np.float64,) * 3 + (np.int64,) * 2 + (np.float64,) * 7
        kernels.assemble_scene(*map(np.ascontiguousarray, arrays, types), smallest_length, frames, J, b, out)
    g, scales = out[: k * bodies], out[k * bodies :]
    return frames, J, b, g, scales[:d].copy(), (float(scales[d]), float(scales[d + 1]), float(scales[d + 2]))


def stack_rows(rows: Sequence[np.ndarray], width: int) -> np.ndarray:
    """``np.array(rows, dtype=float)`` of 1-D float vectors of length ``width``, (len(rows), width), copied in C
    (numpy's conversion of a list of small arrays costs ~10x more); numpy's where the extension was not built or a
    row is not a C-contiguous float64 vector of that length."""
    if kernels is None:  # not built: numpy's, the same numbers
        return np.array(rows, dtype=float).reshape(len(rows), width)
    out = np.empty((len(rows), width))
    try:
        kernels.stack_rows(rows, out)
    except ValueError:
        return np.array(rows, dtype=float).reshape(len(rows), width)
    return out


HAVE_AUDIT_ROWS = HAVE_KERNELS and hasattr(kernels, "audit_rows")  # an extension built before it lacks it


def audit_rows(
    normals: np.ndarray,
    points: np.ndarray,
    coms: np.ndarray,
    links: np.ndarray,
    twists: np.ndarray,
    origins: np.ndarray,
    driven: np.ndarray,
    through_joints: np.ndarray,
    mu: np.ndarray,
) -> np.ndarray:
    """The audit's contact rows in C, as ``check/audit.py::_read_geometry``'s Python loop computes them: (m, 1 + d (d + 3)),
    each ``(normal, tangents, arm from the body's com, arm from the other free body's com or zeros, the mover's point
    velocity or zeros, mu)``.

    ``normals`` and ``points`` (m, d), ``coms`` (bodies, d), ``links`` (m, 2) int64 (body, other; -1 a mover), each
    contact's mover ``twists`` (m, k) and ``origins`` (m, d), ``driven`` (m, d) the point velocity of the contacts
    ``through_joints`` (m,) bool (a robot's link: taken as it is), ``mu`` (m,).

    Raises
    ------
    ValueError
        When the shapes disagree or a link is outside the bodies.
    """
    m, d = normals.shape
    rows = np.empty((m, 1 + d * (d + 3)))
    floats = [np.ascontiguousarray(a, np.float64) for a in (normals, points, coms)]
    rest = [np.ascontiguousarray(a, np.float64) for a in (twists, origins, driven)]
    joints = np.ascontiguousarray(through_joints, np.bool_)
    kernels.audit_rows(*floats, np.ascontiguousarray(links, np.int64), *rest, joints, np.ascontiguousarray(mu, np.float64), rows)
    return rows
