"""`python -m generator diff OLD [NEW]` on hand-made spec pairs, and the rule that protocol.version rises on a
break (checked against the generated contract.json by generation and by --check)."""

from __future__ import annotations

import shutil
from pathlib import Path

import protocol_harness as h
import pytest

from generator.build import load_spec

VERSION = ("  version: 1", "  version: 2")
CODE_R = ("  out_of_range:\n    code: r\n", "  out_of_range:\n    code: R\n")
TURN_LEFT = "      l:\n        name: left\n        description: Turn left"
TURN_RIGHT = "      r:\n        name: right\n        description: Turn right"
ANGLE = "    range: [1, 180]"
RELOAD = "re-load the parameter file in generated/ardupilot/ into the flight controller"

# (id, edits of the fixture, expected lines of the report without the summary, breaking?)
PAIRS = [
    ("nothing changed", (), [], False),
    ("command added", (("        routine: firstTest()\n",
                        "        routine: firstTest()\n      z:\n        name: zoom\n        description: Zoom\n"),),
     ["ok    command iz added (zoom)"], False),
    ("range widened", ((ANGLE, "    range: [1, 200]"),),
     [f"ok    command s{d} (servo_{n}): range 1..180 widened to 1..200"
      for d, n in (("d", "down"), ("l", "left"), ("r", "right"), ("u", "up"))], False),
    ("text changed", (("        description: Strafe left", "        description: Strafe to the left"),),
     ["ok    command ml (move_left): description 'Strafe left' -> 'Strafe to the left'"], False),
    ("a direction renamed", ((TURN_LEFT, "      l:\n        name: ccw\n        description: Turn left"),),
     ["ok    command tl (turn_ccw): name 'turn_left' -> 'turn_ccw'"], False),
    ("inter-byte timeout raised", (("  inter_byte_timeout_ms: 20", "  inter_byte_timeout_ms: 30"),),
     ["ok    frame.inter_byte_timeout_ms: 20 -> 30"], False),
    ("command removed", (("      t:\n        name: first_test", "      T:\n        name: first_test"),),
     ["BREAK command it removed (first_test)", "ok    command iT added (first_test)"], True),
    ("range narrowed", ((ANGLE, "    range: [1, 90]"),),
     [f"BREAK command s{d} (servo_{n}): range 1..180 narrowed to 1..90"
      for d, n in (("d", "down"), ("l", "left"), ("r", "right"), ("u", "up"))], True),
    ("codes swapped: a code reused with another meaning",
     ((TURN_LEFT, TURN_LEFT.replace("name: left", "name: right")),
      (TURN_RIGHT, TURN_RIGHT.replace("name: right", "name: left"))),
     ["BREAK command tl: now turn_right, which was tr (a code reused with another meaning)",
      "BREAK command tr: now turn_left, which was tl (a code reused with another meaning)",
      "ok    command tl (turn_right): name 'turn_left' -> 'turn_right'",
      "ok    command tr (turn_left): name 'turn_right' -> 'turn_left'"], True),
    ("a direction drives another channel", (("        channel: pitch\n        default: high",
                                              "        channel: roll\n        default: high"),),
     ["BREAK command mf (move_forward): target 'pitch' -> 'roll' (a code reused with another meaning)"], True),
    ("error code changed", (CODE_R,),
     ["BREAK error out_of_range: code 'r' -> 'R'"], True),
    ("reply prefix changed", (("    prefix: A\n", "    prefix: OK\n"),),
     ["BREAK reply accepted: prefix 'A' -> 'OK'"], True),
    ("baud changed", (("  baud: 115200", "  baud: 57600"),), ["BREAK link.baud: 115200 -> 57600"], True),
    ("integrity mode changed", (("  integrity: none", "  integrity: crc8"),),
     ["BREAK frame.integrity: 'none' -> 'crc8'", "BREAK frame.wire_length: 6 -> 8"], True),
    ("inter-byte timeout lowered", (("  inter_byte_timeout_ms: 20", "  inter_byte_timeout_ms: 10"),),
     ["BREAK frame.inter_byte_timeout_ms: 20 -> 10"], True),
    # how the drone flies: a new dead band or reversal needs the flight controller's parameters loaded again
    ("throttle dead band widened", (("  throttle_dead_band: 10", "  throttle_dead_band: 100"),),
     [f"BREAK flight_controller.arducopter-{line}/THR_DZ: 10 -> 100 ({RELOAD})" for line in ("3.2", "4")], True),
    ("pitch reversal removed", (("  reversed: [pitch]", "  reversed: []"),),
     [f"BREAK flight_controller.arducopter-3.2/RC2_REV: -1 -> unset (ArduCopter's default) ({RELOAD})",
      f"BREAK flight_controller.arducopter-4/RC2_REVERSED: 1 -> unset (ArduCopter's default) ({RELOAD})"], True),
    ("yaw reversed too", (("  reversed: [pitch]", "  reversed: [pitch, yaw]"),),
     [f"BREAK flight_controller.arducopter-3.2/RC4_REV: unset -> -1 ({RELOAD})",
      f"BREAK flight_controller.arducopter-4/RC4_REVERSED: unset -> 1 ({RELOAD})"], True),
    ("speed step changed", (("  step_us: 100", "  step_us: 150"),),
     ["ok    flight.step_us: 100 -> 150 (how the drone flies: the default speeds and the landing descent)",
      *(f"ok    command {code} ({name}): default {old} -> {new}" for code, name, old, new in (
          ("mf", "move_forward", 1600, 1650), ("mb", "move_backward", 1400, 1350), ("ml", "move_left", 1400, 1350),
          ("mr", "move_right", 1600, 1650), ("mu", "move_up", 1621, 1671), ("md", "move_down", 1421, 1371),
          ("tl", "turn_left", 1424, 1374), ("tr", "turn_right", 1624, 1674)))], False),
]


