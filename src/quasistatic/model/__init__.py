"""The model: what a scene is (bodies, movers, robots, contacts, friction), its kinematics, scales and files.

Imports nothing of the package above it (only ``errors`` and ``tolerances``);
every other stage reads a :class:`Scene`, which is validated here once.
"""

from .friction import FrictionModel, parse_friction
from .io import FORMAT_VERSION
from .scales import Scales, scene_scales
from .scene import Body, Contact, FloatArray, Mover, Robot, Scene, Stiffness, checked_array, checked_number

__all__ = [
    "FORMAT_VERSION",
    "Body",
    "Contact",
    "FloatArray",
    "FrictionModel",
    "Mover",
    "Robot",
    "Scales",
    "Scene",
    "Stiffness",
    "parse_friction",
    "checked_array",
    "checked_number",
    "scene_scales",
]
