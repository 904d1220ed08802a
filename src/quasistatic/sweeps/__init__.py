"""Sweeps: one scene solved over a grid of parameter values, serially, on local cores or on a Dask cluster.

- :func:`sweep`: the grid (Cartesian product), chunked, resumable from a chunk folder, with phase
  boundaries refined by bisection; every point audited as :func:`quasistatic.solve` audits it.
- :class:`SweepResult`: typed points, ``to_table`` (pyarrow), ``to_parquet``, ``to_csv``, ``phase_map``
  (drawn by :func:`quasistatic.viz.phase_diagram`).

Dask and pyarrow are the ``sweeps`` extra; a serial or joblib sweep without a chunk folder needs neither.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

if TYPE_CHECKING:
    from .params import SweepParam, parse_param_spec, parse_path
    from .result import SWEEPS_INSTALL_HINT, PhaseMap, SweepPoint, SweepResult
    from .run import sweep

# Each public name and the module (relative to this package) that defines it, imported when first read (PEP 562):
# the CLI checks ``--param`` with ``params`` before ``run`` loads the solvers.
_MODULES: dict[str, tuple[str, ...]] = {
    "params": ("SweepParam", "parse_param_spec", "parse_path"),
    "result": ("SWEEPS_INSTALL_HINT", "PhaseMap", "SweepPoint", "SweepResult"),
    "run": ("sweep",),
}
__getattr__, __dir__ = lazy_exports(__name__, _MODULES)


__all__ = ["SWEEPS_INSTALL_HINT", "PhaseMap", "SweepParam", "SweepPoint", "SweepResult", "parse_param_spec", "parse_path", "sweep"]
