"""One API in five languages: every entry of the README's table exists in every generated codec.

API_ENTRIES is the manifest: per entry, per language, a pattern its generated source must hold (`{cmd}` and `{Cmd}`
stand for each command's snake_case and camelCase names, `{err}` for each error's name). The Python entries are
also run, and the C++ and C ones compiled with -Wall -Wextra -Werror and run."""

from __future__ import annotations

import collections
import json
import re
import subprocess
from collections.abc import Callable
from pathlib import Path

import drone_protocol as dp
import protocol_harness as h
import pytest

SOURCES = {
    "python": ("python/drone_protocol", "*.py"),
    "cpp": ("arduino/DroneProtocol/src", "*.h"),
    "c": ("c", "drone_protocol.*"),
    "rust": ("rust/src", "*.rs"),
    "typescript": ("typescript/src", "*.ts"),
}
API_ENTRIES: dict[str, dict[str, str]] = {
    "lookup by name": {
        "python": r"def find_command_by_name\(name: str\)",
        "cpp": r"bool find_command\(const char\* name, CommandId& id\)",
        "c": r"int dp_find_command_by_name\(const char \*name\)",
        "rust": r"pub fn from_name\(name: &str\) -> Option<CommandId>",
        "typescript": r"export const COMMANDS: Readonly<Record<CommandName, CommandSpec>>",
    },
    "lookup by the two code bytes": {
        "python": r"def find_command\(category: str, direction: str\)",
        "cpp": r"bool find_command\(uint8_t category, uint8_t direction, CommandId& id\)",
        "c": r"int dp_find_command\(uint8_t category, uint8_t direction\)",
        "rust": r"pub const fn from_codes\(category: u8, direction: u8\)",
        "typescript": r"export function lookup\(categoryByte: number, directionByte: number\)",
    },
    "one encoder per command": {
        "python": r"def {cmd}\(",
        "cpp": r"inline (Error|void) {cmd}\(",
        "c": r"(dp_error|void) dp_{cmd}\(",
        "rust": r"pub (const )?fn {cmd}\(",
        "typescript": r"export function {Cmd}\(",
    },
    "generic encode": {
        "python": r"def encode\(category",
        "cpp": r"inline Error encode\(CommandId id, uint16_t value",
        "c": r"dp_error dp_encode\(dp_command_id id, uint16_t value",
        "rust": r"pub fn encode\(id: CommandId, value: u16",
        "typescript": r"export function encode\(category: string",
    },
    "decode": {
        "python": r"def decode\(frame",
        "cpp": r"inline Error decode\(const uint8_t\* frame, size_t length",
        "c": r"dp_error dp_decode\(const uint8_t \*frame, size_t length",
        "rust": r"pub fn decode\(bytes: &\[u8\]\)",
        "typescript": r"export function decode\(frame",
    },
    "the command's default": {
        "python": r"    default: int \| None",
        "cpp": r"bool command_default\(CommandId id, uint16_t& value\)",
        "c": r"bool dp_command_default\(dp_command_id id, uint16_t \*value\)",
        "rust": r"pub const fn default_value\(self\) -> Option<u16>",
        "typescript": r"readonly default: number \| null",
    },
    "error names": {
        "python": r'    {ERR} = "{err}"',
        "cpp": r'return "{err}";',
        "c": r'"{err}",',
        "rust": r'Error::{Err} => "{err}"',
        "typescript": r'{err}: Object.freeze\(\{ name: "{err}"',
    },
    "stream parser, integer ms clock": {
        "python": r"def feed_ms\(self, data: BytesLike, now_ms: int\)",
        "cpp": r"bool feed\(uint8_t byte, uint32_t now_ms\)",
        "c": r"bool dp_stream_feed\(dp_stream_parser \*parser, uint8_t byte, uint32_t now_ms",
        "rust": r"pub fn feed\(&mut self, byte: u8, now_ms: u32\)",
        "typescript": r"feed\(byte: number, nowMs: number\)",
    },
    "reply parsing": {
        "python": r"def parse_reply\(line",
        "cpp": r"inline ReplyError parse_reply\(const char\* line, size_t length, Reply& reply\)",
        "c": r"dp_parse_reply\(const char \*line, size_t length",
        "rust": r"pub fn parse_reply\(line: &\[u8\]\)",
        "typescript": r"export function parseReply\(line",
    },
}


