"""Solver backends, one per module, behind a registry keyed by name."""
