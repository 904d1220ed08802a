"""The optional C extension (Lemke's method, ``quasistatic._lemke``); everything else is in pyproject.toml.

``optional=True``: where no C compiler (or no Python headers) is found, the build
warns and goes on, and the library runs the numpy twin instead.
"""

from setuptools import Extension, setup

setup(ext_modules=[Extension("quasistatic._lemke", sources=["src/quasistatic/_lemke.c"], optional=True)])
