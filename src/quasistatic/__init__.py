"""quasistatic: the forward object motion problem of quasi-static manipulation.

Given the motion of a robot and the contacts, predict how grasped or pushed
objects move, the contact forces and each contact's mode (Trinkle & Hunter).
"""

from .batch import solve_many
from .errors import BackendUnavailableError, QuasistaticError, SceneError, SolverError
from .friction import FrictionModel
from .problem import Problem, assemble
from .scene import Body, Contact, Mover, Robot, Scene, load_scene
from .solution import Audit, ContactResult, Motion, PowerBalance, Solution
from .solve import METHODS, solve

__version__ = "0.1.0"

__all__ = [
    "Audit",
    "BackendUnavailableError",
    "Body",
    "Contact",
    "ContactResult",
    "FrictionModel",
    "METHODS",
    "Motion",
    "Mover",
    "PowerBalance",
    "Problem",
    "QuasistaticError",
    "Robot",
    "Scene",
    "SceneError",
    "Solution",
    "SolverError",
    "assemble",
    "load_scene",
    "solve",
    "solve_many",
]
