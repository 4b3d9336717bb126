"""Broken specs: exit 2, every error reported as `file:line:column: path: message (hint: ...)`, nothing written.

Each case is a small inline edit of the real spec/drone.yaml. Expected locations are computed from an anchor in
the edited text (where the reported token starts), so the cases survive unrelated edits of the spec while still
asserting the exact line and column.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import protocol_harness as h
import pytest


@dataclass(frozen=True)
class Case:
    id: str
    edits: tuple[tuple[str, str], ...]
    # (anchor, "path: message (hint: ...)"): the error is reported where the anchor starts in the edited spec.
    # An anchor "context^token" locates `token`, found after `context`.
    errors: tuple[tuple[str, str], ...]
    text: str | None = None  # the whole spec instead of edits of the real one

    def spec(self) -> str:
        if self.text is not None:
            return self.text
        return h.edited_spec(*self.edits)


def at(text: str, anchor: str) -> str:
    context, _, token = anchor.rpartition("^")
    line_col = h.location(text, context + token)
    if not context:
        return line_col
    start = text.index(context + token) + len(context)
    line = text.count("\n", 0, start) + 1
    return f"{line}:{start - (text.rfind(chr(10), 0, start) + 1) + 1}"


def line_of(anchor: str, *edits: tuple[str, str]) -> int:
    return int(h.location(h.edited_spec(*edits), anchor).split(":")[0])


IDENT_HINT = "(hint: names become Python and C++ identifiers)"
LINK_8N1 = "is not supported: the firmware and the pilot run 8 data bits, no parity, 1 stop bit"
RC_HINT = "(hint: ArduPilot's RCn_MIN and RCn_MAX range: the flight controller reads no stick outside it)"
TEXT_HINT = "(hint: write plain text; it is printed into the code of every target)"
NO_RANGE = ("field 'angle' has no range and the direction drives no channel "
            "(hint: give the field a range or the direction a channel)")
SERVO_MOVES = (("u", "      u:\n        ^name: up\n        description: Up\n"),
               ("d", "      d:\n        ^name: down\n        description: Down\n"),
               ("l", "      l:\n        ^name: left\n        description: Left\n"),
               ("r", "      r:\n        ^name: right\n        description: Right"))

SENSE_1 = "        servo: tilt\n        sense: 1"
PITCH_HIGH = "        channel: pitch\n        default: high"
ROLL_LOW = "        channel: roll\n        default: low"
STRAFE = "        description: Strafe left"
DUP_CAT = ("  t:\n    name: turn", "  m:\n    name: turn")
DUP_DIR = ("      b:\n        name: backward", "      f:\n        name: backward")
DUP_KEY = ("        name: backward\n", "        name: backward\n        name: back\n")
FIRST_M = line_of("  m:\n    name: move", DUP_CAT)
FIRST_F = line_of("      f:\n        name: forward", DUP_DIR)
FIRST_NAME = line_of("name: backward", DUP_KEY)

CASES = [
    # -- unknown and missing keys ----------------------------------------------------------------------------
    Case("unknown key, with did-you-mean", (("  stop_bits: 1", "  stop_bit: 1"),),
         (("stop_bit: 1", "link.stop_bit: unknown key 'stop_bit' (hint: did you mean 'stop_bits'?)"),)),
    Case("unknown key in a direction", ((SENSE_1, "        servo: tilt\n        sens: 1"),),
         (("sens: 1", "categories.s.directions.u.sens: unknown key 'sens' (hint: did you mean 'sense'?)"),)),
    Case("unknown top-level key lists the known ones", (("# Tables 1, 2, 3, 5 and 6.\n", "notes: hello\n"),),
         (("notes: hello", "notes: unknown key 'notes' (hint: known keys: categories, channels, errors, fields, "
           "flight_controller, flight_modes, frame, link, project, protocol, replies, safety, servos, settled, "
           "speeds, status, wiring)"),)),
    Case("missing key", (("        name: backward\n", ""),),
         (("description: Backward", "categories.m.directions.b.name: missing key 'name'"),)),
    Case("missing key of a category: no field for its directions",
         (("    field: speed\n    directions:\n      l:", "    directions:\n      l:"),),
         (("      l:\n        ^name: left\n        description: Turn left",
           "categories.t.directions.l.field: missing key 'field' "
           "(hint: give the direction or its category a field)"),
          ("      r:\n        ^name: right\n        description: Turn right",
           "categories.t.directions.r.field: missing key 'field' "
           "(hint: give the direction or its category a field)"))),
    Case("missing parser error kind", (("  too_long:\n    code: l\n    description: The frame has more than 6 bytes\n",
                                        ""),),
         (("errors:\n  ^bad_category:", "errors.too_long: missing error 'too_long' "
           "(hint: the generated code relies on it)"),)),
    # -- duplicates --------------------------------------------------------------------------------------------
    Case("duplicate category", (DUP_CAT,),
         (("m:\n    name: turn", f"categories.m: duplicate key 'm' (first defined at line "
           f"{FIRST_M})"),)),
    Case("duplicate direction", (DUP_DIR,),
         (("f:\n        name: backward", f"categories.m.directions.f: duplicate key 'f' (first defined at line "
           f"{FIRST_F})"),)),
    Case("duplicate key", (DUP_KEY,),
         (("name: back\n", f"categories.m.directions.b.name: duplicate key 'name' (first defined at line "
           f"{FIRST_NAME})"),)),
    Case("duplicate error code", (("    code: b\n", "    code: c\n"),),
         (("  busy:\n    code: ^c", "errors.busy.code: error code 'c' is already used by bad_category"),)),
    Case("reply prefix that starts another", (("    prefix: A\n", "    prefix: \"#\"\n"),),
         (("  accepted:\n    ^prefix", "replies.accepted.prefix: prefix '#' is the start of '#READY' "
           "(hint: reply prefixes must not be prefixes of each other)"),)),
    # -- codes -------------------------------------------------------------------------------------------------
    Case("multi-character category code", (("  t:\n    name: turn", "  tt:\n    name: turn"),),
         (("tt:", "categories.tt: category code 'tt' is not one printable ASCII character "
           "(hint: use one letter, e.g. 'm')"),)),
    Case("multi-character direction code", (("      b:\n        name: backward", "      bk:\n        name: backward"),),
         (("bk:", "categories.m.directions.bk: direction code 'bk' is not one printable ASCII character "
           "(hint: use one letter, e.g. 'f')"),)),
    Case("non-printable category code", (("  t:\n    name: turn", '  "\\t":\n    name: turn'),),
         (('"\\t":', "categories.\t: category code '\\t' is not one printable ASCII character "
           "(hint: use one letter, e.g. 'm')"),)),
    Case("space as direction code", (("      b:\n        name: backward", '      " ":\n        name: backward'),),
         (('" ":', "categories.m.directions. : direction code ' ' is not one printable ASCII character "
           "(hint: use one letter, e.g. 'f')"),)),
    Case("non-ASCII category code", (("  t:\n    name: turn", '  "é":\n    name: turn'),),
         (('"é":', "categories.é: category code 'é' is not one printable ASCII character "
           "(hint: use one letter, e.g. 'm')"),)),
    Case("digit as category code", (("  t:\n    name: turn", '  "7":\n    name: turn'),),
         (('"7":', "categories.7: category code '7' is a digit "
           "(hint: a digit would be mistaken for a value byte when resynchronising)"),)),
    # -- ranges and defaults -----------------------------------------------------------------------------------
    Case("range not fitting the width", (("    range: [1, 180]", "    range: [1, 18000]"),),
         (("[1, 18000]", "fields.angle.range: maximum 18000 does not fit in 4 digits (hint: at most 9999)"),
          *((a, f"categories.s.directions.{d}: range 1..18000 does not fit in 4 digits") for d, a in SERVO_MOVES))),
    Case("recorded channel extremes not fitting the width",
         (("    recorded: [1035, 2012]", "    recorded: [1035, 12012]"),),
         (("[1035, 12012]", f"channels.yaw.recorded: recorded [1035, 12012] is outside 800..2200 us {RC_HINT}"),
          ("      l:\n        ^name: left\n        description: Turn left",
           "categories.t.directions.l: range 1035..12012 does not fit in 4 digits"),
          ("      r:\n        ^name: right\n        description: Turn right",
           "categories.t.directions.r: range 1035..12012 does not fit in 4 digits"))),
    Case("recorded extremes outside ArduPilot's RC range", (("    recorded: [1000, 2000]\n    movement: Strafe",
                                                             "    recorded: [18, 255]\n    movement: Strafe"),),
         (("[18, 255]", f"channels.roll.recorded: recorded [18, 255] is outside 800..2200 us {RC_HINT}"),)),
    Case("servo range past 180 degrees", (("    description: Vertical servo carrying the camera and the laser\n"
                                            "    range_deg: [0, 180]", "    description: Vertical servo carrying the "
                                            "camera and the laser\n    range_deg: [0, 200]"),),
         (("[0, 200]", "servos.tilt.range_deg: maximum 200 is past 180 degrees (hint: the firmware maps 0..180 degrees "
           "onto the Arduino Servo library's pulses: more would drive the servo past its end)"),)),
    Case("default outside the range", ((PITCH_HIGH,
                                        "        channel: pitch\n        default: 2500"),),
         (("2500", "categories.m.directions.f.default: default 2500 is outside range 1000..2000"),)),
    Case("field default outside the field's range", (("    range: [1, 180]", "    range: [1, 180]\n    default: 200"),),
         (("default: ^200", "fields.angle.default: default 200 is outside range 1..180"),
          *((a, f"categories.s.directions.{d}.default: default 200 is outside range 1..180") for d, a in SERVO_MOVES))),
    Case("minimum above maximum", (("    range: [1, 180]", "    range: [180, 1]"),),
         (("[180, 1]", "fields.angle.range: minimum 180 is greater than maximum 1 (hint: write [min, max])"),
          *((a, f"categories.s.directions.{d}: {NO_RANGE}") for d, a in SERVO_MOVES))),
    Case("negative minimum", (("    range: [1, 180]", "    range: [-1, 180]"),),
         (("[-1, 180]", "fields.angle.range: minimum -1 is negative (hint: values are unsigned decimal digits)"),
          *((a, f"categories.s.directions.{d}: {NO_RANGE}") for d, a in SERVO_MOVES))),
    Case("unknown speed label", ((PITCH_HIGH, "        channel: pitch\n        default: hihg"),),
         (("hihg", "categories.m.directions.f.default: unknown speed 'hihg' (hint: did you mean 'high'?)"),)),
    Case("sense other than 1 or -1", ((SENSE_1, "        servo: tilt\n        sense: 2"),),
         (("sense: ^2", "categories.s.directions.u.sense: sense must be 1 or -1, found 2"),)),
    Case("frame length out of bounds", (("  length: 6", "  length: 9"),),
         (("length: ^9", "frame.length: frame length 9 is not in 3..6 "
           "(hint: a frame is category, direction and 1 to 4 value digits (16-bit values on the Arduino))"),
          ("  speed:\n    width: ^4", "fields.speed.width: width 4 does not fill the frame "
           "(hint: frame.length 9 leaves 7 value digits)"),
          ("  angle:\n    width: ^4", "fields.angle.width: width 4 does not fill the frame "
           "(hint: frame.length 9 leaves 7 value digits)"),
          ("  zero:\n    width: ^4", "fields.zero.width: width 4 does not fill the frame "
           "(hint: frame.length 9 leaves 7 value digits)"))),
    Case("command timeout longer than the failsafe", (("  command_timeout_ms: 500", "  command_timeout_ms: 1500"),),
         (("1500", "safety.command_timeout_ms: command_timeout_ms is longer than failsafe_timeout_ms "
           "(hint: a movement must end before the failsafe fires)"),)),
    # -- names -------------------------------------------------------------------------------------------------
    Case("Python reserved word", (("        name: forward", "        name: class"),),
         (("class", f"categories.m.directions.f.name: 'class' is a reserved word in a target language {IDENT_HINT}"),)),
    Case("Python soft keyword", (("        name: forward", "        name: match"),),
         (("name: ^match",
           f"categories.m.directions.f.name: 'match' is a reserved word in a target language {IDENT_HINT}"),)),
    Case("C++ reserved word", (("        name: forward", "        name: delete"),),
         (("delete",
           f"categories.m.directions.f.name: 'delete' is a reserved word in a target language {IDENT_HINT}"),)),
    Case("Arduino macro", (("    name: servo\n", "    name: constrain\n"),),
         (("constrain", f"categories.s.name: 'constrain' is a reserved word in a target language {IDENT_HINT}"),)),
    Case("Python keyword as a parameter name", (("    parameter: degrees", "    parameter: lambda"),),
         (("lambda", f"fields.angle.parameter: 'lambda' is a Python keyword {IDENT_HINT}"),)),
    Case("not an identifier", (("        name: forward", "        name: Forward-Fast"),),
         (("Forward-Fast", "categories.m.directions.f.name: 'Forward-Fast' is not a lower_snake_case identifier "
           f"(letters, digits, single underscores) {IDENT_HINT}"),)),
    Case("double underscore", (("        name: forward", "        name: for__ward"),),
         (("for__ward", "categories.m.directions.f.name: 'for__ward' is not a lower_snake_case identifier "
           f"(letters, digits, single underscores) {IDENT_HINT}"),)),
    Case("clashing command names", (("        name: backward", "        name: forward"),),
         (("      b:\n        ^name: forward", "categories.m.directions.b: command name 'move_forward' is already used "
           "by mf (hint: rename the direction)"),)),
    Case("command prefix making commands clash",
         (("    field: speed\n    directions:\n      l:\n        name: left\n        description: Turn left",
           "    field: speed\n    command_prefix: move_\n    directions:\n      l:\n        name: left\n"
           "        description: Turn left"),),
         (("      l:\n        ^name: left\n        description: Turn left",
           "categories.t.directions.l: command name 'move_left' is already used by ml (hint: rename the direction)"),
          ("      r:\n        ^name: right\n        description: Turn right",
           "categories.t.directions.r: command name 'move_right' is already used by mr (hint: rename the direction)"))),
    Case("category name equal to a command name", (("    name: laser\n", "    name: arm\n"),),
         (("  l:\n    name: ^arm", "categories.l.name: name 'arm' is already used "
           "(hint: category and command names must all differ)"),)),
    # -- text that would break out of generated code -----------------------------------------------------------
    Case("text with a backslash", ((STRAFE, "        description: Strafe \\\\ left"),),
         (("Strafe \\\\ left", "categories.m.directions.l.description: text contains '\\\\', which could break out "
           f"of a comment or string in generated code {TEXT_HINT}"),)),
    Case("text with a triple quote", ((STRAFE, "        description: 'Strafe \"\"\" left'"),),
         (("'Strafe", "categories.m.directions.l.description: text contains '\"\"\"', which could break out of a "
           f"comment or string in generated code {TEXT_HINT}"),)),
    Case("text with a trigraph", ((STRAFE, "        description: Strafe left??/"),),
         (("Strafe left??/", "categories.m.directions.l.description: text contains '??', which could break out of "
           f"a comment or string in generated code {TEXT_HINT}"),)),
    Case("text that ends a block comment", ((STRAFE, "        description: Strafe left */ int x;"),),
         (("Strafe left */", "categories.m.directions.l.description: text contains '*/', which could break out of a "
           f"comment or string in generated code {TEXT_HINT}"),)),
    Case("text that opens a block comment", ((STRAFE, "        description: Strafe /* left"),),
         (("Strafe /*", "categories.m.directions.l.description: text contains '/*', which could break out of a "
           f"comment or string in generated code {TEXT_HINT}"),)),
    Case("text with a control character", ((STRAFE, '        description: "Strafe\\x01left"'),),
         (('"Strafe', "categories.m.directions.l.description: text contains '\\x01', which could break out of a "
           f"comment or string in generated code {TEXT_HINT}"),)),
    # -- the link: the firmware's UART and the pilot's port run 8N1 only ----------------------------------------
    Case("seven data bits", (("  data_bits: 8", "  data_bits: 7"),),
         (("7\n  parity", f"link.data_bits: data_bits 7 {LINK_8N1} (hint: write 8 (8N1))"),)),
    Case("even parity", (("  parity: none", "  parity: even"),),
         (("even\n  stop_bits", f"link.parity: parity even {LINK_8N1} (hint: write none (8N1))"),)),
    Case("two stop bits", (("  stop_bits: 1", "  stop_bits: 2"),),
         (("2\n  # Opening", f"link.stop_bits: stop_bits 2 {LINK_8N1} (hint: write 1 (8N1))"),)),
    # -- YAML itself -------------------------------------------------------------------------------------------
    Case("YAML syntax error", ((STRAFE, "        description: [Strafe left"),),
         (("[Strafe left\n        channel^:", "YAML syntax error: expected ',' or ']', but got ':'"),)),
    Case("tab indentation", ((STRAFE, "\tdescription: Strafe left"),),
         (("\tdescription", "YAML syntax error: found character '\\t' that cannot start any token"),)),
    Case("empty spec", (), (("", "the spec is empty"),), text=""),
    Case("category that is not a mapping", (("  l:\n    name: laser", "  l: laser\n  x:\n    name: laser"),),
         (("  l: ^laser", "categories.l: expected a mapping, found text"),)),
    # -- wrong types -------------------------------------------------------------------------------------------
    Case("list instead of a range", (("    range: [1, 180]", "    range: 180"),),
         (("range: ^180", "fields.angle.range: expected [min, max] as two integers, found 180"),
          *((a, f"categories.s.directions.{d}: {NO_RANGE}") for d, a in SERVO_MOVES))),
    # -- unknown references ------------------------------------------------------------------------------------
    Case("unknown channel", ((ROLL_LOW, "        channel: rol\n        default: low"),),
         (("rol\n", "categories.m.directions.l.channel: unknown channel 'rol' (hint: did you mean 'roll'?)"),)),
    Case("unknown servo", ((SENSE_1, "        servo: tlt\n        sense: 1"),),
         (("tlt", "categories.s.directions.u.servo: unknown servo 'tlt' (hint: did you mean 'tilt'?)"),)),
    Case("unknown field of a category", (("    field: angle", "    field: angel"),),
         (("angel", "categories.s.field: unknown field 'angel' (hint: did you mean 'angle'?)"),)),
    Case("unknown field of a direction",
         (("        servo: both\n        field: zero", "        servo: both\n        field: zeros"),),
         (("zeros", "categories.s.directions.x.field: unknown field 'zeros' (hint: did you mean 'zero'?)"),)),
    Case("a channel and a servo", ((SENSE_1, "        servo: tilt\n        channel: yaw\n        sense: 1"),),
         (("      u:\n        ^name: up\n        description: Up\n",
           "categories.s.directions.u: a direction drives a channel or a servo, not both"),)),
    # -- several errors at once, in several sections, sorted by position ---------------------------------------
    Case("several errors reported at once",
         (("        name: forward", "        name: class"), ("  stop_bits: 1", "  stop_bit: 1"),
          (SENSE_1, "        servo: tilt\n        sense: 2"),
          (ROLL_LOW, "        channel: roll\n        default: lo")),
         (("stop_bit: 1", "link.stop_bit: unknown key 'stop_bit' (hint: did you mean 'stop_bits'?)"),
          ("class", f"categories.m.directions.f.name: 'class' is a reserved word in a target language {IDENT_HINT}"),
          ("default: ^lo\n", "categories.m.directions.l.default: unknown speed 'lo' (hint: did you mean 'low'?)"),
          ("sense: ^2", "categories.s.directions.u.sense: sense must be 1 or -1, found 2"))),
]

# One mistake, one error: these cases also report false consequences today (generator bugs, see the report).
CASCADES = [
    Case("wrong type: text for an integer", (("  inter_byte_timeout_ms: 20", "  inter_byte_timeout_ms: twenty"),),
         (("twenty", "frame.inter_byte_timeout_ms: expected an integer, found text 'twenty'"),)),
    Case("wrong type: boolean for an integer", (("  baud: 115200", "  baud: true"),),
         (("baud: ^true", "link.baud: expected an integer, found a boolean True"),)),
    Case("wrong type: integer for a name", (("    name: turn\n", "    name: 5\n"),),
         (("  t:\n    name: ^5", "categories.t.name: expected text, found an integer 5"),)),
    Case("python tag on a scalar is refused, not constructed",
         (("  title: Quadrotor drone protocol (Raspberry Pi to Arduino)",
           "  title: !!python/object/apply:os.system echo"),),
         (("!!python", "protocol.title: unsupported YAML tag tag:yaml.org,2002:python/object/apply:os.system"),)),
    Case("python tag on a list is refused, not ignored",
         (("  title: Quadrotor drone protocol (Raspberry Pi to Arduino)",
           "  title: !!python/object/apply:os.system [echo]"),),
         (("!!python", "protocol.title: unsupported YAML tag tag:yaml.org,2002:python/object/apply:os.system"),)),
    Case("missing section", (("speeds:\n  step_us: 100\n", ""),),
         (("protocol:\n  name: drone_protocol", "speeds: missing key 'speeds'"),)),
    Case("error in the laser's only direction",
         (("        name: toggle\n", "        name: toggle\n        default: 5\n"),),
         (("default: ^5", "categories.l.directions.0.default: default 5 is outside range 0..0"),)),
    Case("empty directions",
         (('    directions:\n      "0":\n        name: toggle\n'
           '        description: Toggle the laser (the seed\'s frame)\n'
           '      "n":\n        name: "on"\n        description: Switch the laser on\n'
           '      f:\n        name: "off"\n        description: Switch the laser off\n',
           "    directions: {}\n"),),
         (("{}", "categories.l.directions: must not be empty"),)),
]


def expected_lines(case: Case, spec: Path) -> list[str]:
    text = case.spec()
    lines = []
    for anchor, rest in case.errors:
        where = "1:1" if not text else at(text, anchor)
        lines.append(f"{spec}:{where}: {rest}")
    return lines


def check(case: Case, tmp_path: Path, expected: list[str]) -> None:
    spec = tmp_path / "drone.yaml"
    spec.write_text(case.spec(), encoding="utf-8")
    out = tmp_path / "generated"
    shutil.copytree(h.fixture_generated(), out)
    before = h.tree(out)
    run = h.generate("--spec", spec, "--out", out)
    count = len(expected)
    assert run.stderr.splitlines() == [f"{spec}: {count} error{'s' if count != 1 else ''}; nothing was written",
                                       *expected]
    assert run.code == 2
    assert run.stdout == ""
    assert h.tree(out) == before, "a broken spec changed the existing output folder"
    assert not any(p.name.endswith(".tmp") for p in out.rglob("*")), "staged files left behind"
    fresh = tmp_path / "fresh"
    assert h.generate("--spec", spec, "--out", fresh).code == 2
    assert not fresh.exists(), "a broken spec created the output folder"


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_malformed_spec_is_reported_exactly_and_nothing_is_written(case: Case, tmp_path: Path) -> None:
    check(case, tmp_path, expected_lines(case, tmp_path / "drone.yaml"))


@pytest.mark.parametrize("case", CASCADES, ids=[c.id for c in CASCADES])
def test_one_mistake_gives_one_error_not_false_consequences(case: Case, tmp_path: Path) -> None:
    check(case, tmp_path, expected_lines(case, tmp_path / "drone.yaml"))


def test_there_are_at_least_twenty_malformed_specs() -> None:
    assert len(CASES) + len(CASCADES) >= 20


def test_python_m_generator_exits_2_on_a_broken_spec(tmp_path: Path) -> None:
    spec = tmp_path / "drone.yaml"
    spec.write_text(h.edited_spec(("        name: forward", "        name: class")))
    run = h.generate_subprocess("--spec", spec, "--out", tmp_path / "out")
    assert run.code == 2
    assert f"{spec}:{h.location(spec.read_text(), 'class')}: categories.m.directions.f.name:" in run.stderr
    assert not (tmp_path / "out").exists()


def test_an_unreadable_spec_is_an_error_not_a_traceback(tmp_path: Path) -> None:
    missing = tmp_path / "nope.yaml"
    run = h.generate("--spec", missing, "--out", tmp_path / "out")
    assert run.code == 2
    assert run.stderr.splitlines()[1].startswith(f"{missing}:1:1: cannot read the spec: ")
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\xff\xfe\x00protocol")
    run = h.generate("--spec", binary, "--out", tmp_path / "out")
    assert run.code == 2 and "1:1: the spec is not UTF-8 text (byte 0xff)" in run.stderr
