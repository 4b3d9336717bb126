"""The Rust and C targets generated from the spec in crc8 integrity mode: their own test suites pass (wire frames
carry the check, a wrong check is bad_check, reply lines end in *XX), and their stream parsers agree with each
other, with Python's and with TypeScript's."""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import drone_protocol as p
import targets_harness as t
import test_targets_differential as d

from generator.cli import main as generate
from generator.model import check_text

BUILD = t.ROOT / "build" / "targets" / "crc8"


@functools.cache
def crc8_tree() -> Path:
    spec = BUILD / "drone.yaml"
    spec.parent.mkdir(parents=True, exist_ok=True)
    text = (t.ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8")
    assert text.count("  integrity: none") == 1, "the test's edit of the spec no longer applies"
    spec.write_text(text.replace("  integrity: none", "  integrity: crc8"), encoding="utf-8")
    shutil.rmtree(BUILD / "generated", ignore_errors=True)  # a fresh codec: no earlier run's contract to rise from
    assert generate(["--spec", str(spec), "--out", str(BUILD / "generated")]) == 0
    return BUILD / "generated"


def c_driver(tree: Path) -> Path:
    out = BUILD / "stream_driver_c"
    t.run(["gcc", *t.CFLAGS, f"-I{tree / 'c'}", str(t.DRIVERS / "stream_driver.c"),
           str(tree / "c" / "drone_protocol.c"), "-o", str(out)])
    return out


def test_the_crc8_crate_passes_rustfmt_its_tests_and_clippy() -> None:
    crate = crc8_tree() / "rust"
    env = {"CARGO_TARGET_DIR": str(BUILD / "target")}
    t.run(["cargo", "fmt", "--check"], cwd=crate)
    t.run(["cargo", "test", "--locked", "--offline", "--quiet"], cwd=crate, env=env)
    t.run(["cargo", "clippy", "--locked", "--offline", "--all-targets", "--quiet", "--", "-D", "warnings"], cwd=crate,
          env=env)
    assert 'pub const INTEGRITY: &str = "crc8";' in (crate / "src" / "lib.rs").read_text()


def test_the_crc8_c_codec_passes_its_tests() -> None:
    tree = crc8_tree()
    exe = BUILD / "test_c_codec"
    t.run(["gcc", *t.CFLAGS, "-fsanitize=address,undefined", f"-I{tree / 'c'}",
           str(Path(t.__file__).parent / "c" / "test_c_codec.c"), str(tree / "c" / "drone_protocol.c"), "-o", str(exe)])
    assert "agree" in t.run([str(exe), str(tree / "vectors.json")])


def crc8_stream() -> str:
    """The shared stream, with a check after each 6-byte piece of every burst of a multiple of 6 bytes (most of
    them valid commands); one check in ten is wrong."""
    lines = []
    for i, line in enumerate(d.stream_lines(77, 40_000).splitlines()):
        now, _, data = line.partition(" ")
        raw = bytes.fromhex(data)
        if raw and len(raw) % 6 == 0:
            pieces = [raw[k:k + 6] for k in range(0, len(raw), 6)]
            raw = b"".join(p + (check_text(p).encode() if i % 10 else b"00") for p in pieces)
        lines.append(f"{now} {raw.hex()}")
    return "\n".join(lines) + "\n"


@functools.cache
def crc8_outputs(language: str) -> list[str]:
    tree = crc8_tree()
    if language == "python":
        env = {**os.environ, "PYTHONPATH": str(tree / "python")}
        proc = subprocess.run(t.python_driver(), input=crc8_stream(), capture_output=True, text=True, timeout=120,
                              check=True, env=env)
        return proc.stdout.splitlines()
    if language == "c":
        return _run(c_driver(tree), crc8_stream())
    if language == "typescript":
        t.run([str(t.tsc()), "-p", str(tree / "typescript" / "tsconfig.json")])
        return _run_cmd(t.typescript_driver_of(tree / "typescript" / "dist"), crc8_stream())
    t.run(["cargo", "build", "--release", "--locked", "--offline", "--quiet"], cwd=tree / "rust",
          env={"CARGO_TARGET_DIR": str(BUILD / "target")})
    rlib = BUILD / "target" / "release" / "libdrone_protocol.rlib"
    rust = BUILD / "stream_driver_rs"
    t.run(["rustc", "--edition", "2021", "-O", "--extern", f"drone_protocol={rlib}", "-L", str(rlib.parent / "deps"),
           str(t.DRIVERS / "stream_driver.rs"), "-o", str(rust)])
    return _run(rust, crc8_stream())


def test_the_crc8_rust_and_c_stream_parsers_agree_on_checked_frames_and_garbage() -> None:
    assert crc8_outputs("rust") == crc8_outputs("c")
    errors = d.errors_of(crc8_outputs("c")[-1])
    assert errors["bad_check"] > 100 and errors["out_of_range"] > 100 and len(crc8_outputs("c")) > 1000, errors


def test_the_crc8_python_and_typescript_stream_decoders_agree_with_rust_and_c() -> None:
    assert crc8_outputs("python") == crc8_outputs("c")
    assert crc8_outputs("typescript") == crc8_outputs("c")


def _run(exe: Path, stdin: str) -> list[str]:
    return _run_cmd([str(exe)], stdin)


def _run_cmd(cmd: list[str], stdin: str) -> list[str]:
    proc = subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=120, check=True)
    return proc.stdout.splitlines()