def spec_file(tmp_path: Path, name: str, *edits: tuple[str, str]) -> Path:
    path = tmp_path / name
    path.write_text(h.edited_spec(*edits), encoding="utf-8")
    return path


@pytest.mark.parametrize(("edits", "expected", "breaking"), [p[1:] for p in PAIRS], ids=[p[0] for p in PAIRS])
def test_diff_lists_each_change_and_marks_the_breaking_ones(
        edits: tuple[tuple[str, str], ...], expected: list[str], breaking: bool, tmp_path: Path) -> None:
    old, new = h.FIXTURE, spec_file(tmp_path, "new.yaml", *edits)
    run = h.generate("diff", old, new)
    *lines, summary = run.stdout.splitlines()
    assert sorted(lines) == sorted(expected)
    assert lines == sorted(lines, key=lambda line: not line.startswith("BREAK")), "breaking changes come first"
    breaks = sum(line.startswith("BREAK") for line in lines)
    assert summary.startswith(f"{breaks} breaking, {len(lines) - breaks} compatible change")
    assert summary.endswith(": the version must rise)") == breaking
    assert run.code == (1 if breaking else 0)


def test_a_break_with_a_risen_version_still_exits_1_but_asks_nothing(tmp_path: Path) -> None:
    new = spec_file(tmp_path, "new.yaml", ("  baud: 115200", "  baud: 57600"), VERSION)
    run = h.generate("diff", h.FIXTURE, new)
    assert run.code == 1 and run.stdout.splitlines()[-1] == "1 breaking, 0 compatible changes (version 1 -> 2)"


def test_diff_of_an_invalid_spec_exits_2_with_located_errors(tmp_path: Path) -> None:
    bad = spec_file(tmp_path, "bad.yaml", ("  baud: 115200", "  baud: fast"))
    run = h.generate("diff", h.FIXTURE, bad)
    assert run.code == 2 and run.stdout == ""
    assert f"{bad}:{h.location(bad.read_text(), 'fast')}: link.baud: expected an integer" in run.stderr


