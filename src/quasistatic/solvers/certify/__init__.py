"""Certification helpers of the solvers: the complete search, diagnoses, exact-cone proofs, the paper's program.

Private to :mod:`quasistatic.solvers`: only its front doors (``lp``, ``fast``,
``scip``, ``paper``) import from here.
"""
