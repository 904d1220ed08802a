"""One exception root for the library; subclasses carry what is needed to debug."""

from __future__ import annotations

from typing import Any

__all__ = [
    "QuasistaticError",
    "SceneError",
    "SolverError",
    "BackendUnavailableError",
]


class QuasistaticError(Exception):
    """Root of every error this library raises on purpose."""


class SceneError(QuasistaticError, ValueError):
    """A scene (file, dict or Python objects) is malformed.

    Attributes
    ----------
    field : str
        Path of the offending field, e.g. ``contacts[1].normal``.
    value : Any
        The offending value as given.
    reason : str
        What is wrong with it, in words.
    """

    def __init__(self, field: str, value: Any, reason: str) -> None:
        self.field = field
        self.value = value
        self.reason = reason
        shown = _short_repr(value)
        where = f"{field}: " if field else ""
        super().__init__(f"{where}{reason} (got {shown})" if shown else f"{where}{reason}")


class SolverError(QuasistaticError, RuntimeError):
    """A solver backend was misused or the library underneath it crashed."""

    def __init__(self, backend: str, message: str) -> None:
        self.backend = backend
        super().__init__(f"{backend}: {message}")


class BackendUnavailableError(QuasistaticError, ImportError):
    """An optional backend was asked for but its library is not installed."""

    def __init__(self, backend: str, install_hint: str) -> None:
        self.backend = backend
        self.install_hint = install_hint
        super().__init__(f"solver {backend!r} is not available: {install_hint}")


def _short_repr(value: Any, limit: int = 80) -> str:
    if value is _MISSING:
        return ""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


_MISSING: Any = _Missing()
MISSING = _MISSING
