"""Benchmarks of quasistatic: ``python -m benchmarks [--quick | --full] [--out DIR] [--repeat N]``.

The families and the runner live in :mod:`quasistatic.bench`, so that the
installed ``quasistatic bench`` command runs the same code.
"""
