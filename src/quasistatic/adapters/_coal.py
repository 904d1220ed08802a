"""The one door to coal, the optional collision library: imported on first use, never by ``import quasistatic``."""

from __future__ import annotations

import importlib
from types import ModuleType

from ..errors import BackendUnavailableError

__all__ = ["import_coal", "INSTALL_HINT"]

INSTALL_HINT = "pip install 'quasistatic[robots]'"


def import_coal() -> ModuleType:
    """The ``coal`` module.

    Raises
    ------
    BackendUnavailableError
        With the install hint, when coal is not installed.
    """
    try:
        return importlib.import_module("coal")
    except ImportError as error:
        raise BackendUnavailableError("coal", INSTALL_HINT, needed_for="shapes and contact detection") from error
