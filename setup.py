"""The optional C extensions (``quasistatic._lemke``, ``quasistatic._kernels``); everything else is in pyproject.toml.

``optional=True``: where no C compiler (or no Python headers) is found, the build
warns and goes on, and the library runs the numpy twins instead. Each module
builds on its own, so one that fails leaves the other.
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("quasistatic._lemke", sources=["src/quasistatic/_lemke.c"], optional=True),
        Extension("quasistatic._kernels", sources=["src/quasistatic/_kernels.c"], optional=True),
    ]
)
