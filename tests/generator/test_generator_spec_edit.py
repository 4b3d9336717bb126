"""Editing the spec works end to end: a new category and a new direction reach Python and C++ with no hand edit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import protocol_harness as h
import pytest

from generator.build import load_spec

# One new category (g, gripper: a command with a value and one without) and one new direction in an existing
# category (t h, turn_hold: a speed whose default is a label of Table 4).
NEW_CATEGORY = """\
  g:
    name: gripper
    hardware: Gripper servo
    description: Open the gripper by some degrees, or close it.
    field: angle
    directions:
      o:
        name: open
        description: Open by some degrees
      c:
        name: close
        description: Close the gripper
        field: zero
"""
YAW_HIGH = "        channel: yaw\n        default: high\n"
NEW_DIRECTION = """\
      h:
        name: hold
        description: Hold the heading
        channel: yaw
        default: median
"""

PYTHON_CHECK = '''\
from __future__ import annotations

import drone_protocol as p

assert p.SPEC_FINGERPRINT == "{fingerprint}", p.SPEC_FINGERPRINT
assert p.Category.GRIPPER.value == "g" and p.Category("g") is p.Category.GRIPPER
assert [d.value for d in p.GripperDirection] == ["o", "c"]
assert p.TurnDirection.HOLD.value == "h"

frame: bytes = p.gripper_open(45)
assert frame == b"go0045", frame
assert p.decode(frame) == p.Command(p.Category.GRIPPER, p.GripperDirection.OPEN, 45, p.CommandName.GRIPPER_OPEN)
assert p.gripper_close() == b"gc0000" and p.decode(b"gc0000").name == "gripper_close"
assert p.turn_hold() == b"th1524" and p.turn_hold(1035) == b"th1035"
assert p.encode("t", "h") == b"th1524" and p.encode(p.Category.GRIPPER, "o", 180) == b"go0180"
held = p.decode(b"th2012")
assert (held.category, held.direction, held.value) == (p.Category.TURN, p.TurnDirection.HOLD, 2012)
assert held.name == "turn_hold"
assert p.COMMANDS[p.CommandName.TURN_HOLD].default == p.CHANNELS[p.ChannelName.YAW].median == 1524

for bad, kind in ((b"go0000", p.ErrorKind.OUT_OF_RANGE), (b"go0181", p.ErrorKind.OUT_OF_RANGE),
                  (b"gx0045", p.ErrorKind.BAD_DIRECTION), (b"th1034", p.ErrorKind.OUT_OF_RANGE)):
    try:
        p.decode(bad)
    except p.ProtocolError as exc:
        assert exc.kind is kind, (bad, exc.kind)
    else:
        raise AssertionError(f"{{bad!r}} decoded")
try:
    p.gripper_open(0)
except p.OutOfRangeError:
    pass
else:
    raise AssertionError("gripper_open(0) encoded")

stream = p.StreamDecoder(time_fn=lambda: 0.0)
found = stream.feed(b"zz" + p.gripper_open(7) + b"?" + p.turn_hold() + p.move_forward())
assert [c.name for c in found] == ["gripper_open", "turn_hold", "move_forward"], found
assert p.decode(p.arm()).name == "arm"  # the old commands are untouched
print("python ok")
'''

CPP_CHECK = r"""
#include <DroneProtocol.h>
#include <stdio.h>
#include <string.h>

using namespace drone_protocol;

// Category handlers only, plus one specific handler: dispatch must prefer on_gripper_close for gc and fall
// back to on_gripper / on_turn for the new commands.
struct Handlers {
  char last[32];
  uint16_t value;
  void on_move(const Command& c) { strcpy(last, "move"); value = c.value; }
  void on_turn(const Command& c) { strcpy(last, "turn"); value = c.value; }
  void on_servo(const Command& c) { strcpy(last, "servo"); value = c.value; }
  void on_laser(const Command& c) { strcpy(last, "laser"); value = c.value; }
  void on_init(const Command& c) { strcpy(last, "init"); value = c.value; }
  void on_gripper(const Command& c) { strcpy(last, "gripper"); value = c.value; }
  void on_gripper_close(const Command& c) { strcpy(last, "gripper_close"); value = c.value; }
};

static int failures = 0;
#define CHECK(cond) do { if (!(cond)) { printf("FAILED line %d: %s\n", __LINE__, #cond); ++failures; } } while (0)

