"""The pilot's layers (ARCHITECTURE.md): every import, lazy ones included, runs down a layer or stays inside its
own; no two modules reach each other through any chain of imports; no module grows past 400 lines."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

PILOT = Path(__file__).resolve().parents[2] / "pilot"
# The rank of each layer: a module may import from a layer of lower rank or from its own layer. Two layers of one
# rank (vision and link; control and sim) know nothing of each other.
RANKS = {"common": 0, "vision": 1, "link": 1, "control": 2, "sim": 2, "app": 3, "": 4}
MAX_LINES = 400


def module_name(path: Path) -> str:
    parts = path.relative_to(PILOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] in RANKS) else ""


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(PILOT.rglob("*.py"))}


def imported(module: str, path: Path, known: set[str]) -> Iterator[tuple[str, int]]:
    """The pilot modules ``module`` imports, with the line of each import (relative imports resolved)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                target = ".".join([*base, node.module] if node.module else base)
            else:
                target = node.module or ""
            for alias in node.names:  # `from . import config` names a module; `from .config import X` does not
                candidate = f"{target}.{alias.name}"
                yield (candidate if candidate in known else target), node.lineno
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno


def graph() -> dict[str, set[str]]:
    found = modules()
    known = set(found)
    return {m: {t for t, _ in imported(m, p, known) if t in known and t != m} for m, p in found.items()}


def test_the_pilot_is_split_into_its_layers() -> None:
    assert {layer(m) for m in modules()} == set(RANKS)


def test_no_import_climbs_a_layer_or_crosses_to_a_sibling() -> None:
    found = modules()
    known = set(found)
    wrong = []
    for module, path in found.items():
        for target, line in imported(module, path, known):
            if target not in known:
                continue
            mine, theirs = layer(module), layer(target)
            if mine != theirs and RANKS[theirs] >= RANKS[mine]:
                wrong.append(f"{path.relative_to(PILOT.parent)}:{line}: {module} ({mine or 'pilot'}) imports "
                             f"{target} ({theirs or 'pilot'})")
    assert not wrong, "imports against the layers:\n" + "\n".join(wrong)


def test_no_modules_import_each_other_through_any_chain() -> None:
    edges = graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def visit(node: str) -> None:  # Tarjan's strongly connected components
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in edges[node]:
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while (top := stack.pop()) != node:
                component.append(top)
            component.append(node)
            if len(component) > 1:
                cycles.append(sorted(component))

    for node in edges:
        if node not in index:
            visit(node)
    assert not cycles, f"modules that import each other: {cycles}"


@pytest.mark.parametrize("path", sorted(PILOT.rglob("*.py")), ids=lambda p: str(p.relative_to(PILOT)))
def test_no_module_is_over_the_line_limit(path: Path) -> None:
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MAX_LINES, f"{path.relative_to(PILOT.parent)} has {lines} lines (at most {MAX_LINES})"


def test_the_checker_sees_a_climbing_import(tmp_path: Path) -> None:
    """The check itself: a vision module importing the application, relative and absolute, is found as such."""
    fake = tmp_path / "probe.py"
    fake.write_text("from ..app.runner import run\nfrom . import detect\nimport pilot.app.cli\n", encoding="utf-8")
    targets = [t for t, _ in imported("pilot.vision.probe", fake, set(modules()))]
    assert targets == ["pilot.app.runner", "pilot.vision.detect", "pilot.app.cli"]
    assert [RANKS[layer(t)] > RANKS["vision"] for t in targets] == [True, False, True]
