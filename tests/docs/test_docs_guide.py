"""docs/guide.md, the user guide: every command in it is run or, where it needs the hardware, checked by the
tool that would run it; its YAML is loaded by the pilot's config loader; its troubleshooting lists every message
the pilot can print (read from the pilot's source, so a new message fails here until the guide has it); the
wiring diagram it shows is generated from the spec and names every wired pin.

The guide marks its blocks: ```sh runs here, from the repository's root; ```sh hardware needs the drone, the
Arduino or a Pi, and is checked instead: `make` with -n (the target and its variables parse), the pilot's own
argument parser, anything else `bash -n`."""

from __future__ import annotations

import ast
import re
import shlex
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from generator.build import load_spec
from pilot.app.cli import build_parser
from pilot.common import config as pilot_config

ROOT = Path(__file__).resolve().parents[2]
GUIDE = ROOT / "docs" / "guide.md"
WIRING = ROOT / "generated" / "docs" / "wiring.svg"
BLOCK = re.compile(r"^```(?P<info>[^\n`]*)\n(?P<body>.*?)^```$", re.MULTILINE | re.DOTALL)
PILOT = ".venv/bin/python -m pilot"


def blocks(kind: str) -> list[str]:
    return [m["body"] for m in BLOCK.finditer(GUIDE.read_text(encoding="utf-8")) if m["info"].strip() == kind]


def commands(kind: str) -> list[str]:
    """The commands of the guide's blocks of this kind: one per line, comments and blank lines left out."""
    out = []
    for body in blocks(kind):
        for line in body.replace("\\\n", " ").splitlines():
            line = line.split("  #")[0].strip()
            if line and not line.startswith("#"):
                out.append(line)
    return out


def test_the_guide_has_only_blocks_a_test_knows() -> None:
    kinds = {m["info"].strip() for m in BLOCK.finditer(GUIDE.read_text(encoding="utf-8"))}
    assert kinds <= {"sh", "sh hardware", "yaml", "text"}, kinds
    assert commands("sh") and commands("sh hardware")


@pytest.mark.parametrize("command", commands("sh"))
def test_every_command_that_can_run_here_runs(command: str) -> None:
    result = subprocess.run(["bash", "-c", command], cwd=ROOT, capture_output=True, text=True, timeout=300,
                            check=False)
    assert result.returncode == 0, f"{command}\n{result.stdout[-2000:]}\n{result.stderr[-2000:]}"


@pytest.mark.parametrize("command", commands("sh hardware"))
def test_every_hardware_command_parses_in_its_tool(command: str, tmp_path: Path) -> None:
    board = tmp_path / "ttyACM0"  # stands for the plugged-in board the makefile checks for
    board.touch()
    words = [re.sub(r"^PORT=/dev/\S+$", f"PORT={board}", word) for word in shlex.split(command)]
    if command.startswith(PILOT + " "):
        args = build_parser().parse_args(words[3:])  # SystemExit (exit 2) on an option the pilot lacks
        assert args.port or args.calibrate or args.camera is not None, command
    elif words[0] == "make":
        result = subprocess.run(["make", "-n", *words[1:]], cwd=ROOT, capture_output=True, text=True, timeout=60,
                                check=False)
        assert result.returncode == 0 and result.stdout, f"{command}\n{result.stderr}"
    else:
        result = subprocess.run(["bash", "-n", "-c", command], capture_output=True, text=True, check=False)
        assert result.returncode == 0, f"{command}\n{result.stderr}"


def test_every_yaml_block_is_a_config_the_pilot_loads(tmp_path: Path) -> None:
    assert blocks("yaml")
    for body in blocks("yaml"):
        data = yaml.safe_load(body)
        pilot_config.from_dict(data, "docs/guide.md")  # ConfigError on an unknown option or a bad value


# --- the pilot's messages --------------------------------------------------------------------------------------


def _pattern(node: ast.expr) -> str | None:
    """The text of a message with each interpolated value as '…'; None when it is not built from literals."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(str(v.value) if isinstance(v, ast.Constant) else "…" for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _pattern(node.left), _pattern(node.right)
        return None if left is None or right is None else left + right
    return None


def pilot_messages() -> dict[str, str]:
    """Every message the pilot raises or prints (and the errors' own texts), as patterns, with where it is.
    A message that is only a value passed through ('pilot: …') says nothing of its own and is left out."""
    found: dict[str, str] = {}
    for path in sorted((ROOT / "pilot").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            call = node.exc if isinstance(node, ast.Raise) else node
            if not isinstance(call, ast.Call) or not call.args:
                continue
            func = call.func
            name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if not (isinstance(node, ast.Raise) or name in ("print", "__init__")):
                continue
            pattern = _pattern(call.args[0])
            for part in (pattern or "").split("\n"):
                if len(re.sub(r"[^A-Za-z]", "", part.replace("pilot: ", "").replace("…", ""))) >= 3:
                    found.setdefault(part.strip(), f"{path.relative_to(ROOT)}:{call.lineno}")
    return found


def test_the_troubleshooting_lists_every_message_the_pilot_can_print() -> None:
    text = GUIDE.read_text(encoding="utf-8")
    section = text[text.index("## Troubleshooting"):]
    messages = pilot_messages()
    assert len(messages) > 80  # the extractor still finds them
    # in backticks; a message holding a backtick in double ones, as Markdown wants
    missing = {m: where for m, where in messages.items() if f"`{m}`" not in section and f"`` {m} ``" not in section}
    assert not missing, "the guide's troubleshooting lacks:\n" + "\n".join(f"{w}: {m}" for m, w in missing.items())


# --- the wiring diagram ----------------------------------------------------------------------------------------


def test_the_wiring_diagram_names_every_pin_of_the_spec() -> None:
    spec = load_spec(ROOT / "spec" / "drone.yaml")
    tree = ET.parse(WIRING)
    ns = {"svg": "http://www.w3.org/2000/svg"}
    drawn = {g.get("data-pin"): " ".join(t.text or "" for t in g.iterfind("svg:text", ns))
             for g in tree.getroot().iterfind("svg:g", ns)}
    wiring = spec.wiring
    for p in wiring.rc_inputs:
        assert f"RC input {p.rc_input}" in drawn[f"D{p.pin}"] and p.name in drawn[f"D{p.pin}"]
    for p in wiring.servos:
        assert p.name in drawn[f"D{p.pin}"]
    assert "laser" in drawn[f"D{wiring.laser.pin}"] and str(spec.baud) in drawn["USB"] and "GND" in drawn
    assert "../generated/docs/wiring.svg" in GUIDE.read_text(encoding="utf-8")
