"""Build and run the stream drivers of every generated codec (one shared stdin/stdout format, see drivers/).

Not a conftest.py on purpose (mypy checks `tests` as one tree of top-level modules); tests import this as
`import targets_harness as t`. Everything is built under build/targets/, cached by a hash of its inputs.
"""

from __future__ import annotations

import functools
import hashlib
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ROOT / "generated"
DRIVERS = Path(__file__).resolve().parent / "drivers"
TYPESCRIPT_DRIVER = Path(__file__).resolve().parent / "typescript" / "stream_driver.mjs"
BUILD = ROOT / "build" / "targets"
CARGO_TARGET = ROOT / "build" / "rust" / "target"
CRATE = GENERATED / "rust"
C_DIR = GENERATED / "c"
CPP_DIR = GENERATED / "arduino" / "DroneProtocol" / "src"
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2")
CXXFLAGS = ("-std=c++11", "-Wall", "-Wextra", "-Werror", "-O2")


def _digest(*parts: Path | str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.read_bytes() if isinstance(part, Path) else part.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


def run(cmd: list[str], cwd: Path = ROOT, env: dict[str, str] | None = None, timeout: float = 600) -> str:
    proc = subprocess.run(cmd, cwd=cwd, env={**os.environ, **(env or {})}, capture_output=True, text=True,
                          timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(cmd)} exited {proc.returncode}:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout + proc.stderr


def _cached(name: str, key: str, command: Callable[[Path], list[str]]) -> Path:
    """The executable `name` built by `command(output path)`, unless one with the same inputs exists."""
    BUILD.mkdir(parents=True, exist_ok=True)
    exe = BUILD / f"{name}-{key}"
    if not exe.exists():
        tmp = exe.with_name(f"{exe.name}.{os.getpid()}.tmp")
        run(command(tmp))
        tmp.replace(exe)
    return exe


def c_sources() -> list[Path]:
    return sorted(C_DIR.glob("*.c"))


@functools.cache
def c_driver() -> Path:
    source = DRIVERS / "stream_driver.c"
    key = _digest(source, *sorted(C_DIR.iterdir()), *CFLAGS)
    return _cached("stream_driver_c", key, lambda out: [
        "gcc", *CFLAGS, f"-I{C_DIR}", str(source), *map(str, c_sources()), "-o", str(out)])


@functools.cache
def cpp_driver() -> Path:
    source = DRIVERS / "stream_driver.cpp"
    key = _digest(source, *sorted(CPP_DIR.iterdir()), *CXXFLAGS)
    return _cached("stream_driver_cpp", key, lambda out: [
        "g++", *CXXFLAGS, f"-I{CPP_DIR}", str(source), "-o", str(out)])


def cargo(*args: str, cwd: Path = CRATE) -> str:
    """Run cargo on the generated crate, offline-friendly: --locked (the committed Cargo.lock), target dir in build/."""
    return run(["cargo", *args], cwd=cwd, env={"CARGO_TARGET_DIR": str(CARGO_TARGET)})


@functools.cache
def rust_rlib() -> Path:
    """The crate built in release mode; returns its .rlib."""
    cargo("build", "--release", "--locked", "--offline", "--quiet")
    return CARGO_TARGET / "release" / "libdrone_protocol.rlib"


def rustc_program(source: Path, name: str, extra: tuple[str, ...] = ()) -> Path:
    """A std program compiled with rustc -O against the generated crate (no Cargo.lock of its own to keep in step)."""
    rlib = rust_rlib()
    key = _digest(source, rlib, *extra)
    return _cached(name, key, lambda out: [
        "rustc", "--edition", "2021", "-O", "-C", "codegen-units=1", *extra, "--extern", f"drone_protocol={rlib}",
        "-L", str(rlib.parent / "deps"), str(source), "-o", str(out)])


@functools.cache
def rust_driver() -> Path:
    return rustc_program(DRIVERS / "stream_driver.rs", "stream_driver_rs")


def python_driver() -> list[str]:
    return [sys.executable, str(DRIVERS / "stream_driver.py")]


@functools.cache
def typescript_driver() -> list[str]:
    """The TypeScript package packed as a user gets it (`make typescript`: pinned tsc, build/typescript)."""
    run(["make", "--no-print-directory", "--quiet", "typescript"])
    return typescript_driver_of(ROOT / "build" / "typescript" / "package" / "dist")


def typescript_driver_of(dist: Path) -> list[str]:
    return ["node", str(TYPESCRIPT_DRIVER), str(dist)]


def tsc() -> Path:
    """The repository's pinned TypeScript compiler (installed by `make typescript`)."""
    typescript_driver()
    return TYPESCRIPT_DRIVER.parent / "node_modules" / ".bin" / "tsc"


# Every language's stream driver. Adding a language is one line here.
STREAM_DRIVERS: dict[str, Callable[[], list[str]]] = {
    "python": python_driver,
    "cpp": lambda: [str(cpp_driver())],
    "c": lambda: [str(c_driver())],
    "rust": lambda: [str(rust_driver())],
    "typescript": typescript_driver,
}


def run_stream_driver(language: str, stdin: str) -> list[str]:
    cmd = STREAM_DRIVERS[language]()
    proc = subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, f"{language} driver exited {proc.returncode}: {proc.stderr}"
    return proc.stdout.splitlines()
