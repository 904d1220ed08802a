"""Interval arithmetic on numpy arrays, rounded outwards, and Krawczyk's test for a unique zero in a box.

Every operation rounds to nearest and then widens each end by one unit in the
last place (``np.nextafter``), so the true result of the operation on any
points of its operands lies inside (IEEE arithmetic errs by at most half a
unit). Products of a point matrix with an interval vector or matrix
(:func:`matmul`) work in midpoint-radius form and add a bound on the
rounding of the sums.

A box holding the solutions of every linear system of an interval family
(:func:`linear_solutions`) bounds the exact-cone certificate's forces.

Only what the exact-cone certificate needs is here (:mod:`quasistatic.laws.fixed_modes`
encloses its laws over a box with it): no library for interval arithmetic is a
dependency of the project, and this much is short.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["Interval", "point", "matmul", "krawczyk", "KrawczykTest", "linear_solutions", "unit_vectors"]

FloatArray = npt.NDArray[np.float64]
_EPS = float(np.finfo(float).eps)


def _down(x: FloatArray) -> FloatArray:
    return np.nextafter(x, -np.inf)


def _up(x: FloatArray) -> FloatArray:
    return np.nextafter(x, np.inf)


@dataclass(frozen=True)
class Interval:
    """Arrays of lower and upper ends (same shape), ``lo <= hi`` entrywise."""

    lo: FloatArray
    hi: FloatArray

    @property
    def mid(self) -> FloatArray:
        return 0.5 * (self.lo + self.hi)

    @property
    def rad(self) -> FloatArray:
        """Half-widths, rounded up: ``[mid - rad, mid + rad]`` holds the interval."""
        return _up(np.maximum(self.hi - self.mid, self.mid - self.lo))

    def __getitem__(self, key: Any) -> Interval:
        return Interval(self.lo[key], self.hi[key])

    def __add__(self, other: Interval | FloatArray | float) -> Interval:
        lo, hi = _ends(other)
        return Interval(_down(self.lo + lo), _up(self.hi + hi))

    __radd__ = __add__

    def __neg__(self) -> Interval:
        return Interval(-self.hi, -self.lo)

    def __sub__(self, other: Interval | FloatArray | float) -> Interval:
        lo, hi = _ends(other)
        return Interval(_down(self.lo - hi), _up(self.hi - lo))

    def __mul__(self, other: Interval | FloatArray | float) -> Interval:
        lo, hi = _ends(other)
        a, b, c, d = self.lo * lo, self.lo * hi, self.hi * lo, self.hi * hi  # pairwise: no stacked copy (measured 2x)
        return Interval(_down(np.minimum(np.minimum(a, b), np.minimum(c, d))), _up(np.maximum(np.maximum(a, b), np.maximum(c, d))))

    __rmul__ = __mul__

    def square(self) -> Interval:
        """``x**2`` (tighter than ``x * x``: never negative)."""
        low, high = self.lo * self.lo, self.hi * self.hi
        straddles = (self.lo < 0.0) & (self.hi > 0.0)
        return Interval(np.where(straddles, 0.0, _down(np.minimum(low, high))), _up(np.maximum(low, high)))

    def sqrt(self) -> Interval:
        """Square root of a non-negative interval (negative lower ends are taken as 0)."""
        return Interval(_down(np.sqrt(np.maximum(self.lo, 0.0))), _up(np.sqrt(np.maximum(self.hi, 0.0))))

    def reciprocal(self) -> Interval:
        """``1 / x`` of an interval that excludes 0 (the caller checks)."""
        if np.any((self.lo <= 0.0) & (self.hi >= 0.0)):
            raise ZeroDivisionError("interval reciprocal of an interval holding 0")
        return Interval(_down(1.0 / self.hi), _up(1.0 / self.lo))

    def sum(self, axis: int | None = None) -> Interval:
        return Interval(_down(self.lo.sum(axis=axis)) - _sum_error(self.lo, axis), _up(self.hi.sum(axis=axis)) + _sum_error(self.hi, axis))

    def inside(self, other: Interval) -> bool:
        """Whether this interval lies in the interior of ``other`` (every entry)."""
        return bool(np.all(self.lo > other.lo) and np.all(self.hi < other.hi))


def point(x: FloatArray) -> Interval:
    """The degenerate interval ``[x, x]``."""
    x = np.asarray(x, dtype=float)
    return Interval(x, x.copy())


def _ends(value: Interval | FloatArray | float) -> tuple[FloatArray | float, FloatArray | float]:
    if isinstance(value, Interval):
        return value.lo, value.hi
    return value, value


def _sum_error(terms: FloatArray, axis: int | None) -> FloatArray:
    """A bound on the rounding error of a floating-point sum of ``terms`` (Higham: (k - 1) eps sum |t|)."""
    count = terms.size if axis is None else terms.shape[axis]
    return _up(1.01 * count * _EPS * np.abs(terms).sum(axis=axis))


def matmul(A: npt.NDArray[np.floating[Any]] | Interval, x: Interval) -> Interval:
    """An enclosure of ``A @ x`` for a point or interval matrix ``A`` and an interval vector or matrix ``x``."""
    if isinstance(A, Interval):
        Am, Ar = A.mid, A.rad
    else:
        Am, Ar = np.asarray(A, dtype=float), np.zeros(np.shape(A))
    xm, xr = x.mid, x.rad
    centre = Am @ xm
    spread = np.abs(Am) @ xr + Ar @ (np.abs(xm) + xr)
    k = Am.shape[-1]
    rounding = 1.01 * (k + 2) * _EPS * (np.abs(Am) @ np.abs(xm) + spread) + np.finfo(float).tiny
    radius = _up(spread + rounding)
    return Interval(_down(centre - radius), _up(centre + radius))


@dataclass(frozen=True)
class KrawczykTest:
    """Krawczyk's verdict (``unique``: exactly one zero in the box, proven) and the row-sum norm of
    ``|I - Y F'(box)|`` in the box's own scale (``D^-1 |I - Y F'| D``, ``D`` the box's half-widths), which must be
    below 1 for the test to pass: a box that fails shrinks by about it (its entries may differ by orders of
    magnitude, twists against forces: the unscaled norm says little of how far the box is from passing)."""

    unique: bool
    contraction: float
    image: Interval | None = None  # Krawczyk's operator: every zero of the box lies in it


def krawczyk(center: FloatArray, box: Interval, residual: Interval, jacobian: Interval) -> KrawczykTest:
    """Krawczyk's test for a unique zero of ``F`` in ``box``.

    ``residual`` encloses ``F(center)`` (``center`` a point of ``box``) and ``jacobian`` encloses ``F'`` over the
    whole box. With ``Y`` an approximate inverse of the Jacobian at the centre, the operator
    ``K = center - Y F(center) + (I - Y F'(box)) (box - center)`` holds every zero of ``F`` in the box, and
    ``K`` inside the box's interior proves there is one, and only one (Krawczyk 1969; Moore, Kearfott and
    Cloud, *Introduction to Interval Analysis*, section 8.2).
    """
    try:
        Y = np.linalg.inv(jacobian.mid)
    except np.linalg.LinAlgError:
        return KrawczykTest(False, np.inf)
    if not np.all(np.isfinite(Y)):
        return KrawczykTest(False, np.inf)
    identity = np.eye(center.size)
    contraction = Interval(identity, identity.copy()) - matmul(Y, jacobian)
    radius = box.rad
    with np.errstate(divide="ignore", invalid="ignore"):  # a flat side (radius 0) cannot hold K inside it
        scaled = (_magnitude(contraction) @ radius) / radius
    norm = float(np.max(np.where(radius > 0.0, scaled, np.inf), initial=0.0))
    K = point(center) - matmul(Y, residual) + matmul(contraction, box - center)
    return KrawczykTest(K.inside(box), norm, K)


def linear_solutions(A: Interval, b: Interval) -> Interval | None:
    """A box holding the solution of ``A x = b`` for every square matrix of ``A`` and vector of ``b``; None where
    the preconditioned family is not proven regular.

    With ``C`` an approximate inverse of ``A.mid``, ``x~ = C b.mid`` and ``G`` enclosing ``I - C A``: the error
    ``e = x - x~`` solves ``e = C (b - A x~) + (I - C A) e``, so with ``beta = ||G||_inf < 1`` (which makes every
    ``A`` regular) ``||e|| <= ||r|| / (1 - beta)`` for ``r`` enclosing ``C (b - A x~)``, and entry by entry
    ``|e| <= |r| + |G| ||e||`` (Rump's residual bound; Neumaier, *Interval Methods for Systems of Equations*, 4.1).
    """
    try:
        C = np.linalg.inv(A.mid)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(C)):
        return None
    approximate = C @ b.mid
    identity = np.eye(approximate.size)
    G = _magnitude(Interval(identity, identity.copy()) - matmul(C, A))
    r = _magnitude(matmul(C, b - matmul(A, point(approximate))))
    beta = float(_up_sum(G).max(initial=0.0))
    if not beta < 1.0:
        return None
    norm = float(_up(np.max(r, initial=0.0) / _down(np.array(1.0 - beta))))
    error = _up(r + _up_sum(G * norm))  # the products' rounding is within the sum's error allowance
    return Interval(_down(approximate - error), _up(approximate + error))


def _magnitude(x: Interval) -> FloatArray:
    """``max |v|`` over each entry's interval (exact)."""
    return np.maximum(np.abs(x.lo), np.abs(x.hi))


def _up_sum(terms: FloatArray) -> FloatArray:
    """An upper bound on each row's sum of the non-negative ``terms``."""
    return _up(terms.sum(axis=-1)) + _sum_error(terms, -1)


def unit_vectors(lo: FloatArray, hi: FloatArray) -> Interval:
    """Boxes (k, 2) holding ``(cos a, sin a)`` for every angle ``a`` in ``[lo, hi]`` [rad] (each of the k arcs
    shorter than a turn)."""
    ends_cos, ends_sin = np.stack([np.cos(lo), np.cos(hi)]), np.stack([np.sin(lo), np.sin(hi)])
    # an extreme is reached inside the arc where the arc holds its angle (0 and pi for cos, +-pi/2 for sin)
    inside = [np.floor((hi - at) / (2.0 * np.pi)) * 2.0 * np.pi + at >= lo for at in (0.0, np.pi, 0.5 * np.pi, -0.5 * np.pi)]
    cos_lo, cos_hi = np.where(inside[1], -1.0, ends_cos.min(axis=0)), np.where(inside[0], 1.0, ends_cos.max(axis=0))
    sin_lo, sin_hi = np.where(inside[3], -1.0, ends_sin.min(axis=0)), np.where(inside[2], 1.0, ends_sin.max(axis=0))
    slack = 4.0 * _EPS  # numpy's cos and sin err by less than an ulp of 1, and the extremes' angles by rounding
    return Interval(np.stack([cos_lo, sin_lo], axis=1) - slack, np.stack([cos_hi, sin_hi], axis=1) + slack)
