"""The independent judge: every motion is audited against the laws on the original scene data.

Imports ``model`` (and the leaf modules ``solution``, ``tolerances``, ``jit``)
only: no assembly and no solver code, so a bug there cannot hide here.
"""

from .audit import DEFAULT_TOLERANCE, AuditGeometry, audit_motion, audit_motion_velocities, power_balance, relative_velocities
from .compliance import audited_step
from .loads import ForceFunctionals, LoadMap, LoadTable
from .motion import ContactTable, MotionGeometry, audited_motion

__all__ = [
    "DEFAULT_TOLERANCE",
    "AuditGeometry",
    "ContactTable",
    "ForceFunctionals",
    "LoadMap",
    "LoadTable",
    "MotionGeometry",
    "audit_motion",
    "audit_motion_velocities",
    "audited_motion",
    "audited_step",
    "power_balance",
    "relative_velocities",
]
