"""Motion over time: quasi-static steps with contacts found again at every step.

- :func:`step` ``(model, state, inputs) -> (state, StepResult)`` is a pure function over frozen
  values, for a planner's own loop; :func:`simulate` loops it into a :class:`Trajectory`,
  shortening steps where surfaces close in and bisecting them where an event happens.
- Each step builds a Scene through ``adapters`` and calls :func:`quasistatic.solve`: the same
  audited, certified solve as a single answer, never a solver called directly.
- It may import ``model``, ``adapters``, ``laws``, ``loading`` and the top-level ``solve``;
  never ``viz`` or ``tools``.
"""

from .rigid import advance_pose, screw
from .simulate import simulate
from .state import Inputs, InputSource, InputTable, State
from .step import ContactRecord, Evaluation, Event, SimModel, StepOptions, StepResult, advance, evaluate, step
from .trajectory import RunStatus, Trajectory

__all__ = [
    "ContactRecord",
    "Evaluation",
    "Event",
    "InputSource",
    "InputTable",
    "Inputs",
    "RunStatus",
    "SimModel",
    "State",
    "StepOptions",
    "StepResult",
    "Trajectory",
    "advance",
    "advance_pose",
    "evaluate",
    "screw",
    "simulate",
    "step",
]
