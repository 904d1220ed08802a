"""Validation suite: classical results of statics with friction, run through the library.

The cases live in a folder (``validation/`` of a clone): ``cases.yaml`` lists
each case with its source, a hand derivation of the expected outcome and its
tolerances, and points at a scene file under ``scenes/``. A case is one of

- ``solve``: one solve compared with the expected status, twists, modes,
  normal forces (or their ranges) and, for ``ambiguous``, the kinds of motion
  that must be listed;
- ``bisect``: a threshold (angle of repose, a ladder's critical angle, a
  pushing height) found by bisection over a scene parameter, each step a solve;
- ``whitney-grid``: a grid of peg loads compared with Whitney's jamming line.

A planar case with ``extrude: d`` runs a second time in 3-D: extruded along z
with every contact duplicated at ``z = -d/2`` and ``z = +d/2``. The 3-D run
must give the same status, twists and modes, and each pair of contacts must
carry the planar contact's normal force.

``run_validation(folder)`` runs every case and ``render_results`` prints the
table; ``python -m quasistatic.tools.validation --whitney docs/whitney.png``
draws Whitney's jamming diagram from a sweep of the library (needs matplotlib).

Modules: ``cases`` (the case schema and ``cases.yaml``), ``scenes`` (a case's
scene dict, the 3-D extrusion, the parameters a bisection varies), ``whitney``
(the peg in a hole), ``run`` (running and checking cases), ``report`` (the
table and the text descriptions).
"""

from .cases import CASES_FILE, Case, CaseResult, load_cases
from .report import render_results
from .run import run_case, run_validation
from .scenes import extrude, scene_data
from .whitney import plot_whitney, whitney_line, whitney_load, whitney_parameters

__all__ = [
    "CASES_FILE",
    "Case",
    "CaseResult",
    "load_cases",
    "run_case",
    "run_validation",
    "render_results",
    "scene_data",
    "extrude",
    "whitney_parameters",
    "whitney_line",
    "whitney_load",
    "plot_whitney",
]
