"""Infeasible LPs proven by Farkas vectors, checked on the LP's own data.

``row_lower <= A x <= row_upper, col_lower <= x <= col_upper`` has no point exactly when some multipliers ``y``
on its rows (positive on a lower bound, negative on an upper one) bound ``y.(A x)`` from below above the most
that ``A^T y`` can reach over the column bounds (Farkas' lemma). :func:`proves_infeasible` checks such a vector,
wherever it came from: HiGHS's dual ray (:mod:`.highs`), or a non-negative fit (:func:`infeasible_by_fit`).

A HiGHS run costs ~0.3-1 ms whatever the LP's size, while the branch and bound's leaves ask thousands of small,
mostly infeasible LPs (a twist of 6 entries and tens of rows). For those, the Farkas vector is sought directly:
writing every finite bound as an inequality ``G x >= h``, a vector ``z >= 0`` with ``G^T z = 0`` and
``h.z = 1`` is a non-negative solution of ``[G^T; h^T] z = e_last``, which the branch and bound's compiled
non-negative least-squares fit (:func:`.nnls.nonnegative_fit`, microseconds) finds where one exists.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...tolerances import FARKAS_ROUNDOFF
from .nnls import nonnegative_fit

__all__ = ["Bounds", "proves_infeasible", "infeasible_by_fit", "FIT_COLUMNS"]

Bounds = tuple[np.ndarray | None, np.ndarray | None]  # least and greatest values; None: unbounded
FIT_COLUMNS = 12  # the most columns an LP may have for infeasible_by_fit (a twist's 6 and the kinematic LPs' dofs)


def proves_infeasible(y: np.ndarray, A: np.ndarray | sp.spmatrix, rows: Bounds, columns: Bounds, slack: float = 0.0) -> bool:
    """Whether the row multipliers ``y`` prove that no ``x`` meets ``rows`` (with every row loosened by ``slack``
    more) within ``columns``: the rows give ``y.(A x) >= sum(y_i lower_i, y_i > 0) + sum(y_i upper_i, y_i < 0)
    - slack sum|y_i|``, while ``w = A^T y`` and the column bounds cap ``w.x`` below that. Round-off
    (:data:`FARKAS_ROUNDOFF`) is taken as zero, so the proof holds for points of the LP's own scale, not for
    ones 1e12 times larger."""
    y = np.array(y, dtype=float)
    if not y.size:
        return False
    size = np.abs(y)
    y[size <= FARKAS_ROUNDOFF * size.max()] = 0.0
    w = np.asarray(A.T @ y, dtype=float)
    w[np.abs(w) <= FARKAS_ROUNDOFF * np.asarray(abs(A).T @ np.abs(y), dtype=float)] = 0.0
    by_rows = _least_terms(y, *rows)  # sum: the least y.(A x) the rows allow
    by_columns = _least_terms(-w, *columns)  # sum: minus the most w.x the columns allow
    if by_rows is None or by_columns is None:
        return False
    margin = FARKAS_ROUNDOFF * (np.abs(by_rows).sum() + np.abs(by_columns).sum()) + slack * np.abs(y).sum()
    return bool(by_rows.sum() + by_columns.sum() > margin)


def infeasible_by_fit(A: np.ndarray, rows: Bounds, columns: Bounds, slack: float) -> bool:
    """Whether a Farkas vector found by a non-negative fit proves the LP has no point, even with every row
    loosened by ``slack`` more (:func:`proves_infeasible`); False where none is found (the LP may have one).
    For dense LPs of at most :data:`FIT_COLUMNS` columns (else False)."""
    n = A.shape[1]
    if n > FIT_COLUMNS or not A.shape[0]:
        return False
    inequalities = _Inequalities.of(A, rows, columns)
    G, h = inequalities.G, inequalities.h
    norms = np.maximum(np.sqrt(np.einsum("ij,ij->i", G, G) + h * h), np.finfo(float).tiny)  # each row to unit size
    system = np.ascontiguousarray(np.vstack([G.T, h[None, :]]) / norms)
    target = np.zeros(n + 1)
    target[n] = 1.0
    z = np.empty(h.size)
    nonnegative_fit(system, np.ones(h.size, dtype=np.bool_), target, z)
    return proves_infeasible(inequalities.row_multipliers(z / norms, A.shape[0]), A, rows, columns, slack)


@dataclass(frozen=True)
class _Inequalities:
    """Every finite bound of an LP as a row of ``G x >= h``: a row of ``A`` (``owner``; ``sign`` +1 for its lower
    bound, -1 for its upper one) or a column's bound (``owner`` -1: the check reads column bounds itself)."""

    G: np.ndarray
    h: np.ndarray
    owner: np.ndarray
    sign: np.ndarray

    @classmethod
    def of(cls, A: np.ndarray, rows: Bounds, columns: Bounds) -> _Inequalities:
        n = A.shape[1]
        parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, float]] = []
        for matrix, bounds, owners in ((A, rows, np.arange(A.shape[0])), (np.eye(n), columns, np.full(n, -1))):
            for bound, sign in zip(bounds, (1.0, -1.0), strict=True):
                if bound is not None:
                    finite = np.isfinite(bound)
                    parts.append((sign * matrix[finite], sign * bound[finite], owners[finite], sign))
        return cls(
            np.vstack([p[0] for p in parts] + [np.zeros((0, n))]),
            np.concatenate([p[1] for p in parts] + [np.zeros(0)]),
            np.concatenate([p[2] for p in parts] + [np.zeros(0, dtype=int)]),
            np.concatenate([np.full(p[2].size, p[3]) for p in parts] + [np.zeros(0)]),
        )

    def row_multipliers(self, z: np.ndarray, count: int) -> np.ndarray:
        """Multipliers ``z >= 0`` of the inequalities as one per row of ``A`` (a lower bound's ``+z``, an upper
        bound's ``-z``); the column bounds' are left out."""
        y = np.zeros(count)
        mine = self.owner >= 0
        np.add.at(y, self.owner[mine], self.sign[mine] * z[mine])
        return y


def _least_terms(v: np.ndarray, lower: np.ndarray | None, upper: np.ndarray | None) -> np.ndarray | None:
    """The terms of the least ``v.z`` over ``lower <= z <= upper`` (None: unbounded): ``v_i lower_i`` where
    ``v_i > 0``, ``v_i upper_i`` where ``v_i < 0``, zero where ``v_i`` is; None where one is infinite."""
    up, down = v > 0.0, v < 0.0
    if (lower is None and up.any()) or (upper is None and down.any()):
        return None
    terms = v * np.where(up, 0.0 if lower is None else lower, np.where(down, 0.0 if upper is None else upper, 0.0))
    return terms if np.isfinite(terms).all() else None
