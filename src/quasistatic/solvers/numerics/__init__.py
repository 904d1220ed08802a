"""Numerical kernels of the solvers: HiGHS LPs, Lemke's method, the split-twist LCP, LP ranges, SCIP model helpers.

Private to :mod:`quasistatic.solvers`: only its front doors and ``certify`` import from here.
"""
