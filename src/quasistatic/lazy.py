"""Public names of a package imported from their modules when first read (PEP 562).

The package root, ``viz/`` and ``sweeps/`` use it so that ``import quasistatic`` and a CLI command's option
checks load none of the solvers, the simulator or matplotlib. A leaf: it imports nothing of the package.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, modules: Mapping[str, tuple[str, ...]]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The module-level ``__getattr__`` and ``__dir__`` of ``package``.

    ``modules``: each module (relative to ``package``) and the public names it defines. A name is imported the first
    time it is read and then kept in the package's namespace, so later reads are plain attribute reads."""
    exports = {name: module for module, names in modules.items() for name in names}
    namespace = sys.modules[package].__dict__

    def attribute(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{module}", package), name)
        namespace[name] = value
        return value

    def names() -> list[str]:
        return sorted(set(namespace) | set(exports))

    return attribute, names
