"""Adapters: the user's world (URDF robots, shapes and meshes) turned into a :class:`~quasistatic.model.Scene`.

Empty for now; its rules, for the first tenants (robots through Pinocchio,
contact detection through coal):

- An adapter's output is a Scene (points, normals, Jacobians, twists): no
  third-party type (``pinocchio.Model``, ``coal.CollisionObject``) leaks into
  ``model``, ``laws``, ``solvers`` or ``check``.
- It imports ``model`` (and the leaf modules ``errors``, ``tolerances``) only;
  heavy libraries are optional extras, imported inside the adapter, and a
  missing one raises an error that says how to install it.
- Bad input (a missing URDF, an unknown joint) is a ``SceneError`` naming the
  field and the value.
"""
