"""The case schema: ``Case``, ``CaseResult`` and reading them from ``cases.yaml``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

import quasistatic as qs
from quasistatic.solution import Mode

CASES_FILE = "cases.yaml"
DEFAULT_FOLDER = Path("validation")
_DEFAULT_TOLERANCE = {"force": 1e-4, "twist": 1e-7, "threshold": 1e-3}
_CHECKS = ("solve", "bisect", "whitney-grid")
_ENTRY_KEYS = frozenset(
    {
        "id",
        "group",
        "title",
        "source",
        "ref",
        "derivation",
        "scene",
        "set",
        "modes",
        "check",
        "expect",
        "tolerance",
        "extrude",
        "slow",
        "known",
        "known_3d",
    }
)


@dataclass(frozen=True)
class Case:
    """One validation case, as read from ``cases.yaml``.

    Attributes
    ----------
    id, group, title, source, ref, derivation : str
        ``ref`` is the short source shown in the table.
    folder : Path
        The validation folder; ``scene`` is relative to it.
    scene : str
        Scene file of the case.
    overrides : mapping
        Scene keys to replace, by dotted path (``bodies.peg.wrench``, ``contacts[2].point``).
    modes : tuple of str or None, optional
        Prescribed contact modes of the solve.
    check : {"solve", "bisect", "whitney-grid"}
    expect : mapping
        The expected outcome (see ``cases.yaml``).
    tolerance : mapping
        ``force`` [N], ``twist`` [m/s, rad/s], ``threshold`` [unit of the varied parameter].
    depth : float or None
        Set for the 3-D run of a planar case: extrusion depth [m].
    slow : bool
        Left out of the default pytest run.
    known : str or None
        A documented disagreement: why the library's answer differs from the
        expectation (``known``, or ``known_3d`` for the extruded run, in
        ``cases.yaml``). Such a case is reported ``known`` when it fails and
        ``FIXED`` (a failure: update the file) when it passes.
    params : mapping
        Parameters of ``bisect`` and ``whitney-grid`` checks.
    """

    id: str
    group: str
    title: str
    source: str
    ref: str
    derivation: str
    folder: Path
    scene: str
    overrides: Mapping[str, Any] = field(default_factory=dict)
    modes: tuple[Mode | None, ...] | None = None
    check: str = "solve"
    expect: Mapping[str, Any] = field(default_factory=dict)
    tolerance: Mapping[str, float] = field(default_factory=dict)
    depth: float | None = None
    slow: bool = False
    known: str | None = None
    params: Mapping[str, Any] = field(default_factory=dict)

    @property
    def dimension(self) -> int:
        """Dimension the case runs in (3 for an extruded planar case)."""
        return 3 if self.depth is not None else int(read_yaml(self.folder / self.scene).get("dimension", 3))


@dataclass(frozen=True)
class CaseResult:
    """The outcome of one case.

    Attributes
    ----------
    case : Case
    expected, got : str
        One-line summaries for the table.
    passed : bool
    failures : tuple of str
        What differs from the expectation, one line each.
    seconds : float
        Wall time of the case [s].
    error : str or None
        ``ExceptionType: message`` when the library raised.
    """

    case: Case
    expected: str
    got: str
    passed: bool
    failures: tuple[str, ...] = ()
    seconds: float = 0.0
    error: str | None = None

    @property
    def verdict(self) -> str:
        """``pass``, ``FAIL``, ``known`` (fails as documented) or ``FIXED`` (documented to fail, passes)."""
        if self.case.known is None:
            return "pass" if self.passed else "FAIL"
        return "FIXED" if self.passed else "known"

    @property
    def ok(self) -> bool:
        """True unless the case fails unexpectedly or a documented failure went away."""
        return self.verdict in ("pass", "known")


def load_cases(folder: str | Path = DEFAULT_FOLDER, *, extruded: bool = True) -> list[Case]:
    """Every case of ``folder/cases.yaml``, each planar case followed by its 3-D run.

    Parameters
    ----------
    folder : path
        Folder holding ``cases.yaml`` and the scene files.
    extruded : bool
        Follow each planar case that names an ``extrude`` depth with its 3-D run.

    Returns
    -------
    list of Case
        In the order of the file.

    Raises
    ------
    QuasistaticError
        When the folder or its ``cases.yaml`` is missing or malformed.
    """
    folder = Path(folder)
    path = folder / CASES_FILE
    if not path.is_file():
        raise qs.QuasistaticError(
            f"no validation cases: {path} does not exist; run from the repository root or pass the folder that holds cases.yaml"
        )
    data = read_yaml(path)
    defaults = {**_DEFAULT_TOLERANCE, **(data.get("defaults", {}).get("tolerance", {}))}
    cases: list[Case] = []
    seen: set[str] = set()
    for entry in data.get("cases", []):
        case = _case(entry, folder, defaults)
        if case.id in seen:
            raise qs.QuasistaticError(f"{path}: case id {case.id!r} appears twice")
        seen.add(case.id)
        cases.append(case)
        if extruded and entry.get("extrude") is not None:
            cases.append(_extruded_twin(case, entry))
    return cases


def read_yaml(path: Path) -> dict[str, Any]:
    """The mapping a YAML file holds.

    Raises
    ------
    QuasistaticError
        When the file cannot be read or parsed, or holds no mapping.
    """
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise qs.QuasistaticError(f"cannot read {path}: {exc}") from None
    if not isinstance(data, dict):
        raise qs.QuasistaticError(f"{path}: expected a mapping of keys")
    return data


def _case(entry: Mapping[str, Any], folder: Path, defaults: Mapping[str, float]) -> Case:
    """The case of one entry of ``cases.yaml``; keys it does not know become its ``params``."""
    try:
        check = entry.get("check", "solve")
        if check not in _CHECKS:
            raise qs.QuasistaticError(f"case {entry.get('id')!r}: unknown check {check!r}; known: {', '.join(_CHECKS)}")
        modes = entry.get("modes")
        return Case(
            id=str(entry["id"]),
            group=str(entry["group"]),
            title=str(entry["title"]),
            source=str(entry["source"]),
            ref=str(entry.get("ref", entry["source"])),
            derivation=" ".join(str(entry["derivation"]).split()),
            folder=folder,
            scene=str(entry["scene"]),
            overrides=dict(entry.get("set", {})),
            modes=tuple(modes) if modes is not None else None,
            check=check,
            expect=dict(entry["expect"]),
            tolerance={**defaults, **entry.get("tolerance", {})},
            slow=bool(entry.get("slow", False)),
            known=" ".join(str(entry["known"]).split()) if entry.get("known") else None,
            params={k: v for k, v in entry.items() if k not in _ENTRY_KEYS},
        )
    except KeyError as exc:
        raise qs.QuasistaticError(f"case {entry.get('id', '?')!r} in {folder / CASES_FILE}: missing key {exc}") from None


def _extruded_twin(case: Case, entry: Mapping[str, Any]) -> Case:
    """The 3-D run of a planar case: slow, with ``known_3d`` as its documented disagreement."""
    known_3d = " ".join(str(entry["known_3d"]).split()) if entry.get("known_3d") else None
    return _replace(case, id=f"{case.id}-3d", title=f"{case.title} (3-D)", depth=float(entry["extrude"]), slow=True, known=known_3d)


def _replace(case: Case, **changes: Any) -> Case:
    """A copy of ``case`` with some fields changed."""
    return Case(**{**case.__dict__, **changes})
