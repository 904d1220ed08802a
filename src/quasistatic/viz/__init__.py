"""Pictures: plots, animations and the interactive viewer.

Empty for now; its rules, for the first tenants (matplotlib figures, a viser viewer):

- It reads Solutions, Scenes and Trajectories only; it computes no physics
  (a slip arrow is ``ContactResult.slip``, not a new velocity).
- matplotlib and viser are optional extras, imported inside the functions
  that need them; a missing one raises an error that says how to install it.
- Nothing in the core imports it; the CLI calls it lazily.
"""
