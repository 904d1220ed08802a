"""Assembly: a Scene becomes the matrices of the contact laws, in scene-relative units.

Every quantity is divided by the scene's own scales (length, force, velocity,
:class:`~quasistatic.model.Scales`), so one tolerance serves a scene in
millimetres and grams as well as one in metres and kilograms, and the answer
does not depend on where the world origin is.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple, TypeVar, cast

import numpy as np

from ..compiled import HAVE_KERNELS, stack_rows
from ..compiled import assemble_scene as compiled_assemble
from ..model import FloatArray, FrictionModel, Scales, Scene, scene_scales
from ..model.kinematics import contact_frames, cross, mover_parts, mover_point_velocities
from ..tolerances import SMALLEST_LENGTH

__all__ = ["Problem", "SceneNumbers", "assemble", "scene_numbers"]

T = TypeVar("T")
_FRICTIONLESS = "frictionless"  # the derived key of Problem.is_frictionless, which assembly may fill from the scene


@dataclass(frozen=True)
class Problem:
    """The contact laws of one scene in scene-relative units.

    With ``k`` = 3 (2-D) or 6 (3-D) twist entries per body, ``n`` free bodies,
    ``m`` contacts and ``d`` the dimension:

    Attributes
    ----------
    scene : Scene
        The scene this was assembled from (names, order, original data).
    frames : (m, d, d)
        Rows of each contact frame: the tangent(s), then the normal (into ``body``).
    J : (m, d, k n)
        Relative contact velocity per unit twist, in contact frames: ``u = J q - b``.
    b : (m, d)
        Velocity of the other body's material point (movers only), in contact frames.
    g : (k n,)
        Gravity plus applied wrench on each body, about its com.
    mu : (m,)
        Friction coefficients [-], zero under ``friction: none``.
    friction : FrictionModel
    scales : Scales
    """

    scene: Scene
    frames: FloatArray
    J: FloatArray
    b: FloatArray
    g: FloatArray
    mu: FloatArray
    friction: FrictionModel
    scales: Scales
    _derived: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __getstate__(self) -> dict[str, Any]:
        # What a solve derived from this problem is rebuilt where it is needed, not pickled.
        return {key: value for key, value in self.__dict__.items() if key != "_derived"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state, _derived={})

    def derived(self, key: str, build: Callable[[Problem], T]) -> T:
        """``build(self)``, computed once and kept with this problem (problems are frozen).

        For what a solver derives from a problem on every solve (contiguous
        copies, index arrays, names): solving the same problem again, as
        benchmarks, batches and simulations do, skips that work. ``key`` names
        the derived value; one key, one ``build``.
        """
        values = self._derived
        if key not in values:
            values[key] = build(self)
        return cast(T, values[key])

    @property
    def dimension(self) -> int:
        return self.scene.dimension

    @property
    def n_contacts(self) -> int:
        return int(self.J.shape[0])

    @property
    def n_dof(self) -> int:
        return int(self.J.shape[2])

    @property
    def Jn(self) -> FloatArray:
        """Normal rows of J, (m, k n)."""
        return self.J[:, -1, :]

    @property
    def Jt(self) -> FloatArray:
        """Tangent rows of J, (m, d - 1, k n)."""
        return self.J[:, :-1, :]

    @property
    def bn(self) -> FloatArray:
        return self.b[:, -1]

    @property
    def bt(self) -> FloatArray:
        return self.b[:, :-1]

    @property
    def is_frictionless(self) -> bool:
        return self.derived(_FRICTIONLESS, lambda p: not (p.mu > 0.0).any())  # (np.any's dispatch costs 5x more)

    def velocities(self, q: FloatArray) -> FloatArray:
        """Relative contact velocities ``u = J q - b`` in contact frames, (m, d), at the scene-relative twist ``q``."""
        return np.einsum("mdn,n->md", self.J, q) - self.b


def assemble(scene: Scene) -> Problem:
    """Build the scene-relative matrices of the contact laws (all contacts at once).

    In the extension's C where it was built (one call for what costs two dozen small numpy calls on a few
    contacts), else by :func:`assemble_numpy`: the same arithmetic in the same order, so the same bits.
    The scene's numbers are gathered once per scene (:func:`scene_numbers`, kept with it): a scene solved
    again pays for the C call and the Problem only.
    """
    if not (HAVE_KERNELS and scene.contacts):
        return assemble_numpy(scene)
    n = scene.derived("assembly_numbers", scene_numbers)
    movers = (n.twists, n.origins, n.places, n.driven)
    laws = compiled_assemble(n.normals, n.points, n.coms, n.owners, n.others, *movers, n.wrenches, n.masses, scene.gravity, SMALLEST_LENGTH)
    frames, J, b, g, origin, (length, force, velocity) = laws
    origin.setflags(write=False)
    scales = Scales(length=length, force=force, velocity=velocity, origin=origin)
    problem = Problem(scene, frames, J, b, g, n.mu.copy(), scene.friction, scales)
    problem._derived[_FRICTIONLESS] = n.frictionless  # known from the scene: no array reduction per problem
    return problem


class SceneNumbers(NamedTuple):
    """What the C assembly reads of a scene, gathered into read-only arrays (kept with the scene).

    Attributes
    ----------
    normals, points : (m, d) the contacts' world normals and points
    coms : (bodies, d) the bodies' centres of mass
    owners, others : (m,) each contact's body and other body as indices into the bodies (-1: a mover)
    twists, origins, places, driven : the movers' parts (:func:`~quasistatic.model.kinematics.mover_parts`)
    wrenches : (bodies, k) applied wrenches; masses : (bodies,)
    mu : (m,) friction coefficients [-], zero under ``friction: none``
    frictionless : no contact has mu > 0 (:attr:`Problem.is_frictionless`)
    """

    normals: FloatArray
    points: FloatArray
    coms: FloatArray
    owners: np.ndarray
    others: np.ndarray
    twists: FloatArray
    origins: FloatArray
    places: FloatArray
    driven: FloatArray
    wrenches: FloatArray
    masses: FloatArray
    mu: FloatArray
    frictionless: bool


def scene_numbers(scene: Scene) -> SceneNumbers:
    """The numbers :func:`assemble` hands the compiled kernel, read from ``scene`` (frozen: they can be kept)."""
    wrenches = stack_rows([cast(FloatArray, body.wrench) for body in scene.bodies], scene.twist_size)  # a Scene fills each
    masses = np.array([body.mass for body in scene.bodies], dtype=float)
    arrays = (*_contact_numbers(scene), *mover_parts(scene), wrenches, masses, _friction_coefficients(scene))
    for array in arrays:
        array.setflags(write=False)
    mu = arrays[-1]
    return SceneNumbers(*arrays, frictionless=not (mu > 0.0).any())


def assemble_numpy(scene: Scene) -> Problem:
    """:func:`assemble` in numpy (the C kernel's twin, and what runs where the extension was not built)."""
    dim, k = scene.dimension, scene.twist_size
    movers = mover_point_velocities(scene)
    scales = scene_scales(scene, movers)
    L, V = scales.length, scales.velocity
    normals, points, coms, body, other = _contact_numbers(scene)
    m, n_bodies = len(normals), len(coms)
    coms, points = (coms - scales.origin) / L, (points - scales.origin) / L
    frames = contact_frames(normals)
    J = np.zeros((m, dim, k * n_bodies))
    rows = np.arange(m)
    _add_blocks(J, rows, body, _twist_rows(frames, points - coms[body]), k)
    pair = other >= 0  # a contact between two free bodies: the other body's motion counts against
    if n_bodies > 1 and pair.any():  # (one free body touches only movers: skip four empty numpy calls)
        _add_blocks(J, rows[pair], other[pair], -_twist_rows(frames[pair], points[pair] - coms[other[pair]]), k)
    b = frames[:, :, 0] * movers[:, None, 0]  # summed in order (einsum's order depends on its build)
    for j in range(1, dim):
        b += frames[:, :, j] * movers[:, None, j]
    g = np.concatenate([scene.load(body) / scales.wrench_units(dim) for body in scene.bodies])
    return Problem(scene, frames, J, b / V, g, _friction_coefficients(scene), scene.friction, scales)


def _contact_numbers(scene: Scene) -> tuple[FloatArray, FloatArray, FloatArray, np.ndarray, np.ndarray]:
    """World normals and points (m, d), the bodies' coms (bodies, d), and each contact's body and other body as
    indices into the bodies (-1: a mover), as both assemblies read them."""
    dim, contacts, bodies = scene.dimension, scene.contacts, scene.bodies
    index = {body.name: i for i, body in enumerate(bodies)}
    normals = stack_rows([c.normal for c in contacts], dim)
    points = stack_rows([c.point for c in contacts], dim)
    coms = stack_rows([body.com for body in bodies], dim)
    owners = np.array([index[c.body] for c in contacts], dtype=np.int64)
    others = np.array([index.get(c.other, -1) for c in contacts], dtype=np.int64)
    return normals, points, coms, owners, others


def _friction_coefficients(scene: Scene) -> FloatArray:
    return np.array([c.mu for c in scene.contacts]) if scene.friction.kind != "none" else np.zeros(len(scene.contacts))


def _twist_rows(frames: FloatArray, arms: FloatArray) -> FloatArray:
    """Each frame row's velocity per unit body twist, for contacts at ``arms`` from the com: (m, d, k).

    A row ``f`` of a frame measures ``f . (v + omega x r) = f . v + omega . (r x f)``.
    """
    m, d = frames.shape[:2]
    rows = np.empty((m, d, 3 if d == 2 else 6))  # filled in place: a concatenation costs more on small scenes
    rows[:, :, :d] = frames
    if d == 2:
        rows[:, :, 2] = arms[:, None, 0] * frames[:, :, 1] - arms[:, None, 1] * frames[:, :, 0]
    else:
        rows[:, :, 3:] = cross(arms[:, None, :], frames)
    return rows


def _add_blocks(J: FloatArray, rows: np.ndarray, bodies: np.ndarray, blocks: FloatArray, k: int) -> None:
    """``J[row, :, body block] += block`` for each contact (each row once per call)."""
    by_body = J.reshape(J.shape[0], J.shape[1], J.shape[2] // k, k)  # a view: (m, d, bodies, k)
    by_body[rows, :, bodies, :] += blocks
