"""A spec edit that renames or removes a name the pilot uses stops the pilot at start-up with one line naming it,
never an AttributeError in flight (a spec without `land` failed in the safe shutdown itself)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from generator.cli import main as generate
from pilot.link import protocol_needs

REPO = Path(__file__).resolve().parents[3]


def dp_names(trees: list[ast.AST]) -> set[str]:
    """Every ``dp.X.Y`` chain read in ``trees``, longest only, without an enum member's ``.value``."""
    chains = set()
    for node in (n for tree in trees for n in ast.walk(tree)):
        parts: list[str] = []
        inner: ast.expr = node if isinstance(node, ast.Attribute) else ast.Constant(None)
        while isinstance(inner, ast.Attribute):
            parts.append(inner.attr)
            inner = inner.value
        if isinstance(inner, ast.Name) and inner.id == "dp":
            chains.add(".".join(reversed(parts)).removesuffix(".value"))
    return {c for c in chains if not any(o.startswith(c + ".") for o in chains)}


def test_the_start_up_check_reads_every_protocol_name_the_pilot_uses() -> None:
    used = dp_names([ast.parse(path.read_text(encoding="utf-8")) for path in (REPO / "pilot").rglob("*.py")
                     if path.name != "protocol_needs.py"])
    source = Path(protocol_needs.__file__).read_text(encoding="utf-8")
    function = next(n for n in ast.walk(ast.parse(source))
                    if isinstance(n, ast.FunctionDef) and n.name == "_read_every_name")
    assert used == dp_names([function]), "pilot/link/protocol_needs.py's list differs from the names the pilot reads"
    assert protocol_needs.protocol_problem() is None


def _drop_land(spec: dict[str, Any]) -> None:
    del spec["categories"]["i"]["directions"]["l"]


def _rename_turn_left(spec: dict[str, Any]) -> None:
    spec["categories"]["t"]["directions"]["l"]["name"] = "spin_left"


@pytest.mark.parametrize(("edit", "name"), [(_drop_land, "land"), (_rename_turn_left, "TURN_LEFT")],
                         ids=["land removed", "turn_left renamed (read when a module is imported)"])
def test_a_spec_without_a_name_the_pilot_uses_stops_it_at_start(tmp_path: Path, edit: Callable[[dict[str, Any]], None],
                                                                 name: str) -> None:
    spec = yaml.safe_load((REPO / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    edit(spec)
    (tmp_path / "drone.yaml").write_text(yaml.safe_dump(spec, sort_keys=False, allow_unicode=True), encoding="utf-8")
    assert generate(["--spec", str(tmp_path / "drone.yaml"), "--out", str(tmp_path / "out")]) == 0
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), str(tmp_path / "out" / "python")])}
    proc = subprocess.run([sys.executable, "-m", "pilot", "--dry-run", "--max-seconds", "1", "--no-status"], env=env,
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith("pilot: error: the generated module drone_protocol") and f"no {name!r}" in proc.stderr
