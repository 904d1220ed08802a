"""One exception root for the library; subclasses carry what is needed to debug."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import PurePath
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

    The message shows at most 80 characters of the value and 120 of the field,
    however large or deeply nested the value is; a long file path (a ``Path``
    value) keeps its end, where the file's name is.
    """

    def __init__(self, field: str, value: Any, reason: str) -> None:
        self.field = field
        self.value = value
        self.reason = reason
        shown = _short_repr(value)
        where = f"{_short_text(field, _FIELD_LIMIT)}: " if field else ""
        super().__init__(f"{where}{reason} (got {shown})" if shown else f"{where}{reason}")


class SolverError(QuasistaticError, RuntimeError):
    """A solver backend was misused or the library underneath it crashed."""

    def __init__(self, backend: str, message: str) -> None:
        self.backend = backend
        super().__init__(f"{backend}: {message}")


class BackendUnavailableError(QuasistaticError, ImportError):
    """An optional backend (a solver, or the robots-and-shapes adapter) was asked for but its library is not installed."""

    def __init__(self, backend: str, install_hint: str, needed_for: str | None = None) -> None:
        self.backend = backend
        self.install_hint = install_hint
        what = f"solver {backend!r}" if needed_for is None else f"{backend}, needed for {needed_for},"
        super().__init__(f"{what} is not available: {install_hint}")


_FIELD_LIMIT = 120
_REPR_LIMIT = 80
_CONTAINERS: dict[type, tuple[str, str]] = {list: ("[", "]"), tuple: ("(", ")"), set: ("{", "}"), frozenset: ("frozenset({", "})")}


def _short_repr(value: Any, limit: int = _REPR_LIMIT) -> str:
    """``repr(value)`` cut to ``limit`` characters, built piece by piece: a huge or deeply nested value costs no more."""
    if value is _MISSING:
        return ""
    text = ""
    for piece in _pieces(value, limit):
        text += piece
        if len(text) > limit:
            return text[: limit - 3] + "..."
    return text


def _pieces(value: Any, limit: int) -> Iterator[str]:
    """The pieces of ``repr(value)`` in order, lazily: the caller stops reading once it has enough."""
    kind = next((base for base in _CONTAINERS if isinstance(value, base)), None)
    if kind is not None and value:
        opening, closing = _CONTAINERS[kind]
        yield opening
        for index, item in enumerate(value):
            yield ", " if index else ""
            yield from _pieces(item, limit)
        yield ",)" if kind is tuple and len(value) == 1 else closing
    elif isinstance(value, dict) and value:
        yield "{"
        for index, (key, item) in enumerate(value.items()):
            yield ", " if index else ""
            yield from _pieces(key, limit)
            yield ": "
            yield from _pieces(item, limit)
        yield "}"
    else:
        yield _leaf_repr(value, limit)


def _leaf_repr(value: Any, limit: int) -> str:
    """``repr`` of one value, never longer than needed: long text is cut first, huge integers are described."""
    if isinstance(value, PurePath):
        return repr(_path_tail(str(value), limit))
    if isinstance(value, (str, bytes, bytearray)) and len(value) > limit:
        return repr(value[:limit])
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 4 * limit:
        return f"<an integer of about {int(value.bit_length() * 0.30103) + 1} digits>"
    size = getattr(value, "size", None)
    if isinstance(size, int) and size > limit and hasattr(value, "shape"):
        return f"<array of shape {tuple(value.shape)}>"
    try:
        return repr(value)
    except Exception:  # a broken __repr__ must not hide the error being reported
        return f"<{type(value).__name__}>"


def _path_tail(text: str, limit: int) -> str:
    """A path cut at its start, not its end: in a deep folder the file's name must still show."""
    return text if len(text) <= limit - 2 else "..." + text[-(limit - 5) :]


def _short_text(text: str, limit: int) -> str:
    """``text`` cut to ``limit`` characters, with non-printable characters escaped (a path may hold any key)."""
    shown = text[: limit + 1]
    if not shown.isprintable():
        shown = "".join(c if c.isprintable() else repr(c)[1:-1] for c in shown)
    return shown if len(shown) <= limit and len(text) <= limit else shown[: limit - 3] + "..."


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


_MISSING: Any = _Missing()
MISSING = _MISSING