def _source(language: str) -> str:
    folder, pattern = SOURCES[language]
    files = sorted((h.GENERATED / folder).glob(pattern))
    assert files, f"no generated {language} source in {folder}"
    return "\n".join(p.read_text(encoding="utf-8") for p in files)


def _camel(name: str, upper: bool = False) -> str:
    words = name.split("_")
    return "".join(w.capitalize() if upper or i else w for i, w in enumerate(words))


def _expand(pattern: str) -> list[str]:
    if "{cmd}" in pattern or "{Cmd}" in pattern:
        return [pattern.replace("{cmd}", c).replace("{Cmd}", _camel(c)) for c in dp.CommandName]
    if "{err}" in pattern:
        return [pattern.replace("{ERR}", e.value.upper()).replace("{Err}", _camel(e.value, True))
                .replace("{err}", e.value) for e in dp.ErrorKind]
    return [pattern]


@pytest.mark.parametrize("entry", sorted(API_ENTRIES))
def test_every_language_has_every_entry(entry: str) -> None:
    languages = API_ENTRIES[entry]
    assert sorted(languages) == sorted(SOURCES), entry
    for language, pattern in languages.items():
        text = _source(language)
        missing = [p for p in _expand(pattern) if not re.search(p, text)]
        assert not missing, f"{entry}: the generated {language} codec lacks {missing}"


def test_the_readme_table_has_a_row_per_entry_and_a_cell_per_language() -> None:
    text = (h.ROOT / "README.md").read_text(encoding="utf-8").split("### One API in five languages", 1)[1]
    text = text.split("\n### ", 1)[0]
    rows = {r[0]: r[1:] for r in (
        [c.strip() for c in line.strip("|").split("|")] for line in text.splitlines() if line.startswith("| "))}
    for entry in API_ENTRIES:
        assert entry in rows, f"the README's table has no row {entry!r}"
        assert len(rows[entry]) == len(SOURCES) and all(rows[entry]), rows[entry]


def test_python_error_kinds_are_named_as_in_the_other_languages() -> None:
    contract = json.loads((h.GENERATED / "contract.json").read_text(encoding="utf-8"))
    text = json.dumps(contract)
    for kind in dp.ErrorKind:
        assert kind.value in text and dp.ErrorKind.from_code(kind.code) is kind
    reply = dp.parse_reply(dp.rejected_line(dp.ErrorKind.AIRBORNE, dp.DroneState.DISARMED, False))
    assert reply.error is dp.ErrorKind.AIRBORNE
    assert dp.rejected_line(dp.ErrorKind.AIRBORNE, dp.DroneState.DISARMED, False).startswith(
        (dp.ReplyKind.REJECTED.value + dp.ErrorKind.AIRBORNE.code).encode())


def test_python_missing_value_is_the_same_error_from_every_entry_point() -> None:
    spec = dp.COMMANDS[dp.CommandName.SERVO_UP]
    errors = []
    calls: list[Callable[[], bytes]] = [lambda: dp.servo_up(), lambda: dp.encode(spec.category, spec.direction),
                                        lambda: dp.command_frame(dp.CommandName.SERVO_UP)]
    for call in calls:
        with pytest.raises(dp.MissingValueError) as caught:
            call()
        errors.append(str(caught.value))
    assert len(set(errors)) == 1 and "servo_up" in errors[0]


def test_python_lookups_find_what_decode_finds() -> None:
    for name, spec in dp.COMMANDS.items():
        assert dp.find_command_by_name(name) is spec
        assert dp.find_command(spec.category.value, spec.direction.value) is spec
    assert dp.find_command_by_name("nothing") is None and dp.find_command("?", "?") is None


def test_python_stream_takes_integer_milliseconds() -> None:
    frame = dp.move_forward()
    start = 10**12  # a large clock: the gap is still counted in whole milliseconds
    decoder = dp.StreamDecoder()
    assert decoder.feed_ms(frame[:3], start) == []
    assert decoder.feed_ms(frame[3:], start + dp.INTER_BYTE_TIMEOUT_MS) == [dp.decode(frame)]
    assert decoder.feed_ms(frame[:3], start + 100) == []
    assert decoder.feed_ms(frame[3:], start + 101 + dp.INTER_BYTE_TIMEOUT_MS) == []
    assert decoder.errors[dp.ErrorKind.TIMEOUT] == 1
    with pytest.raises(TypeError, match="now_ms"):
        decoder.feed_ms(frame, 1.5)  # type: ignore[arg-type]


