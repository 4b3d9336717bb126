"""Whatever the validator accepts must give working code: unusual codes and names either fail validation with a
located error (exit 2) or produce Python that imports and C++ that compiles. Never broken generated code."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import protocol_harness as h
import pytest

INIT = "  i:\n    name: init"
ARM = "      a:\n        name: arm"
READY = 'prefix: "#READY"'


def generate_or_reject(tmp_path: Path, text: str, *located_at: str) -> Path | None:
    """Generate `text`; None if it was rejected with an error located at one of `located_at` (spec paths)."""
    spec = tmp_path / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    run = h.generate("--spec", spec, "--out", out)
    if run.code == 2:
        assert any(f": {path}" in run.stderr for path in located_at), run.stderr
        assert not out.exists()
        return None
    assert run.code == 0, run.stderr
    return out


def python_runs(out: Path, code: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(out / "python")}
    proc = subprocess.run([sys.executable, "-W", "error", "-c", code], env=env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout.strip()


def cpp_compiles(out: Path) -> None:
    include = out / "arduino" / "DroneProtocol" / "src"
    proc = subprocess.run(["g++", *h.CXXFLAGS, "-fsyntax-only", f"-I{include}", "-x", "c++", "-"],
                          input="#include <DroneProtocol.h>\nint main() { return 0; }\n", capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]


# Printable ASCII that means something in Python or C++ source: quotes, escapes, comments, trigraph starts.
CODES = ['"', "\\", "'", "?", "#", "`", "{", "%"]


def yaml_key(code: str) -> str:
    return json.dumps(code)  # a JSON string is a valid YAML double-quoted scalar


@pytest.mark.parametrize("code", CODES, ids=[f"0x{ord(c):02x}" for c in CODES])
def test_an_accepted_category_code_gives_working_code(code: str, tmp_path: Path) -> None:
    text = h.edited_spec((INIT, f"  {yaml_key(code)}:\n    name: init"))
    out = generate_or_reject(tmp_path, text, f"categories.{code}")
    if out is None:
        return
    frame = (code + "a0000").encode()
    assert python_runs(out, f"import drone_protocol as p; print(p.arm() == {frame!r}, p.decode({frame!r}).name)") \
        == "True arm"
    cpp_compiles(out)


@pytest.mark.parametrize("code", ['"', "\\", "'", "?"], ids=["0x22", "0x5c", "0x27", "0x3f"])
def test_an_accepted_direction_code_gives_working_code(code: str, tmp_path: Path) -> None:
    text = h.edited_spec((ARM, f"      {yaml_key(code)}:\n        name: arm"))
    out = generate_or_reject(tmp_path, text, f"categories.i.directions.{code}")
    if out is None:
        return
    frame = ("i" + code + "0000").encode()
    assert python_runs(out, f"import drone_protocol as p; print(p.arm() == {frame!r}, p.decode({frame!r}).name)") \
        == "True arm"
    cpp_compiles(out)


@pytest.mark.parametrize("prefix", ['#"READY', "#READY'", "#READY?"])
def test_an_accepted_reply_prefix_gives_working_code(prefix: str, tmp_path: Path) -> None:
    quoted = "'" + prefix.replace("'", "''") + "'"
    out = generate_or_reject(tmp_path, h.edited_spec((READY, f"prefix: {quoted}")), "replies.ready.prefix")
    if out is None:
        return
    assert python_runs(out, "import drone_protocol as p; print(p.parse_reply(p.ready_line()).kind.value)") == prefix
    cpp_compiles(out)


# Names the generated Python module uses itself (builtins it calls, its own functions): a command of that name
# would be a module-level function that replaces them.
SHADOWING = ["ord", "isinstance", "bytes", "len", "chr", "ready_line", "failsafe_line", "find_command", "missing_value"]


@pytest.mark.parametrize("name", SHADOWING)
def test_a_command_name_cannot_shadow_what_the_generated_module_uses(name: str, tmp_path: Path) -> None:
    text = h.edited_spec(("        name: first_test", f"        name: {name}"))
    out = generate_or_reject(tmp_path, text, "categories.i.directions.t.name")
    if out is None:
        return
    check = (
        "import drone_protocol as p\n"
        "for spec in p.COMMANDS.values():\n"
        "    f = getattr(p, spec.name)\n"
        "    frame = f() if spec.default is not None else f(spec.minimum)\n"
        "    assert p.decode(frame).name == spec.name, (spec.name, frame)\n"
        "assert p.parse_reply(p.ready_line()).kind is p.ReplyKind.READY\n"
        "assert p.parse_reply(p.failsafe_line()).kind is p.ReplyKind.FAILSAFE\n"
        "print('ok')\n"
    )
    assert python_runs(out, check) == "ok"


@pytest.mark.parametrize("length", [7, 8])
def test_an_accepted_frame_length_gives_working_code(length: int, tmp_path: Path) -> None:
    """frame.length may be 3..8 by the validator; wider value fields must work on both ends, or be refused."""
    text = h.edited_spec(("  length: 6", f"  length: {length}")).replace("    width: 4\n", f"    width: {length - 2}\n")
    out = generate_or_reject(tmp_path, text, "frame.length", "fields.speed.width")
    if out is None:
        return
    frame = b"sr" + b"45".rjust(length - 2, b"0")
    assert python_runs(out, "import drone_protocol as p; print(p.servo_right(45), p.decode(p.servo_right(45)).value)") \
        == f"{frame!r} 45"
    cpp_compiles(out)
    vectors = json.loads((out / "vectors.json").read_text())["vectors"]
    driver = h.compile_cpp(h.CPP_DIR / "protocol_driver.cpp", f"protocol_driver_{length}",
                           include=out / "arduino" / "DroneProtocol" / "src")
    proc = subprocess.run([str(driver), "decode"], input="".join(v["frame_hex"] + "\n" for v in vectors),
                          capture_output=True, text=True, timeout=60)
    expected = [f"ok {v['command']} {ord(v['category'])} {ord(v['direction'])} {v['value']}" if v["ok"]
                else f"err {v['error']}" for v in vectors]
    assert proc.stdout.splitlines() == expected
