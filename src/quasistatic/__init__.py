"""quasistatic: the forward object motion problem of quasi-static manipulation.

Given the motion of a robot and the contacts, predict how grasped or pushed
objects move, the contact forces and each contact's mode (Trinkle & Hunter).

The root imports its public names lazily (PEP 562): each is imported from its
module the first time it is read, so the command line answers a bad scene
file or ``--help`` without first loading SciPy, HiGHS, SCIP and numba.
"""

from __future__ import annotations

import sys
import types
from typing import TYPE_CHECKING, Any

from .lazy import lazy_exports

if TYPE_CHECKING:
    from .adapters import (
        Box,
        Capsule,
        ContactDetection,
        Cylinder,
        FrictionPair,
        Halfspace,
        Mesh,
        PlanarWorld,
        Pose,
        ShapedMover,
        SolidBody,
        Sphere,
        UrdfRobot,
        World,
        planar_pose,
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

# each module (relative to this package) and the public names it defines
_MODULES: dict[str, tuple[str, ...]] = {
    "adapters": (
        "Box",
        "Capsule",
        "ContactDetection",
        "Cylinder",
        "FrictionPair",
        "Halfspace",
        "Mesh",
        "PlanarWorld",
        "Pose",
        "ShapedMover",
        "SolidBody",
        "Sphere",
        "UrdfRobot",
        "World",
        "planar_pose",
    ),
    "batch": ("solve_many",),
    "errors": ("BackendUnavailableError", "QuasistaticError", "SceneError", "SolverError"),
    "laws": ("Problem", "assemble"),
    "loading": ("load_scene", "load_world"),
    "model": ("Body", "Contact", "FrictionModel", "Mover", "Robot", "Scene", "Stiffness"),
    "plan": ("PlanResult", "QuadraticCost", "plan"),
    "sensitivity": (
        "GeometrySensitivity",
        "InputMargin",
        "ModeChange",
        "NoSensitivity",
        "NoSensitivityReason",
        "Sensitivity",
        "sensitivity",
    ),
    "sim": ("Inputs", "InputTable", "Trajectory", "simulate"),
    "solution": ("Attempt", "Audit", "Certificate", "CertificateKind", "ContactResult", "Diagnosis", "Motion", "PowerBalance", "Solution"),
    "solve": ("METHODS", "solve"),
    "sweeps": ("SweepResult", "sweep"),
    "viz": ("plot", "view"),
}
_EXPORTS = {name: module for module, names in _MODULES.items() for name in names}
__getattr__, __dir__ = lazy_exports(__name__, _MODULES)


class _Package(types.ModuleType):
    """The package module, keeping ``solve``, ``plan`` and ``sensitivity`` the functions.

    Each of those names is also a submodule; importing a submodule binds it on
    its package, which would replace the function the package exports.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and name in _EXPORTS:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

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
    "PlanarWorld",
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
    "planar_pose",
    "plot",
    "simulate",
    "solve",
    "solve_many",
    "sweep",
    "view",
]