def test_new_defaults_to_the_live_spec_and_old_may_be_a_generated_contract() -> None:
    version = load_spec(h.SPEC).version
    run = h.generate_subprocess("diff", "generated/contract.json")
    assert (run.code, run.stdout.splitlines()) == (0, [f"0 breaking, 0 compatible changes (version {version} -> "
                                                       f"{version})"])


def generated_copy(tmp_path: Path) -> Path:
    out = tmp_path / "generated"
    shutil.copytree(h.fixture_generated(), out)
    return out


def test_generation_refuses_a_break_whose_version_did_not_rise_and_writes_nothing(tmp_path: Path) -> None:
    out = generated_copy(tmp_path)
    before = h.tree(out)
    new = spec_file(tmp_path, "drone.yaml", CODE_R)
    where = h.location(new.read_text(), "1\n  title")
    for check in ((), ("--check",)):
        run = h.generate("--spec", new, "--out", out, *check)
        assert run.code == 2, run.stdout + run.stderr
        assert run.stderr.splitlines()[1].startswith(
            f"{new}:{where}: protocol.version: version must rise: 1 breaking change since the generated version 1, "
            "first: error out_of_range: code 'r' -> 'R' (hint: raise protocol.version")
        assert h.tree(out) == before
    risen = spec_file(tmp_path, "drone.yaml", CODE_R, VERSION)
    assert h.generate("--spec", risen, "--out", out).code == 0
    assert h.generate("--spec", risen, "--out", out, "--check").code == 0


def test_compatible_edits_need_no_new_version_and_the_version_never_falls(tmp_path: Path) -> None:
    out = generated_copy(tmp_path)
    compatible = spec_file(tmp_path, "drone.yaml", ("        description: Strafe left", "        description: Left"))
    assert h.generate("--spec", compatible, "--out", out).code == 0
    assert h.generate("--spec", spec_file(tmp_path, "v2.yaml", VERSION), "--out", out).code == 0
    run = h.generate("--spec", h.FIXTURE, "--out", out)
    assert run.code == 2 and "protocol.version: version 1 is lower than the generated version 2" in run.stderr


def test_another_protocol_in_the_output_folder_is_not_a_previous_version(tmp_path: Path) -> None:
    out = generated_copy(tmp_path)
    other = spec_file(tmp_path, "other.yaml", ("  name: drone_protocol", "  name: rover_protocol"),
                      ("  baud: 115200", "  baud: 9600"))
    assert h.generate("--spec", other, "--out", out).code == 0


# A contract.json edited by hand or by a bad merge: each raised a TypeError or KeyError inside the comparison.
BROKEN = [("<<<<<<< HEAD\n", "is not valid JSON"),
          ('{"contract": {"name": "drone_protocol", "version": 1, "commands": 5}}', "commands is not a mapping"),
          ('{"contract": {"name": "drone_protocol", "version": 1, "commands": {"mf": {"name": "move_forward"}}}}',
           "commands.mf.min is missing or not int"),
          ('{"contract": {"name": "drone_protocol", "version": "1"}}', "its name or its integer version is missing")]


@pytest.mark.parametrize(("text", "problem"), BROKEN, ids=["conflict markers", "a number for a table",
                                                           "an entry without its range", "a text version"])
def test_a_broken_contract_is_one_line_naming_it_and_nothing_is_written(tmp_path: Path, text: str,
                                                                        problem: str) -> None:
    out = generated_copy(tmp_path)
    (out / "contract.json").write_text(text, encoding="utf-8")
    before = h.tree(out)
    for args in (("--spec", h.FIXTURE, "--out", out), ("--spec", h.FIXTURE, "--out", out, "--check"),
                 ("diff", out / "contract.json", h.FIXTURE)):
        run = h.generate(*args)
        assert run.code == 2 and run.stderr.count("\n") == 1 and "Traceback" not in run.stderr, run.stderr
        assert f"error: {out / 'contract.json'} " in run.stderr and problem in run.stderr, run.stderr
    assert h.tree(out) == before