int main() {
  uint8_t frame[FRAME_LENGTH];
  CHECK(encode(CommandId::GripperOpen, 45, frame) == Error::None);
  CHECK(memcmp(frame, "go0045", FRAME_LENGTH) == 0);
  CHECK(encode(CommandId::GripperOpen, 0, frame) == Error::OutOfRange);
  CHECK(encode(CommandId::TurnHold, command_info(CommandId::TurnHold).default_value, frame) == Error::None);
  CHECK(memcmp(frame, "th1524", FRAME_LENGTH) == 0);
  CHECK(command_info(CommandId::TurnHold).target == Target::Yaw);
  CHECK(strcmp(command_name(CommandId::GripperClose), "gripper_close") == 0);

  Handlers handlers{};
  Command cmd{};
  CHECK(decode(reinterpret_cast<const uint8_t*>("go0045"), cmd) == Error::None);
  CHECK(cmd.id == CommandId::GripperOpen && cmd.value == 45 && cmd.category == 'g' && cmd.direction == 'o');
  dispatch(cmd, handlers);
  CHECK(strcmp(handlers.last, "gripper") == 0 && handlers.value == 45);
  CHECK(decode(reinterpret_cast<const uint8_t*>("gc0000"), cmd) == Error::None);
  dispatch(cmd, handlers);
  CHECK(strcmp(handlers.last, "gripper_close") == 0);
  CHECK(decode(reinterpret_cast<const uint8_t*>("th1035"), cmd) == Error::None);
  CHECK(cmd.id == CommandId::TurnHold && cmd.value == 1035);
  dispatch(cmd, handlers);
  CHECK(strcmp(handlers.last, "turn") == 0 && handlers.value == 1035);
  CHECK(decode(reinterpret_cast<const uint8_t*>("go0181"), cmd) == Error::OutOfRange);
  CHECK(decode(reinterpret_cast<const uint8_t*>("gz0045"), cmd) == Error::BadDirection);

  StreamParser parser;
  const char* stream = "zzgo0007?th1524";
  int frames = 0;
  for (const char* p = stream; *p; ++p) {
    if (parser.feed(static_cast<uint8_t>(*p), 0)) {
      ++frames;
      dispatch(parser.command(), handlers);
    }
  }
  CHECK(frames == 2 && strcmp(handlers.last, "turn") == 0 && handlers.value == 1524);
  CHECK(strlen(SPEC_FINGERPRINT) == 16);
  printf("%s %s\n", failures ? "c++ FAILED" : "c++ ok", SPEC_FINGERPRINT);
  return failures ? 1 : 0;
}
"""


@pytest.fixture(scope="module")
def edited(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A spec with the new category and direction, regenerated into a temporary folder (returned)."""
    root = tmp_path_factory.mktemp("spec_edit")
    text = h.edited_spec(
        ("  l:\n    name: laser\n", NEW_CATEGORY + "  l:\n    name: laser\n"),
        (YAW_HIGH, YAW_HIGH + NEW_DIRECTION),
    )
    spec = root / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    run = h.generate_subprocess("--spec", spec, "--out", root / "generated")
    assert run.code == 0, run.stderr
    return root


def test_the_edited_spec_has_a_new_fingerprint(edited: Path) -> None:
    assert load_spec(edited / "drone.yaml").fingerprint != load_spec(h.FIXTURE).fingerprint
    run = h.generate("--spec", edited / "drone.yaml", "--out", h.fixture_generated(), "--check")  # now stale
    assert run.code == 1


def test_the_new_python_module_encodes_and_decodes_the_new_commands(edited: Path) -> None:
    script = edited / "check_new_commands.py"
    script.write_text(PYTHON_CHECK.format(fingerprint=load_spec(edited / "drone.yaml").short_fingerprint))
    env = {**os.environ, "PYTHONPATH": str(edited / "generated" / "python")}
    proc = subprocess.run([sys.executable, "-W", "error", str(script)], env=env, capture_output=True, text=True,
                          timeout=60, cwd=edited)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "python ok"
    # and it was the new module that ran, not the installed one
    where = subprocess.run([sys.executable, "-c", "import drone_protocol; print(drone_protocol.__file__)"], env=env,
                           capture_output=True, text=True, timeout=60, cwd=edited)
    assert Path(where.stdout.strip()).is_relative_to(edited)


def test_the_new_python_module_and_its_use_pass_mypy_strict(edited: Path) -> None:
    script = edited / "check_new_commands.py"
    script.write_text(PYTHON_CHECK.format(fingerprint=load_spec(edited / "drone.yaml").short_fingerprint))
    package = edited / "generated" / "python" / "drone_protocol"
    env = {**os.environ, "MYPYPATH": str(package.parent)}
    proc = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental", "--python-version", "3.11",
                           "--config-file", os.devnull, str(package), str(script)], env=env, capture_output=True,
                          text=True, timeout=240, cwd=edited)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_new_cpp_header_compiles_encodes_decodes_and_dispatches_to_the_category_handler(edited: Path) -> None:
    include = edited / "generated" / "arduino" / "DroneProtocol" / "src"
    exe = h.compile_cpp(CPP_CHECK, "spec_edit_check", include=include)
    proc = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    fingerprint = load_spec(edited / "drone.yaml").short_fingerprint
    assert (proc.returncode, proc.stdout.strip()) == (0, f"c++ ok {fingerprint}"), proc.stdout


