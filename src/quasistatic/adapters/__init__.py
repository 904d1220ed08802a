"""Adapters: the user's world (URDF robots, shapes and meshes) turned into a :class:`~quasistatic.model.Scene`.

- ``shapes``: poses and collision shapes (box, sphere, cylinder, capsule, halfspace, convex hull, mesh).
- ``detect``: contact points of placed shapes, found with coal (sweep-and-prune broad phase, contact patches).
- ``robot``: URDF robots through Pinocchio: forward kinematics, collision geometry, point Jacobians.
- ``world``: a :class:`World` of shapes and robots, and the Scene it gives at this instant.
- ``world_file``: a scene file with shapes and robots read into a World.
- ``planar``, ``planar_world``: planar shapes (disk, box, convex polygon, halfplane), their contacts in NumPy, and
  the :class:`PlanarWorld` a ``dimension: 2`` scene of shapes is read into (no coal needed).

Rules:

- An adapter's output is a Scene (points, normals, Jacobians, twists): no
  third-party type (``pinocchio.Model``, ``coal.CollisionObject``) leaks into
  ``model``, ``laws``, ``solvers`` or ``check``.
- It imports ``model`` (and the leaf modules ``errors``, ``tolerances``) only;
  heavy libraries (Pinocchio, coal: the ``robots`` extra) are imported inside
  the functions that need them, so ``import quasistatic`` never loads them,
  and a missing one raises an error that says how to install it.
- Bad input (a missing URDF, an unknown joint) is a ``SceneError`` naming the
  field and the value.
"""

from .detect import Collider, ContactPoint, Layout, candidate_pairs, detect
from .planar import Disk, HalfPlane, PlanarLayout, PlanarShape, Polygon, Rectangle, planar_pose, pose_angle
from .planar_world import PlanarBody, PlanarMover, PlanarWorld
from .robot import ROBOTS_INSTALL_HINT, RobotVisual, UrdfRobot
from .shapes import Box, Capsule, Convex, Cylinder, Halfspace, Mesh, Pose, Shape, Sphere, shape_from_coal
from .world import ContactDetection, Detection, FrictionPair, ShapedMover, SolidBody, StiffnessPair, World
from .world_file import world_from_file

AnyWorld = World | PlanarWorld
"""A world of shapes in space or in the plane: what ``solve``, the command line and a simulation accept."""

__all__ = [
    "AnyWorld",
    "Disk",
    "HalfPlane",
    "PlanarBody",
    "PlanarLayout",
    "PlanarMover",
    "PlanarShape",
    "PlanarWorld",
    "Polygon",
    "Rectangle",
    "planar_pose",
    "pose_angle",
    "ROBOTS_INSTALL_HINT",
    "Box",
    "Capsule",
    "Collider",
    "ContactDetection",
    "ContactPoint",
    "Convex",
    "Cylinder",
    "Detection",
    "FrictionPair",
    "StiffnessPair",
    "Halfspace",
    "Layout",
    "Mesh",
    "Pose",
    "Shape",
    "ShapedMover",
    "SolidBody",
    "Sphere",
    "RobotVisual",
    "UrdfRobot",
    "World",
    "candidate_pairs",
    "detect",
    "shape_from_coal",
    "world_from_file",
]
