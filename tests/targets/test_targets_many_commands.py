"""The Rust and TypeScript codecs generated from the spec plus 26 categories x 26 directions (698 commands: more
than a byte can number, the parsers' lookup tables at their largest): the crate builds, and its stream parser and
decode(), and TypeScript's stream parser, agree with Python's on the same bytes."""

from __future__ import annotations

import functools
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

import targets_harness as t
import test_targets_differential as d
import yaml

from generator.cli import main as generate

BUILD = t.ROOT / "build" / "targets" / "26x26"
UPPER, LOWER = "ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz"


@functools.cache
def tree() -> Path:
    spec = yaml.safe_load((t.ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    spec["fields"]["level"] = {"width": 4, "unit": "none", "range": [0, 9999], "parameter": "level",
                               "description": "A level"}
    for c in UPPER:
        spec["categories"][c] = {"name": f"bank_{c.lower()}", "hardware": "none", "description": "A test category",
                                 "field": "level", "directions": {
                                     d: {"name": f"knob_{d}", "description": "A test command"} for d in LOWER}}
    path = BUILD / "drone.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(spec, sort_keys=False), encoding="utf-8")
    shutil.rmtree(BUILD / "generated", ignore_errors=True)
    assert generate(["--spec", str(path), "--out", str(BUILD / "generated")]) == 0
    return BUILD / "generated"


@functools.cache
def rlib() -> Path:
    target = BUILD / "target"
    t.run(["cargo", "build", "--release", "--locked", "--offline", "--quiet"], cwd=tree() / "rust",
          env={"CARGO_TARGET_DIR": str(target)})
    return target / "release" / "libdrone_protocol.rlib"


def rust_program(driver: str) -> Path:
    exe, lib = BUILD / driver, rlib()
    t.run(["rustc", "--edition", "2021", "-O", "--extern", f"drone_protocol={lib}", "-L", str(lib.parent / "deps"),
           str(t.DRIVERS / f"{driver}.rs"), "-o", str(exe)])
    return exe


def synthetic(rng: random.Random) -> bytes:
    """A frame of the added commands, valid or with one byte changed."""
    frame = bytearray(f"{rng.choice(UPPER)}{rng.choice(LOWER)}{rng.randrange(10_000):04d}".encode())
    if rng.random() < 0.3:
        frame[rng.randrange(6)] = rng.choice(b"Aa0!\xff" + bytes(UPPER, "ascii"))
    return bytes(frame)


def stream() -> str:
    """The differential test's bursts (the shipped commands, garbage, pauses), each followed by added frames."""
    rng = random.Random(2611)
    lines = []
    for line in d.stream_lines(29, 20_000).splitlines():
        now, _, data = line.partition(" ")
        lines.append(f"{now} {data}{b''.join(synthetic(rng) for _ in range(rng.randrange(3))).hex()}")
    return "\n".join(lines) + "\n"


def outputs(cmd: list[str], stdin: str) -> list[str]:
    env = {**os.environ, "PYTHONPATH": str(tree() / "python")}
    return subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=120, check=True,
                          env=env).stdout.splitlines()


def test_the_676_command_stream_parsers_agree_with_python() -> None:
    text = stream()
    python = outputs([sys.executable, str(t.DRIVERS / "stream_driver.py")], text)
    assert sum(line.startswith("bank_") for line in python) > 1000, python[-1]
    assert outputs([str(rust_program("stream_driver"))], text) == python
    t.run([str(t.tsc()), "-p", str(tree() / "typescript" / "tsconfig.json")])
    assert outputs(t.typescript_driver_of(tree() / "typescript" / "dist"), text) == python


def test_the_676_command_crate_decodes_as_python_does() -> None:
    rng = random.Random(7)
    frames = "\n".join(synthetic(rng).hex() for _ in range(5000)) + "\n"
    python = outputs([sys.executable, str(t.DRIVERS / "decode_driver.py")], frames)
    assert {line.split()[0] for line in python} == {"ok", "err"}
    assert outputs([str(rust_program("decode_driver"))], frames) == python