def test_both_new_codecs_pass_the_new_vectors(edited: Path) -> None:
    vectors = json.loads((edited / "generated" / "vectors.json").read_text())["vectors"]
    new = [v for v in vectors if v.get("command") in ("gripper_open", "gripper_close", "turn_hold")]
    assert len(new) == 6, "the vectors do not cover the new commands at their minimum, maximum and default"
    frames = {v["frame"] for v in vectors if v.get("error") == "out_of_range"}
    assert {"go0000", "go0181", "th1034", "th2013"} <= frames
    include = edited / "generated" / "arduino" / "DroneProtocol" / "src"
    driver = h.compile_cpp(h.CPP_DIR / "protocol_driver.cpp", "protocol_driver_edited", include=include)
    proc = subprocess.run([str(driver), "decode"], input="".join(v["frame_hex"] + "\n" for v in vectors),
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == len(vectors)
    for vector, line in zip(vectors, lines, strict=True):
        if vector["ok"]:
            expected = f"ok {vector['command']} {ord(vector['category'])} {ord(vector['direction'])} {vector['value']}"
        else:
            expected = f"err {vector['error']}"
        assert line == expected, vector


def test_the_new_docs_list_the_new_commands(edited: Path) -> None:
    docs = (edited / "generated" / "docs" / "protocol.md").read_text()
    for text in ("gripper_open", "gripper_close", "turn_hold", "`gc0000`", "`th1524`", "Gripper servo"):
        assert text in docs, text


def test_no_file_of_the_repository_changed() -> None:
    assert h.generate("--spec", h.SPEC, "--out", h.GENERATED, "--check").code == 0


NEW_INIT = """\
      z:
        name: zoom
        description: Zoom in
        routine: zoom()
"""


def test_a_new_init_command_needs_no_other_change(tmp_path: Path) -> None:
    text = h.edited_spec(("        routine: firstTest()\n", "        routine: firstTest()\n" + NEW_INIT))
    spec = tmp_path / "drone.yaml"
    spec.write_text(text)
    assert h.generate("--spec", spec, "--out", tmp_path / "out").code == 0
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "out" / "python")}
    code = "import drone_protocol as p; print(p.zoom(), p.decode(p.zoom()).name)"
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert proc.stdout.strip() == "b'iz0000' zoom", proc.stderr


def test_a_speed_direction_without_a_default_generates_and_needs_a_value(tmp_path: Path) -> None:
    # a spec mutation found it: the docs' movement table printed the example frame of a default there was none of
    text = h.edited_spec(("        description: Strafe left\n        channel: roll\n        default: low\n",
                          "        description: Strafe left\n        channel: roll\n"))
    spec = tmp_path / "drone.yaml"
    spec.write_text(text)
    run = h.generate("--spec", spec, "--out", tmp_path / "out")
    assert run.code == 0, run.stderr
    docs = (tmp_path / "out" / "docs" / "protocol.md").read_text()
    assert "| `l` | Strafe left | none: required | 1000–2000 | roll | `ml1000` |" in docs
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "out" / "python")}
    code = ("import drone_protocol as p; print(p.move_left(1400))\n"
            "try:\n p.move_left()\nexcept TypeError: print('required')")
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert proc.stdout.split() == ["b'ml1400'", "required"], proc.stderr


AVR_SKETCH = """
#include <DroneProtocol.h>
using drone_protocol::Command;
struct Handlers {
  volatile uint16_t last;
  void on_move(const Command& c) { last = c.value; }
  void on_turn(const Command& c) { last = c.value; }
  void on_servo(const Command& c) { last = c.value; }
  void on_laser(const Command& c) { last = c.value; }
  void on_init(const Command& c) { last = c.value; }
  void on_gripper(const Command& c) { last = c.value; }
};
drone_protocol::StreamParser parser;
Handlers handlers;
volatile uint8_t rx;
int main() {
  for (uint32_t now = 0;; ++now) {
    if (parser.feed(rx, now)) drone_protocol::dispatch(parser.command(), handlers);
  }
}
"""


def test_the_new_header_builds_for_the_arduino_uno_with_avr_gcc(edited: Path) -> None:
    include = edited / "generated" / "arduino" / "DroneProtocol" / "src"
    source = edited / "sketch.cpp"
    source.write_text(AVR_SKETCH)
    proc = subprocess.run(["avr-g++", "-std=gnu++11", "-mmcu=atmega328p", "-Os", "-Wall", "-Wextra", "-Werror",
                           f"-I{include}", str(source), "-o", str(edited / "sketch.elf")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