def crc8_reply_lines() -> tuple[list[bytes], int]:
    """Every reply line a crc8 drone writes (ready, accepted per command, rejected per error, failsafe per state)
    and a few malformed ones, each also with a wrong check, without its check, with a lower-case check and with
    the check of another line; and how many of them carry their right check."""
    states = list(p.DroneState)
    bodies = [p.ready_line().rstrip(b"\n").replace(b" none", b" crc8")]
    commands = [p.decode(p.encode(s.category, s.direction, s.minimum)) for s in p.COMMANDS.values()]
    bodies += [p.accepted_line(c, states[i % len(states)], i % 2 == 1).rstrip(b"\n") for i, c in enumerate(commands)]
    bodies += [p.rejected_line(k, states[i % len(states)], False).rstrip(b"\n") for i, k in enumerate(p.ErrorKind)]
    bodies += [p.failsafe_line(s, True).rstrip(b"\n") for s in states] + [b"A?? d0", b"Ez d0", b"#READY", b"hello"]
    lines, good = [], 0
    for body in bodies:
        check = check_text(body)
        for tail in (check, f"{(int(check, 16) + 1) % 256:02X}", check.lower(), check_text(body + b"!")):
            lines.append(body + b"*" + tail.encode() + b"\n")
            good += tail == check
        lines.append(body + b"\r\n")
    return lines, good


def test_the_crc8_cpp_reply_parser_reads_lines_as_c_and_python_do() -> None:
    tree, (lines, good) = crc8_tree(), crc8_reply_lines()
    stdin = "".join(line.hex() + "\n" for line in lines)
    c, cpp = BUILD / "reply_driver_c", BUILD / "reply_driver_cpp"
    t.run(["gcc", *t.CFLAGS, f"-I{tree / 'c'}", str(t.DRIVERS / "reply_driver.c"), str(tree / "c" / "drone_protocol.c"),
           "-o", str(c)])
    t.run(["g++", *t.CXXFLAGS, f"-I{tree / 'arduino' / 'DroneProtocol' / 'src'}", str(t.DRIVERS / "reply_driver.cpp"),
           "-o", str(cpp)])
    python = subprocess.run([sys.executable, str(t.DRIVERS / "reply_driver.py")], input=stdin, capture_output=True,
                            text=True, timeout=120, check=True, env={**os.environ, "PYTHONPATH": str(tree / "python")})
    got = _run(cpp, stdin)
    assert got == _run(c, stdin) == python.stdout.splitlines()
    counts = Counter(r.split()[0] for r in got)
    assert counts["bad_check"] == len(lines) - good and good > 0, counts
    firsts = [r.split()[0] for r in got[::5]]  # each body with its right check: the drone's own lines pass
    assert firsts[:-4] == ["ready"] + ["ok"] * (len(firsts) - 5) and "ok" not in firsts[-4:], firsts
