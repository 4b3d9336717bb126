"""A module docstring says what the module does and why in a few lines; figures and tuning history go to
bench/*/HISTORY.md or the commit body (the house style, issue 54)."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TREES = ("pilot", "generator", "bench")
MAX_LINES = 15


def module_docstring(text: str) -> str | None:
    """The docstring that opens a module's text, as ``ast.get_docstring`` gives it, without parsing the whole
    module (a hundredth of the time)."""
    body = text.lstrip()
    while body.startswith("#"):
        body = body.partition("\n")[2].lstrip()
    for prefix in ("", "r"):
        for quote in ('"""', "'''"):
            if body.startswith(prefix + quote):
                end = body.index(quote, len(prefix) + 3)
                return inspect.cleandoc(ast.literal_eval(body[:end + 3]))
    return None


def docstring_lines() -> dict[str, int]:
    out = {}
    for tree in TREES:
        for path in sorted((ROOT / tree).rglob("*.py")):
            doc = module_docstring(path.read_text(encoding="utf-8"))
            if doc is not None:
                out[path.relative_to(ROOT).as_posix()] = len(doc.splitlines())
    return out


def test_the_quick_reading_finds_the_docstring_ast_finds() -> None:
    for text in ('"""One.\n\n  Two."""\nx = 1\n', '#!/usr/bin/env python3\n# c\nr"""A \\d."""\n', "x = '''no'''\n",
                 (ROOT / "pilot" / "app" / "runner.py").read_text(encoding="utf-8")):
        assert module_docstring(text) == ast.get_docstring(ast.parse(text)), text[:40]


def test_no_module_docstring_runs_over_fifteen_lines() -> None:
    lines = docstring_lines()
    assert len(lines) > 100 and "pilot/app/runner.py" in lines  # the walk found the trees
    long = {path: n for path, n in lines.items() if n > MAX_LINES}
    assert long == {}, f"module docstrings over {MAX_LINES} lines (move figures and history to bench/*/HISTORY.md)"
