"""Nothing about the protocol written by hand in product code (issue 8): no command, channel or servo name as a
string, no frame as a literal, in the pilot, the demo and the hand-written firmware. They reach the protocol
through the generated module's typed names (CommandName, ChannelName, ServoName) and functions, so a rename in
the spec is a mypy --strict error, never a KeyError in flight. Also: the demo's frames come from the spec."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import drone_protocol as dp

REPO = Path(__file__).resolve().parents[2]
PYTHON = [*sorted((REPO / "pilot").rglob("*.py")), REPO / "generator" / "demo.py"]
CPP = sorted(p for ext in ("*.cpp", "*.h", "*.ino", "*.c") for p in (REPO / "firmware").rglob(ext)
             if "build" not in p.parts)

NAMES = {m.value for m in dp.CommandName} | {m.value for m in dp.ChannelName} | {m.value for m in dp.ServoName}
CATEGORY_CODES = {c.value for c in dp.Category}
# The firmware reports its state machine's states by the spec's status names (the virtual drone's JSON lines);
# "hold_altitude" is both a command and a state name, so those are left to the status section's owner.
STATE_NAMES = {s.name.lower() for s in dp.DroneState}


def frame_like(text: str) -> bool:
    """A literal that looks like a frame (or a mangled one): a category byte or any letter/digit, a second
    byte, then digits (and '-', as in the seed's mf00-5)."""
    if not 3 <= len(text) <= dp.WIRE_LENGTH + 2:
        return False
    head, tail = text[:2], text[2:]
    starts = head[0] in CATEGORY_CODES or (len(text) == dp.FRAME_LENGTH and head.isalnum())
    return starts and head.isascii() and head.isalnum() and bool(re.fullmatch(r"[0-9-]*[0-9][0-9-]*", tail))


def _docstrings(tree: ast.AST) -> set[int]:
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                ids.add(id(first.value))
    return ids


def _enum_members(tree: ast.AST) -> set[int]:
    """Values of Enum members defined here (the pilot's own states, e.g. State.ARM = "arm")."""
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef) and any("Enum" in ast.unparse(b) for b in node.bases):
            for stmt in node.body:
                if isinstance(stmt, ast.Assign) and isinstance(stmt.value, ast.Constant):
                    ids.add(id(stmt.value))
    return ids


def python_findings(path: Path, root: Path = REPO) -> Iterator[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    skip = _docstrings(tree) | _enum_members(tree)
    for node in ast.walk(tree):
        if not isinstance(node, ast.Constant) or id(node) in skip:
            continue
        value = node.value
        text = value.decode("latin-1") if isinstance(value, bytes) else value
        if not isinstance(text, str):
            continue
        where = f"{path.relative_to(root)}:{node.lineno}"
        if text in NAMES:
            yield f"{where}: the protocol name {text!r} as a string (use the generated enum)"
        elif frame_like(text):
            yield f"{where}: a hand-written frame {text!r} (build it with the generated module)"


_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_STRING = re.compile(r'"((?:[^"\\\n]|\\.)*)"')


def cpp_findings(path: Path, root: Path = REPO) -> Iterator[str]:
    source = path.read_text(encoding="utf-8")
    code = _COMMENT.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), source)  # keep the line numbers
    for m in _STRING.finditer(code):
        text = m.group(1)
        line = code.count("\n", 0, m.start()) + 1
        where = f"{path.relative_to(root)}:{line}"
        if text in NAMES and text not in STATE_NAMES:
            yield f"{where}: the protocol name {text!r} as a string (use the generated identifiers)"
        elif frame_like(text):
            yield f"{where}: a hand-written frame {text!r} (use the generated library)"


def test_the_scan_finds_what_it_looks_for(tmp_path: Path) -> None:
    """The scanner itself: the patterns of issue 8 are caught, the pilot's own state names are not."""
    bad = tmp_path / "bad.py"
    bad.write_text(
        '"""Docstrings may say ``turn_left`` and ik0000."""\n'
        "import enum\n"
        "class State(enum.Enum):\n    ARM = 'arm'\n"
        "x = _speed('turn_left', 1.0)\n"
        "y = CHANNELS['yaw']\n"
        "z = [b'sz0010', b'100000', 'mf00-5', b'mf16', 'ik0000']\n"
        "w = ('2000', 'h264', 'v1.0', 'abc')\n"
    )
    found = list(python_findings(bad, tmp_path))
    assert [f.split(":")[1] for f in found] == ["5", "6", "7", "7", "7", "7", "7"], found
    cpp = tmp_path / "bad.cpp"
    cpp.write_text('// "sr0180" in a comment\nconst char* a = "ik0000";\nconst char* b = "hold_altitude";\n'
                   'const char* c = "move_up";\n')
    assert [f.split(":")[1] for f in cpp_findings(cpp, tmp_path)] == ["2", "4"]


def test_no_protocol_name_or_frame_by_hand_in_product_code() -> None:
    assert PYTHON and CPP
    findings = [f for p in PYTHON for f in python_findings(p)] + [f for p in CPP for f in cpp_findings(p)]
    assert not findings, "protocol written by hand outside spec/ and generated/:\n" + "\n".join(findings)


def test_the_demo_derives_every_command_and_every_parser_error_from_the_spec() -> None:
    from generator.demo import rejected_frames

    kinds = set()
    for _why, frame in rejected_frames():
        try:
            dp.decode(frame)
        except dp.ProtocolError as exc:
            kinds.add(exc.kind)
        else:
            raise AssertionError(f"{frame!r} decoded")
    expected = {dp.ErrorKind.BAD_CATEGORY, dp.ErrorKind.BAD_DIRECTION, dp.ErrorKind.BAD_DIGIT,
                dp.ErrorKind.OUT_OF_RANGE, dp.ErrorKind.TOO_SHORT, dp.ErrorKind.TOO_LONG}
    assert kinds == expected
    out = subprocess.run([sys.executable, "-m", "generator.demo"], cwd=REPO, capture_output=True, text=True,
                         check=True).stdout
    for name in dp.CommandName:
        assert f"-> {name.value} " in out
