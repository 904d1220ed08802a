"""The contact laws of a scene as matrices: assembly, the polyhedral form, fixed-mode equations and modes.

Imports ``model`` (and the leaf modules ``tolerances``, ``jit``, ``solution``'s
type aliases) only. Every solver builds on these; the audit never does.
"""

from .assemble import Problem, assemble
from .modes import ModeMasks, contact_modes, slips
from .motion import DeferredForces, ForceSet, RawMotion, WorldForceSet, free_directions, physical_twists, to_world

__all__ = [
    "DeferredForces",
    "ForceSet",
    "ModeMasks",
    "Problem",
    "RawMotion",
    "WorldForceSet",
    "assemble",
    "contact_modes",
    "free_directions",
    "physical_twists",
    "slips",
    "to_world",
]
