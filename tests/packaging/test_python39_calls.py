"""The tools run on Python 3.9 (Raspberry Pi OS Bullseye): no call that only later Pythons accept. Ruff's py39
target catches 3.10+ syntax; these are calls that parse on 3.9 and fail only when run, so an import test misses
them (a zip(strict=...) in the generator's ready-line vectors broke every generation on 3.9)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted(p for folder in ("pilot", "generator") for p in (ROOT / folder).rglob("*.py"))
# (function name, keyword): added after 3.9
LATER = {("zip", "strict"), ("dataclass", "slots"), ("dataclass", "kw_only"), ("field", "kw_only")}


def later_calls(source: str, where: str) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            name = node.func.id if isinstance(node.func, ast.Name) else getattr(node.func, "attr", "")
            found += [f"{where}:{node.lineno}: {name}({k.arg}=...)" for k in node.keywords if (name, k.arg) in LATER]
    return found


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_call_needs_a_python_after_3_9(path: Path) -> None:
    found = later_calls(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))
    assert not found, "Python 3.10+ only:\n" + "\n".join(found)


def test_the_check_sees_a_later_call() -> None:
    source = "pairs = list(zip([1], [2], strict=True))\n@dataclasses.dataclass(slots=True)\nclass A: ...\nzip([1])\n"
    found = sorted(later_calls(source, "probe.py"))
    assert found == ["probe.py:1: zip(strict=...)", "probe.py:2: dataclass(slots=...)"]
