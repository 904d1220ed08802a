"""quasistatic: the forward object motion problem of quasi-static manipulation.

Given the motion of a robot and the contacts, predict how grasped or pushed
objects move, the contact forces and each contact's mode (Trinkle & Hunter).
"""

from .batch import solve_many
from .errors import BackendUnavailableError, QuasistaticError, SceneError, SolverError
from .laws import Problem, assemble
from .model import Body, Contact, FrictionModel, Mover, Robot, Scene, load_scene
from .solution import Attempt, Audit, Certificate, CertificateKind, ContactResult, Diagnosis, Motion, PowerBalance, Solution
from .solve import METHODS, solve

__version__ = "0.1.0"

__all__ = [
    "Attempt",
    "Audit",
    "BackendUnavailableError",
    "Body",
    "Certificate",
    "CertificateKind",
    "Contact",
    "ContactResult",
    "Diagnosis",
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
