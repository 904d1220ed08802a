"""Adapters: the user's world (URDF robots, shapes and meshes) turned into a :class:`~quasistatic.model.Scene`.

Its rules:

- An adapter's output is a Scene (points, normals, Jacobians, twists): no
  third-party type (``pinocchio.Model``, ``coal.CollisionObject``) leaks into
  ``model``, ``laws``, ``solvers`` or ``check``.
- It imports ``model`` (and the leaf modules ``errors``, ``tolerances``) only;
  heavy libraries are optional extras, imported inside the adapter, and a
  missing one raises an error that says how to install it.
- Bad input (a missing URDF, an unknown joint) is a ``SceneError`` naming the
  field and the value.

Tenants: :mod:`.shapes` (poses and collision shapes) and :mod:`.detect`
(contact points of placed shapes, found with coal). Importing them does not
import coal; the functions that need it do.
"""

from .detect import Collider, ContactPoint, candidate_pairs, detect
from .shapes import Box, Capsule, Convex, Cylinder, Halfspace, Mesh, Pose, Shape, Sphere, shape_from_coal

__all__ = [
    "Box",
    "Capsule",
    "Collider",
    "ContactPoint",
    "Convex",
    "Cylinder",
    "Halfspace",
    "Mesh",
    "Pose",
    "Shape",
    "Sphere",
    "candidate_pairs",
    "detect",
    "shape_from_coal",
]
