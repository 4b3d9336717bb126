"""The ready line's one rule (spec replies.ready), the same in every language: the shared vectors of
vectors.json, and every combination of odd gaps around the prefix and the fields, through each language's reply
driver (drivers/reply_driver.*), which must give identical answers; the C++ library's own line must be the one
the rule reads."""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
from collections import Counter

import drone_protocol as p
import targets_harness as t

from generator.model import check_text

# Every byte one language or another treats as whitespace, and the empty gap.
GAPS = ("", " ", "  ", "\t", "\v", "\f", "\x1c", "\x85", "\xa0")


def reply_drivers() -> dict[str, list[str]]:
    c = t.BUILD / "reply_driver_c"
    t.BUILD.mkdir(parents=True, exist_ok=True)
    t.run(["gcc", *t.CFLAGS, f"-I{t.C_DIR}", str(t.DRIVERS / "reply_driver.c"), *map(str, t.c_sources()), "-o", str(c)])
    cpp = t.BUILD / "reply_driver_cpp"
    t.run(["g++", *t.CXXFLAGS, f"-I{t.CPP_DIR}", str(t.DRIVERS / "reply_driver.cpp"), "-o", str(cpp)])
    dist = t.ROOT / "build" / "typescript" / "package" / "dist"
    t.typescript_driver()  # builds the package
    return {"python": [sys.executable, str(t.DRIVERS / "reply_driver.py")], "c": [str(c)], "cpp": [str(cpp)],
            "rust": [str(t.rustc_program(t.DRIVERS / "reply_driver.rs", "reply_driver_rs"))],
            "typescript": ["node", str(t.TYPESCRIPT_DRIVER.parent / "reply_driver.mjs"), str(dist)]}


def run_all(lines: list[bytes]) -> dict[str, list[str]]:
    stdin = "".join(line.hex() + "\n" for line in lines)
    out = {}
    for language, cmd in reply_drivers().items():
        proc = subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=300, check=True)
        out[language] = proc.stdout.splitlines()
        assert len(out[language]) == len(lines), f"{language}: {proc.stderr}"
    return out


def on_wire(body: bytes) -> bytes:
    check = b"*" + check_text(body).encode() if p.CHECK_LENGTH else b""
    return body + check + b"\n"


def gap_variants() -> list[bytes]:
    """The ready line with each of its five gaps (before the prefix, before each field, after the last) replaced
    by every gap of GAPS: 9^5 lines, one of them the firmware's own."""
    prefix = p.ReplyKind.READY.value.encode()
    fields = [w.encode() for w in (p.PROTOCOL_NAME, p.SPEC_FINGERPRINT, p.INTEGRITY)]
    out = []
    for lead, *inner, trail in itertools.product([g.encode("latin-1") for g in GAPS], repeat=5):
        out.append(on_wire(lead + prefix + b"".join(g + f for g, f in zip(inner, fields, strict=True)) + trail))
    return out


def test_every_language_reads_the_shared_ready_vectors_as_the_rule_says() -> None:
    vectors = json.loads((t.GENERATED / "vectors.json").read_text())["ready_lines"]
    lines = [bytes.fromhex(v["ready_hex"]) for v in vectors]
    want = [f"ready {v['protocol']} {v['fingerprint']} {v['integrity']}" if v["kind"] == "ready"
            else f"malformed {p.ReplyKind.READY.value}" if v["kind"] == "malformed" else v["kind"] for v in vectors]
    for language, got in run_all(lines).items():
        differ = [(v["note"], g, w) for v, g, w in zip(vectors, got, want, strict=True) if g != w]
        assert differ == [], f"{language}: {len(differ)} of {len(vectors)} differ from the rule, e.g. {differ[:5]}"
    assert Counter(v["kind"] for v in vectors)["ready"] >= 5


def test_every_language_accepts_the_same_odd_gap_variants() -> None:
    lines = gap_variants()
    outputs = run_all(lines)
    accepted = {language: {i for i, r in enumerate(got) if r.startswith("ready ")} for language, got in outputs.items()}
    own = lines.index(p.ready_line())
    for language, got in outputs.items():
        differ = [(lines[i], a, b) for i, (a, b) in enumerate(zip(got, outputs["python"], strict=True)) if a != b]
        assert differ == [], f"{language}: {len(differ)} of {len(lines)} differ from python, e.g. {differ[:5]}"
        # one space in each inner gap, nothing before the prefix: the line end's own CR/LF aside, only that passes
        assert accepted[language] == {own}, f"{language} accepts {len(accepted[language])} of {len(lines)}"


def test_the_cpp_library_writes_the_line_the_rule_reads() -> None:
    vectors = json.loads((t.GENERATED / "vectors.json").read_text())["ready_lines"]
    own = next(bytes.fromhex(v["ready_hex"]) for v in vectors if v["note"] == "the firmware's own line")
    source = t.BUILD / "ready_line.cpp"
    source.write_text('#include <DroneProtocol.h>\n#include <cstdio>\nint main() {\n'
                      '  char line[drone_protocol::REPLY_MAX_LENGTH];\n'
                      '  const uint8_t n = drone_protocol::write_ready(line);\n'
                      '  std::fwrite(line, 1, n, stdout);\n  return 0;\n}\n')
    exe = t.BUILD / "ready_line_cpp"
    t.run(["g++", *t.CXXFLAGS, f"-I{t.CPP_DIR}", str(source), "-o", str(exe)])
    written = subprocess.run([str(exe)], capture_output=True, check=True, timeout=30).stdout
    assert written == own == p.ready_line()
