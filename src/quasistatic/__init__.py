"""quasistatic: the forward object motion problem of quasi-static manipulation.

Given the motion of a robot and the contacts, predict how grasped or pushed
objects move, the contact forces and each contact's mode (Trinkle & Hunter).
"""

from .adapters import (
    Box,
    Capsule,
    ContactDetection,
    Cylinder,
    FrictionPair,
    Halfspace,
    Mesh,
    Pose,
    ShapedMover,
    SolidBody,
    Sphere,
    UrdfRobot,
    World,
)
from .batch import solve_many
from .errors import BackendUnavailableError, QuasistaticError, SceneError, SolverError
from .laws import Problem, assemble
from .loading import load_scene, load_world
from .model import Body, Contact, FrictionModel, Mover, Robot, Scene, Stiffness
from .plan import PlanResult, QuadraticCost, plan
from .sensitivity import GeometrySensitivity, InputMargin, ModeChange, NoSensitivity, NoSensitivityReason, Sensitivity, sensitivity
from .sim import Inputs, InputTable, Trajectory, simulate
from .solution import Attempt, Audit, Certificate, CertificateKind, ContactResult, Diagnosis, Motion, PowerBalance, Solution
from .solve import METHODS, solve
from .sweeps import SweepResult, sweep
from .viz import plot, view

__version__ = "0.1.0"

__all__ = [
    "sensitivity",
    "GeometrySensitivity",
    "plan",
    "Sensitivity",
    "QuadraticCost",
    "PlanResult",
    "NoSensitivityReason",
    "NoSensitivity",
    "ModeChange",
    "InputMargin",
    "Attempt",
    "Audit",
    "BackendUnavailableError",
    "Body",
    "Box",
    "Capsule",
    "Certificate",
    "CertificateKind",
    "Contact",
    "ContactDetection",
    "ContactResult",
    "Cylinder",
    "Diagnosis",
    "FrictionModel",
    "FrictionPair",
    "InputTable",
    "Inputs",
    "Halfspace",
    "METHODS",
    "Mesh",
    "Motion",
    "Mover",
    "Pose",
    "PowerBalance",
    "Problem",
    "QuasistaticError",
    "Robot",
    "Scene",
    "Stiffness",
    "SceneError",
    "ShapedMover",
    "SolidBody",
    "Solution",
    "SolverError",
    "SweepResult",
    "Sphere",
    "Trajectory",
    "UrdfRobot",
    "World",
    "assemble",
    "load_scene",
    "load_world",
    "plot",
    "simulate",
    "solve",
    "solve_many",
    "sweep",
    "view",
]
