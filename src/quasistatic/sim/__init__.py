"""Simulation: motion over time as a pure step over frozen state.

Empty for now; its rules, for the first tenant (quasi-static time stepping):

- ``step(model, state, inputs) -> (state, StepResult)`` is a pure function
  over frozen dataclasses; ``simulate`` loops it and returns a Trajectory.
- Each step builds a Scene (through ``adapters`` when contacts come from
  geometry) and calls :func:`quasistatic.solve`: the same audited solve as a
  single answer, never a solver called directly.
- It may import ``model``, ``adapters``, ``laws`` and the top-level ``solve``;
  never ``viz`` or ``tools``.
"""
