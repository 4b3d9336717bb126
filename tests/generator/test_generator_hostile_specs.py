"""Hostile and extreme specs: each is a located error (file:line:column), exit 2, no traceback, nothing written
(not even an empty folder), well within 2 s. Bytes, YAML bombs, names, and numbers that would not fit the C++
type they become (never silently truncated).

Each case is the frozen fixture spec with one edit (or a whole text); expected locations come from anchors in
the edited text, as in test_generator_malformed_specs.py.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import protocol_harness as h
import pytest
import yaml

from generator.reader import MAX_TEXT
from generator.source import MAX_BYTES, MAX_DEPTH

LIMIT_S = 2.0  # the bound the issue sets; the cases take a few to a few hundred milliseconds of CPU
TITLE = "  title: Quadrotor drone protocol (Raspberry Pi to Arduino)"
NAME = "  name: drone_protocol"
LAUGHS = "lol0: &a0 [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"lol{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]\n" for i in range(1, 10))


@dataclass(frozen=True)
class Hostile:
    id: str
    data: Callable[[], bytes]
    # (anchor, "path: message" start): anchor as in test_generator_malformed_specs ("context^token"); an anchor
    # "L:C" is a literal line and column.
    errors: tuple[tuple[str, str], ...]


def edited(*edits: tuple[str, str]) -> Callable[[], bytes]:
    return lambda: h.edited_spec(*edits).encode("utf-8")


def raw(text: str) -> Callable[[], bytes]:
    return lambda: text.encode("utf-8")


def synthetic(change: Callable[[dict[str, Any]], None]) -> Callable[[], bytes]:
    def build() -> bytes:
        spec: dict[str, Any] = yaml.safe_load(h.spec_text())
        change(spec)
        return yaml.safe_dump(spec, sort_keys=False).encode("utf-8")
    return build


def many_commands(total: int) -> Callable[[dict[str, Any]], None]:
    """Categories of zero-field commands added until the spec has `total` commands."""
    codes = [chr(c) for c in range(0x21, 0x7F) if chr(c) not in "\"\\"]
    def change(spec: dict[str, Any]) -> None:
        count = total - sum(len(c["directions"]) for c in spec["categories"].values())
        for n in range(0, count, len(codes)):
            directions = {code: {"name": f"c{n}_{i}", "description": "A command", "field": "zero"}
                          for i, code in enumerate(codes[:count - n])}
            spec["categories"][f"{'ABCDEFG'[n // len(codes)]}"] = {
                "name": f"bulk{n}", "hardware": "none", "description": "Many", "command_prefix": "",
                "directions": directions}
    return change


def where(text: str, anchor: str) -> str:
    if re.fullmatch(r"\d+:\d+", anchor):
        return anchor
    context, _, token = anchor.rpartition("^")
    start = text.index(context + token) + len(context)
    assert text.count(context + token) == 1, anchor
    return f"{text.count(chr(10), 0, start) + 1}:{start - (text.rfind(chr(10), 0, start) + 1) + 1}"


FITS = "(hint: the generated C++ would hold another number)"

CASES = [
    # -- bytes -------------------------------------------------------------------------------------------------
    Hostile("larger than the cap", lambda: h.spec_text().encode() + b"#" * MAX_BYTES,
            (("1:1", f"the spec is larger than {MAX_BYTES} bytes"),)),
    Hostile("a 20 MB scalar", lambda: b"protocol:\n  title: " + b"x" * 20_000_000 + b"\n",
            (("1:1", f"the spec is larger than {MAX_BYTES} bytes"),)),
    Hostile("NUL byte in a value", edited((TITLE, "  title: Quad\0rotor")),
            (("title: Quad^", "the spec contains a NUL"),)),
    Hostile("NUL byte in a comment", lambda: b"# \0\n" + h.spec_text().encode(), (("1:3", "the spec contains a NUL"),)),
    Hostile("latin-1 byte", lambda: h.edited_spec((TITLE, "  title: Quadrotor\xe9")).encode("latin-1", "replace"),
            (("title: Quadrotor^", "the spec is not UTF-8 text (byte 0xe9)"),)),
    Hostile("UTF-16 file", lambda: h.spec_text().encode("utf-16"),
            (("1:1", "the spec is not UTF-8 text (byte 0xff)"),)),
    Hostile("truncated UTF-8 sequence", lambda: h.spec_text().encode() + b"\xe2\x82",
            (("anchor-at-end", "the spec is not UTF-8 text (byte 0xe2)"),)),
    Hostile("control character", edited((TITLE, '  title: "Quad\\arotor"')),
            (("\n  title: ^", "protocol.title: text contains '\\x07'"),)),
    Hostile("raw control character", edited((TITLE, "  title: Quad\x07rotor")),
            (("title: Quad^", "character U+0007 is not allowed in YAML"),)),
    Hostile("bidi override", edited((TITLE, "  title: Quad\u202erotor")),
            (("\n  title: ^", "protocol.title: text contains U+202E, an invisible or control character"),)),
    Hostile("zero-width space", edited((TITLE, "  title: Quad\u200brotor")),
            (("\n  title: ^", "protocol.title: text contains U+200B, an invisible or control character"),)),
    Hostile("line separator", edited((TITLE, '  title: "Quad\\Lrotor"')),
            (("\n  title: ^", "protocol.title: text contains U+2028, an invisible or control character"),)),
    Hostile("zero-width space in a name", edited((NAME, "  name: drone\u200bprotocol")),
            (("protocol:\n  name: ^", "protocol.name: text contains U+200B"),)),
    # -- YAML structure ----------------------------------------------------------------------------------------
    Hostile("billion laughs", raw(LAUGHS), (("lol0: ^&a0", "YAML anchors and aliases are not supported"),)),
    Hostile("billion laughs after a valid spec", lambda: (h.spec_text() + LAUGHS).encode(),
            (("lol0: ^&a0", "YAML anchors and aliases are not supported"),)),
    Hostile("one alias", edited((TITLE, TITLE.replace("title: ", "title: &t ")), (TITLE[9:] + "\n  description: >-",
                                                                  TITLE[9:] + "\n  description: *t\n  x: >-")),
            (("\n  title: ^&t", "YAML anchors and aliases are not supported"),)),
    Hostile("merge key", edited(("speeds:\n  step_us: 100", "speeds:\n  <<: {step_us: 100}")),
            (("  ^<<:", "speeds.<<: unknown key '<<'"),)),
    Hostile("10,000-deep flow nesting", raw("protocol: " + "[" * 10_000 + "]" * 10_000 + "\n"),
            ((f"1:{11 + MAX_DEPTH - 1}", f"the spec nests deeper than {MAX_DEPTH} levels"),)),
    Hostile("deep block nesting", raw("".join(" " * i + f"k{i}:\n" for i in range(60)) + " " * 60 + "v\n"),
            ((f"{MAX_DEPTH + 1}:{MAX_DEPTH + 1}", f"the spec nests deeper than {MAX_DEPTH} levels"),)),
    Hostile("an unsupported tag (set)", edited((TITLE, "  title: !!set {a, b}")),
            (("title: ^!!set", "protocol.title: unsupported YAML tag tag:yaml.org,2002:set"),)),
    Hostile("binary", edited((TITLE, "  title: !!binary aGVsbG8=")),
            (("title: ^!!binary", "protocol.title: unsupported YAML tag tag:yaml.org,2002:binary"),)),
    Hostile("a date for the version", edited(("  version: 1", "  version: 2020-01-01")),
            (("version: ^2020", "protocol.version: unsupported YAML tag tag:yaml.org,2002:timestamp"),)),
    Hostile("a complex key", edited(("speeds:\n  step_us: 100", "speeds:\n  step_us: 100\n  ? [a, b]\n  : 1")),
            (("  ? ^[a, b]", "speeds: a key must be plain text"),)),
    Hostile("a key of 100 characters",
            edited(("speeds:\n  step_us: 100", "speeds:\n  step_us: 100\n  " + "k" * 100 + ": 1")),
            (("  ^kkkk", "speeds: a key of 100 characters is longer than 64"),)),
    Hostile("a list at the top", raw("- protocol\n- frame\n"), (("1:1", "expected a mapping, found a list"),)),
    Hostile("only comments", raw("# nothing here\n"), (("1:1", "the spec is empty"),)),
    Hostile("an integer of 5,000 digits", edited(("  version: 1", "  version: " + "9" * 5000)),
            (("version: ^999", "protocol.version: unreadable value: Exceeds the limit"),)),
    Hostile("infinity for the baud", edited(("  baud: 115200", "  baud: .inf")),
            (("baud: ^.inf", "link.baud: expected an integer, found a number inf"),)),
    Hostile("a float for the version", edited(("  version: 1", "  version: 1.5")),
            (("version: ^1.5", "protocol.version: expected an integer, found a number 1.5"),)),
    Hostile("text of 2,001 characters", edited((TITLE, "  title: " + "x" * (MAX_TEXT + 1))),
            (("title: ^xxx", f"protocol.title: text of {MAX_TEXT + 1} characters is longer than {MAX_TEXT}"),)),
    # -- names -------------------------------------------------------------------------------------------------
    Hostile("a protocol name of 300 characters", edited((NAME, "  name: " + "a" * 300)),
            (("protocol:\n  name: ^", "protocol.name: '" + "a" * 40 + "...' is longer than 40 characters"),)),
    Hostile("a command name of 41 characters", edited(("        name: forward", "        name: " + "f" * 41)),
            (("name: ^fff", "categories.m.directions.f.name: '" + "f" * 40 + "...' is longer than 40"),)),
    *(Hostile(f"protocol name {name!r} shadows a module or library", edited((NAME, f"  name: {name}")),
              (("protocol:\n  name: ^", f"protocol.name: '{name}' would shadow a standard Python module or an Arduino "
                                    "library of that name"),))
      for name in ("os", "json", "typing", "servo", "wire", "std", "pilot")),
    Hostile("protocol name that is no identifier", edited((NAME, "  name: drone-protocol")),
            (("name: ^drone-", "protocol.name: 'drone-protocol' is not a lower_snake_case identifier"),)),
    Hostile("protocol name with a newline and code", edited((NAME, '  name: "x\\n#define static_assert(x)"')),
            (("protocol:\n  name: ^", "protocol.name: 'x #define static_assert(x)' is not a lower_snake_case"),)),
    # -- numbers bounded by their C++ type -----------------------------------------------------------------------
    # Past uint16_t, and so past the flight controller's failsafe band: one mistake, reported once, where it is.
    Hostile("failsafe throttle past uint16_t", edited(("  failsafe_throttle_us: 950", "  failsafe_throttle_us: 66486")),
            (("failsafe_throttle_us: ^66486", "safety.failsafe_throttle_us: no flight-controller FS_THR_VALUE fits "
              "strictly between failsafe_throttle_us 66486 and the throttle minimum 1029"),)),
    Hostile("version past uint16_t", edited(("  version: 1", "  version: 70000")),
            (("version: ^70000", "protocol.version: PROTOCOL_VERSION = 70000 does not fit its C++ type uint16_t"),)),
    Hostile("baud past uint32_t", edited(("  baud: 115200", "  baud: 5000000000")),
            (("baud: ^5000000000", "link.baud: BAUD = 5000000000 does not fit its C++ type uint32_t"),)),
    Hostile("inter-byte timeout past uint16_t",
            edited(("  inter_byte_timeout_ms: 20", "  inter_byte_timeout_ms: 65536")),
            (("inter_byte_timeout_ms: ^65536",
              "frame.inter_byte_timeout_ms: INTER_BYTE_TIMEOUT_MS = 65536 does not fit"),)),
    Hostile("ready timeout past uint16_t", edited(("  ready_timeout_ms: 3000", "  ready_timeout_ms: 100000")),
            (("ready_timeout_ms: ^100000", "link.ready_timeout_ms: READY_TIMEOUT_MS = 100000 does not fit"),)),
    Hostile("arming hold past uint16_t", edited(("  arming_hold_ms: 2000", "  arming_hold_ms: 100000")),
            (("arming_hold_ms: ^100000", "safety.arming_hold_ms: ARMING_HOLD_MS = 100000 does not fit"),)),
    Hostile("landing time past uint16_t", edited(("  landing_ms: 6000", "  landing_ms: 65536")),
            (("landing_ms: ^65536", "safety.landing_ms: LANDING_MS = 65536 does not fit"),)),
    Hostile("flight mode pulse past uint16_t", edited(("  alt_hold_us: 1425", "  alt_hold_us: 99999")),
            (("alt_hold_us: ^99999", "flight_modes.alt_hold_us: MODE_ALT_HOLD_US = 99999 does not fit"),)),
    Hostile("timeouts past uint16_t", edited(("  command_timeout_ms: 500", "  command_timeout_ms: 70000"),
                                             ("  failsafe_timeout_ms: 1000", "  failsafe_timeout_ms: 80000")),
            (("command_timeout_ms: ^70000", "safety.command_timeout_ms: COMMAND_TIMEOUT_MS = 70000 does not fit"),
             ("failsafe_timeout_ms: ^80000", "safety.failsafe_timeout_ms: FAILSAFE_TIMEOUT_MS = 80000 does not fit"))),
    Hostile("servo range past uint8_t", edited(("  pan:\n    description: Horizontal servo carrying the camera and the "
                                                "laser\n    range_deg: [0, 180]", "  pan:\n    description: Horizontal "
                                                "servo carrying the camera and the laser\n    range_deg: [0, 300]")),
            (("  pan:\n    ^description",
              "servos.pan: SERVO_PAN_MAX = 300 does not fit its C++ type uint8_t (0..255)"),)),
    Hostile("a channel no command drives, past uint16_t",
            edited(("channels:\n", "channels:\n  aux:\n    recorded: [1000, 70000]\n    movement: none\n"),
                   ("    mode: 6\n", "    mode: 6\n    aux: 7\n")),  # mode stays input 5 (ArduCopter 3.2)
            (("  aux:\n    recorded: ^[",
              "channels.aux.recorded: AUX_MAX = 70000 does not fit its C++ type uint16_t"),)),
    # 10 ** width was computed before the width was bounded: a spec mutation's width of 2**31 - 1 never finished
    Hostile("a field width of 2**31 - 1", edited(("  speed:\n    width: 4", "  speed:\n    width: 2147483647")),
            (("width: ^2147483647", "fields.speed.width: width 2147483647 is not in 1..4"),)),
    Hostile("a reply prefix that overflows REPLY_MAX_LENGTH",
            edited(('prefix: "#READY"', 'prefix: "#' + "R" * 240 + '"')),
            (("replies:\n  ^ready", "replies: REPLY_MAX_LENGTH = "),)),
]


def located(run_stderr: str, shown: str) -> list[str]:
    lines = run_stderr.splitlines()
    count = len(lines) - 1
    assert lines[0] == f"{shown}: {count} error{'s' if count != 1 else ''}; nothing was written", run_stderr
    for line in lines[1:]:
        assert re.match(rf"{re.escape(shown)}:\d+:\d+: ", line), f"not located: {line!r}"
    return lines[1:]


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_a_hostile_spec_is_a_located_error_and_nothing_is_written(case: Hostile, tmp_path: Path) -> None:
    data = case.data()
    spec = tmp_path / "drone.yaml"
    spec.write_bytes(data)
    out = tmp_path / "out"
    # the generator's own CPU time: a wall clock counts the other processes of a loaded machine (2.26 s at load 17)
    start = time.thread_time()
    run = h.generate("--spec", spec, "--out", out)  # a traceback would raise here and fail the test
    elapsed = time.thread_time() - start
    assert run.code == 2, run.stdout + run.stderr
    lines = located(run.stderr, str(spec))
    text = data.decode("utf-8", "replace")
    for anchor, message in case.errors:
        at = f"{text.count(chr(10)) + 1}:1: " if anchor == "anchor-at-end" else where(text, anchor) + ": "
        assert any(line.startswith(f"{spec}:{at}{message}") for line in lines), (at, message, lines)
    assert not out.exists(), "a rejected spec created the output folder"
    assert elapsed < LIMIT_S, f"{elapsed:.2f} s"


def test_there_are_at_least_sixty_malformed_and_hostile_cases() -> None:
    import test_generator_malformed_specs as malformed

    assert len(CASES) + len(malformed.CASES) + len(malformed.CASCADES) >= 60


def cli(spec: bytes | Path, out: Path) -> subprocess.CompletedProcess[bytes]:
    env = {**os.environ, "PYTHONPATH": str(h.ROOT)}
    return subprocess.run([sys.executable, "-m", "generator", "--spec", spec, "--out", out], cwd=h.ROOT, env=env,
                          capture_output=True, timeout=60)


def test_a_non_utf8_file_name_is_printed_escaped_without_a_traceback(tmp_path: Path) -> None:
    folder = os.fsencode(tmp_path)
    spec = folder + b"/bad\xffname\n.yaml"
    with open(spec, "wb") as fh:
        fh.write(h.edited_spec(("  version: 1", "  version: one")).encode())
    proc = cli(spec, tmp_path / "out")
    stderr = proc.stderr.decode("utf-8")  # strictly UTF-8: the name was escaped, not passed through
    shown = f"{tmp_path}/bad\\xffname\\n.yaml"
    assert proc.returncode == 2 and "Traceback" not in stderr, stderr
    assert located(stderr, shown)[0].endswith("protocol.version: expected an integer, found text 'one'")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("kind", ["directory", "fifo", "missing"])
def test_a_spec_that_is_not_a_file_is_a_located_error_and_never_blocks(kind: str, tmp_path: Path) -> None:
    spec = tmp_path / "drone.yaml"
    if kind == "directory":
        spec.mkdir()
    elif kind == "fifo":
        os.mkfifo(spec)  # opening it for reading would block without O_NONBLOCK
    proc = cli(spec, tmp_path / "out")
    stderr = proc.stderr.decode()
    assert proc.returncode == 2 and "Traceback" not in stderr, stderr
    assert located(stderr, str(spec))[0].startswith(f"{spec}:1:1: cannot read the spec: ")
    assert not (tmp_path / "out").exists()


def test_an_output_folder_that_cannot_be_made_is_one_line_naming_it(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("not a folder")
    out = tmp_path / "file" / "out"
    proc = cli(h.SPEC, out)  # raised NotADirectoryError with a traceback
    stderr = proc.stderr.decode()
    assert proc.returncode == 2 and "Traceback" not in stderr and stderr.count("\n") == 1, stderr
    assert stderr.startswith(f"python -m generator: error: --out {out}: cannot write ")
    assert stderr.rstrip().endswith("no file was written")


HOSTILE_NAMES = ["x --><img src=x onerror=alert(1)><!--.yaml", "a\n#define static_assert(x) x\n.yaml",
                 'q"; import os; "*.yaml', "\u202edrone.yaml", "a'b`c$(d).yaml"]


@pytest.mark.parametrize("name", HOSTILE_NAMES)
def test_the_spec_file_name_never_reaches_generated_code_unescaped(name: str, tmp_path: Path) -> None:
    spec = tmp_path / name
    spec.write_text(h.spec_text(), encoding="utf-8")
    out = tmp_path / "out"
    run = h.generate("--spec", spec, "--out", out)
    assert run.code == 0, run.stderr
    baseline = h.tree(h.fixture_generated())
    for rel, content in h.tree(out).items():
        text = content.decode("utf-8")
        for bad in ("\n#define", "-->", "<img", "*/", "import os", "\u202e", "`c", "$("):
            assert bad not in text or bad in baseline[rel].decode(), (rel, bad)
        # only the do-not-edit header (and docs' own mention of the source) differ from a plain drone.yaml
        assert len(text.splitlines()) == len(baseline[rel].decode().splitlines()), rel