CPP_PROGRAM = r"""
#include <DroneProtocol.h>
#include <stdio.h>
#include <string.h>
using namespace drone_protocol;
int main() {
  for (uint8_t i = 0; i < COMMAND_COUNT; ++i) {
    const CommandId id = static_cast<CommandId>(i);
    const CommandInfo info = command_info(id);
    CommandId by_name = static_cast<CommandId>(0), by_codes = by_name;
    uint16_t value = 0;
    const bool has = command_default(id, value);
    printf("%s %d %d %d %u\n", command_name(id), find_command(command_name(id), by_name) && by_name == id,
           find_command(info.category, info.direction, by_codes) && by_codes == id, has, has ? value : 0u);
  }
  CommandId id;
  uint8_t a[WIRE_LENGTH], b[WIRE_LENGTH];
  printf("%d %d\n", find_command("no_such_command", id), find_command('?', '?', id));
%ENCODERS%
  return 0;
}
"""


def _cpp_encoders() -> str:
    lines = []
    for name, spec in dp.COMMANDS.items():
        pascal = _camel(name, True)
        if spec.minimum == spec.maximum:
            lines.append(f"  {name}(a); encode(CommandId::{pascal}, {spec.minimum}, b);")
        else:
            lines.append(f"  {name}({spec.maximum}, a); encode(CommandId::{pascal}, {spec.maximum}, b);")
        lines.append(f'  printf("{name} %d\\n", memcmp(a, b, WIRE_LENGTH) == 0);')
        if spec.default is not None and spec.minimum != spec.maximum:
            lines.append(f'  printf("{name} default %d\\n", {name}(a) == Error::None && '
                         f"memcmp(a, {name}({spec.default}, b) == Error::None ? b : a, WIRE_LENGTH) == 0);")
    return "\n".join(lines)


def test_the_cpp_lookups_defaults_and_encoders_agree_with_the_spec() -> None:
    exe = h.compile_cpp(CPP_PROGRAM.replace("%ENCODERS%", _cpp_encoders()), "api_cpp")
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60, check=True).stdout.splitlines()
    expected = [f"{name} 1 1 {int(s.default is not None)} {s.default or 0}" for name, s in dp.COMMANDS.items()]
    assert out[:len(expected)] == expected
    assert out[len(expected)] == "0 0"
    assert out[len(expected) + 1:] and all(line.endswith(" 1") for line in out[len(expected) + 1:])


CPP_REPLY_PROGRAM = r"""
#include <DroneProtocol.h>
#include <stdio.h>
using namespace drone_protocol;
int main() {
  static char hex[512], line[256];
  while (fgets(hex, sizeof hex, stdin) != nullptr) {
    size_t n = 0;
    for (size_t i = 0; hex[i] != '\0' && hex[i] != '\n' && n < sizeof line; i += 2) {
      unsigned byte;
      if (sscanf(hex + i, "%2x", &byte) != 1) return 2;
      line[n++] = static_cast<char>(byte);
    }
    Reply r;
    const ReplyError e = parse_reply(line, n, r);
    if (e == ReplyError::None && r.kind == ReplyKind::Ready) {
      printf("ready %.*s %.*s %.*s\n", static_cast<int>(r.protocol_length), r.protocol,
             static_cast<int>(r.fingerprint_length), r.fingerprint, static_cast<int>(r.integrity_length), r.integrity);
    } else if (e == ReplyError::None) {
      printf("%s %s %s %s %d\n", reply_prefix(r.kind), r.kind == ReplyKind::Accepted ? command_name(r.command) : "-",
             error_name(r.error), state_name(r.state), r.laser);
    } else {
      printf("%s %s\n", reply_error_name(e), e == ReplyError::Malformed ? reply_prefix(r.kind) : "-");
    }
  }
  return 0;
}
"""


