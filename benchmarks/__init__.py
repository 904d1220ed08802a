"""Benchmarks of quasistatic: ``python -m benchmarks [--quick | --full] [--out DIR] [--repeat N]``.

The families and the runner live in :mod:`quasistatic.tools.bench`, so that the
installed ``quasistatic bench`` command runs the same code.
"""
