"""The import rules of docs/architecture.md, checked on the source itself.

Every ``import`` of the package (at module level or inside a function) is read
with :mod:`ast`; the rules are then plain set checks, so a change that breaks
the layering fails here with the offending module and import named.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "quasistatic"

# Top-level modules that import nothing else of the package: any stage may use them.
LEAVES = {
    "quasistatic.errors",
    "quasistatic.tolerances",
    "quasistatic.jit",
    "quasistatic.solution",
    "quasistatic.stdio",
    "quasistatic.compiled",
    "quasistatic.lazy",
    "quasistatic.interval",
}

# Stage -> the stages it may import (besides itself and the leaves).
ALLOWED = {
    "model": set(),
    "laws": {"model"},
    "check": {"model"},
    "solvers": {"model", "laws"},
    "adapters": {"model"},
    "sim": {"model", "adapters", "laws", "solve", "loading", "wedging"},
    "viz": {"model", "sim", "adapters", "solve"},  # solve: the viewer's live re-solve, through the public solve()
}
# The ways into viz/ from outside it, besides the CLI: the package root re-exports ``plot`` (matplotlib is
# loaded only when drawing), and ``Solution._repr_png_`` (a notebook's picture) calls ``viz.chart``, which
# imports no value type, so the leaf stays free of cycles; ``Trajectory._repr_html_`` calls ``viz.run_summary``,
# which imports no Trajectory.
PICTURE_ENTRIES = {
    ("quasistatic", "quasistatic.viz"),
    ("quasistatic.solution", "quasistatic.viz.chart"),
    ("quasistatic.sim.trajectory", "quasistatic.viz.run_summary"),
}
FRONT_DOORS = {"quasistatic.solvers.lp", "quasistatic.solvers.fast", "quasistatic.solvers.scip", "quasistatic.solvers.paper"}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, ast.Module]:
    return {_module_name(path): ast.parse(path.read_text(encoding="utf-8")) for path in sorted(PACKAGE.rglob("*.py"))}


MODULES = _modules()


def _imports(name: str, tree: ast.Module) -> Iterator[tuple[str, list[str]]]:
    """``(imported module, names imported from it)`` for every import of the package in a module."""
    is_package = (PACKAGE.parent / Path(*name.split(".")) / "__init__.py").exists()
    base = name.split(".") if is_package else name.split(".")[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("quasistatic"):
                    yield alias.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                target = ".".join(base[: len(base) - node.level + 1] + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.startswith("quasistatic"):
                names = [alias.name for alias in node.names]
                submodules = [f"{target}.{n}" for n in names if f"{target}.{n}" in MODULES]
                yield (target, [n for n in names if f"{target}.{n}" not in MODULES]) if not submodules else (target, [])
                for sub in submodules:
                    yield sub, []


def _stage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _edges() -> list[tuple[str, str, list[str]]]:
    return [(name, target, names) for name, tree in MODULES.items() for target, names in _imports(name, tree)]


def test_the_sources_were_found() -> None:
    assert {"quasistatic.model.scene", "quasistatic.laws.assemble", "quasistatic.check.audit", "quasistatic.solve"} <= set(MODULES)


@pytest.mark.parametrize("stage", sorted(ALLOWED))
def test_each_stage_imports_only_what_it_may(stage: str) -> None:
    """model imports nothing above it; laws only model; check only model (the judge shares nothing with
    assembly or the solvers); solvers only laws and model (never the audit); adapters only model."""
    allowed = ALLOWED[stage] | {stage}
    bad = [
        f"{name} imports {target}"
        for name, target, _ in _edges()
        if _stage(name) == stage
        and target not in LEAVES
        and target != "quasistatic"
        and _stage(target) not in allowed
        and (name, target) not in PICTURE_ENTRIES
    ]
    assert not bad, bad


def test_leaves_import_nothing_of_the_package() -> None:
    bad = [
        f"{name} imports {target}"
        for name, target, _ in _edges()
        if name in LEAVES and target not in LEAVES and (name, target) not in PICTURE_ENTRIES
    ]
    assert not bad, bad


@pytest.mark.parametrize("outer", ["tools", "viz"])
def test_the_core_never_imports_tools_or_pictures(outer: str) -> None:
    """tools/ (validation, bench) and viz/ use the library from outside; only the CLI may call them (and viz's
    PICTURE_ENTRIES: ``qs.plot`` and a Solution's notebook picture)."""
    bad = [
        f"{name} imports {target}"
        for name, target, _ in _edges()
        if _stage(target) == outer and _stage(name) != outer and name != "quasistatic.cli" and (name, target) not in PICTURE_ENTRIES
    ]
    assert not bad, bad


def test_solver_helpers_are_private_to_the_solvers() -> None:
    """solvers/numerics and solvers/certify are imported only from inside solvers/ (their front doors and each other)."""
    helpers = ("quasistatic.solvers.numerics", "quasistatic.solvers.certify")
    bad = [
        f"{name} imports {target}"
        for name, target, _ in _edges()
        if target.startswith(helpers) and not name.startswith("quasistatic.solvers")
    ]
    assert not bad, bad


def test_front_doors_do_not_call_each_other() -> None:
    """A method's front door uses helpers, never another method: the registry is the only way between them."""
    bad = [f"{name} imports {target}" for name, target, _ in _edges() if name in FRONT_DOORS and target in FRONT_DOORS - {name}]
    assert not bad, bad


def test_no_private_name_is_imported_across_modules() -> None:
    bad = [f"{name}: from {target} import {n}" for name, target, names in _edges() for n in names if n.startswith("_")]
    assert not bad, bad


def test_there_is_no_import_cycle() -> None:
    """Between modules, counting function-level imports too (a lazy import only hides a cycle)."""
    graph: dict[str, set[str]] = {name: set() for name in MODULES}
    for name, target, _ in _edges():
        if target in MODULES and target != name and not name.startswith(f"{target}."):
            graph[name].add(target)
    # A package's __init__ re-exports its submodules: an edge into a package stands for its submodules.
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in graph[node]:
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = 2
        return None

    for start in sorted(graph):
        if start not in state and (cycle := visit(start)):
            pytest.fail(" -> ".join(cycle))


def test_no_module_keeps_mutable_state_at_module_level() -> None:
    """Caches belong to the object they cache (Problem.derived), not to module globals: no module-level
    dict/list/set literal is assigned under a private name and then mutated (subscript assignment, .update, .clear...)."""
    bad = []
    for name, tree in MODULES.items():
        globals_ = {
            target.id
            for node in tree.body
            if isinstance(node, (ast.Assign, ast.AnnAssign))
            for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
            if isinstance(target, ast.Name) and isinstance(node.value, (ast.Dict, ast.List, ast.Set, ast.Call))
        }
        bad += [f"{name}: {mutation}" for mutation in _mutations(tree, globals_)]
    assert not bad, bad


def _mutations(tree: ast.Module, names: set[str]) -> Iterator[str]:
    """Writes into the module-level containers ``names``: ``x[...] = ...`` or ``x.update(...)`` and the like."""
    mutators = {"update", "clear", "append", "pop", "setdefault", "add"}
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Subscript)
            and isinstance(node.ctx, ast.Store)
            and isinstance(node.value, ast.Name)
            and node.value.id in names
        ):
            yield f"{node.value.id}[...] = ..."
        call = isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name)
        if call and node.func.value.id in names and node.func.attr in mutators:  # type: ignore[attr-defined]
            yield f"{node.func.value.id}.{node.func.attr}(...)"  # type: ignore[attr-defined]


def test_no_merge_conflict_markers_are_left_in_the_sources_or_docs() -> None:
    """A merge resolved by hand once left its markers in CHANGELOG.md for a whole session."""
    root = Path(__file__).resolve().parents[1]
    files = [*root.glob("*.md"), *root.glob("docs/**/*.md"), *root.glob("src/**/*.py"), *root.glob("tests/**/*.py")]
    markers = ("<" * 7 + " ", "=" * 7 + "\n", ">" * 7 + " ")
    left = [
        f"{path.relative_to(root)}:{number}"
        for path in files
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(keepends=True), 1)
        if line.startswith(markers)
    ]
    assert len(files) > 50 and not left, left