def _python_reply(line: bytes) -> str:
    """What the Python codec makes of a line, in the C++ program's words."""
    try:
        r = dp.parse_reply(line)
    except dp.ReplyError as error:  # malformed: a reply of the kind of the line's longest prefix
        kinds = sorted((k for k in dp.ReplyKind if line.startswith(k.value.encode())), key=lambda k: len(k.value))
        assert (error.reason == "unknown") == (not kinds) and error.reason in ("unknown", "malformed"), error
        assert error.prefix == (kinds[-1].value if kinds else None), error
        return f"{error.reason} {error.prefix or '-'}"
    if r.kind is dp.ReplyKind.READY:
        return f"ready {r.protocol} {r.fingerprint} {r.integrity}"
    command = dp.find_command(r.category.value, r.direction) if r.category and r.direction else None
    assert r.state is not None
    return (f"{r.kind.value} {command.name.value if command else '-'} {r.error.value if r.error else 'none'} "
            f"{r.state.name.lower()} {int(bool(r.laser))}")


def _reply_lines() -> list[bytes]:
    """Every line the drone writes, and each with one byte replaced by each of a few others."""
    states = list(dp.DroneState)
    lines = [dp.ready_line()]
    lines += [dp.accepted_line(dp.decode(dp.command_frame(s.name, s.minimum)), states[i % len(states)], i % 2 == 1)
              for i, s in enumerate(dp.COMMANDS.values())]
    lines += [dp.rejected_line(k, states[i % len(states)], i % 2 == 0) for i, k in enumerate(dp.ErrorKind)]
    lines += [dp.failsafe_line(s, i % 2 == 1) for i, s in enumerate(states)]
    changed = [line[:i] + bytes([b]) + line[i + 1:] for line in lines for i in range(len(line) - 1) for b in b" A?0mz"]
    return [*lines, *changed, b"", b"\r\n", b"A", b"!F", b"#READY\n"]


def test_the_cpp_reply_parser_reads_every_line_as_python_does() -> None:
    exe = h.compile_cpp(CPP_REPLY_PROGRAM, "api_cpp_replies")
    lines = _reply_lines()
    stdin = "".join(line.hex() + "\n" for line in lines)
    out = subprocess.run([str(exe)], input=stdin, capture_output=True, text=True, timeout=60, check=True).stdout
    got, want = out.splitlines(), [_python_reply(line) for line in lines]
    differ = [(line, g, w) for line, g, w in zip(lines, got, want, strict=True) if g != w]
    assert differ == [], f"{len(differ)} of {len(lines)} lines differ, e.g. {differ[:5]}"
    outcomes = collections.Counter(w.split()[0] for w in want)
    assert min(outcomes[k] for k in ("ready", "A", "E", "!F", "malformed", "unknown")) > 0, outcomes


C_PROGRAM = r"""
#include "drone_protocol.h"
#include <stdio.h>
int main(void) {
  for (int i = 0; i < DP_COMMAND_COUNT; ++i) {
    uint16_t value = 0;
    const bool has = dp_command_default((dp_command_id)i, &value);
    printf("%s %d %d %u\n", dp_command_name((dp_command_id)i),
           dp_find_command_by_name(dp_command_name((dp_command_id)i)) == i, has, has ? value : 0u);
  }
  printf("%d %d\n", dp_find_command_by_name("no_such_command"), dp_find_command_by_name(NULL));
  return 0;
}
"""


def test_the_c_lookup_by_name_and_defaults_agree_with_the_spec(tmp_path: Path) -> None:
    source = tmp_path / "api.c"
    source.write_text(C_PROGRAM, encoding="utf-8")
    exe = tmp_path / "api"
    c_dir = h.GENERATED / "c"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-I{c_dir}", str(source),
                    str(c_dir / "drone_protocol.c"), "-o", str(exe)], check=True, timeout=120)
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60, check=True).stdout.splitlines()
    expected = [f"{name} 1 {int(s.default is not None)} {s.default or 0}" for name, s in dp.COMMANDS.items()]
    assert out == [*expected, "-1 -1"]


@pytest.mark.parametrize("name", ["find_command", "command_default", "missing_value", "command_min"])
def test_a_command_cannot_take_the_name_of_an_api_entry(name: str, tmp_path: Path) -> None:
    spec = tmp_path / "drone.yaml"
    spec.write_text(h.edited_spec(("        name: first_test", f"        name: {name}")), encoding="utf-8")
    run = h.generate("--spec", spec, "--out", tmp_path / "out")
    assert run.code == 2 and "clashes with a name the generated code defines" in run.stderr, run.stderr
    assert not (tmp_path / "out").exists()
