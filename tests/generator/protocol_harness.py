"""Shared helpers of the generator tests: run the generator, edit the spec inline, build small C++ drivers.

Not a conftest.py on purpose: mypy checks `tests` as one tree of top-level modules, and every test folder's
conftest would be the same module name. Tests import this as `import protocol_harness as h`.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import hashlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from generator.cli import main as generator_main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "spec" / "drone.yaml"  # the live spec: only generic checks and the seed pins read it
# What every spec-edit and malformed-spec test edits: a frozen copy, so a user's edit of the live spec leaves
# them green.
FIXTURE = Path(__file__).resolve().parent / "specs" / "drone.yaml"
GENERATED = ROOT / "generated"
HEADER = GENERATED / "arduino" / "DroneProtocol" / "src" / "DroneProtocol.h"
CPP_DIR = Path(__file__).resolve().parent / "cpp"
BUILD = ROOT / "build" / "tests" / "generator"
CXXFLAGS = ("-std=c++11", "-Wall", "-Wextra", "-Werror", "-O1")


def header_text(include: Path | None = None) -> str:
    """The generated C++ library: DroneProtocol.h and the parts it includes, as one text."""
    folder = include or HEADER.parent
    return "\n".join(p.read_text(encoding="utf-8") for p in sorted(folder.glob("*.h")))


def spec_text() -> str:
    """The text of the frozen fixture spec (never the live one)."""
    return FIXTURE.read_text(encoding="utf-8")


def edit(text: str, old: str, new: str) -> str:
    """`text` with the one occurrence of `old` replaced: a test that edits a line that moved fails loudly."""
    count = text.count(old)
    assert count == 1, f"{old!r} occurs {count} times in the spec; the test's edit needs exactly one"
    return text.replace(old, new)


def edited_spec(*edits: tuple[str, str]) -> str:
    text = spec_text()
    for old, new in edits:
        text = edit(text, old, new)
    return text


def location(text: str, anchor: str) -> str:
    """`line:column` (1-based) where the one occurrence of `anchor` starts in `text`."""
    assert text.count(anchor) == 1, f"anchor {anchor!r} occurs {text.count(anchor)} times"
    offset = text.index(anchor)
    line = text.count("\n", 0, offset) + 1
    column = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return f"{line}:{column}"


@dataclass(frozen=True)
class Run:
    code: int
    stdout: str
    stderr: str


def generate(*args: str | Path) -> Run:
    """Run the generator's CLI in this process (fast); `args` as on the command line."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = generator_main([str(a) for a in args])
        except SystemExit as exc:  # argparse: --help, --version, bad options
            code = exc.code if isinstance(exc.code, int) else 1
    return Run(code, out.getvalue(), err.getvalue())


def generate_subprocess(*args: str | Path, cwd: Path = ROOT) -> Run:
    """Run `python -m generator` as a user does (the exit status is the process's)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "generator", *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=60)
    return Run(proc.returncode, proc.stdout, proc.stderr)


@functools.cache
def fixture_generated() -> Path:
    """The fixture spec generated once per test process into a temporary folder (copy it before changing it)."""
    root = tempfile.mkdtemp(prefix="fixture_generated_")
    atexit.register(shutil.rmtree, root, True)
    out = Path(root) / "generated"
    run = generate("--spec", FIXTURE, "--out", out)
    assert run.code == 0, run.stderr
    return out


def tree(root: Path) -> dict[str, bytes]:
    """Every file under `root` (relative posix path -> bytes)."""
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def compile_cpp(source: Path | str, name: str, include: Path | None = None,
                flags: tuple[str, ...] = CXXFLAGS, compiler: str = "g++") -> Path:
    """Compile one C++ file (a path, or the text of one) against a DroneProtocol.h; return the executable.

    Executables are cached in build/tests/generator/ by a hash of source, header and flags."""
    include = include or HEADER.parent
    text = source.read_text(encoding="utf-8") if isinstance(source, Path) else source
    headers = [h.read_text(encoding="utf-8") for h in sorted(include.glob("*.h"))]  # the header and its parts
    key = hashlib.sha256("\0".join([text, *headers, compiler, *flags]).encode()).hexdigest()[:16]
    BUILD.mkdir(parents=True, exist_ok=True)
    exe = BUILD / f"{name}-{key}"
    if exe.exists():
        return exe
    src = BUILD / f"{name}-{key}.cpp"
    src.write_text(text, encoding="utf-8")
    tmp = exe.with_name(exe.name + f".{os.getpid()}.tmp")
    proc = subprocess.run([compiler, *flags, f"-I{include}", str(src), "-o", str(tmp)], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, f"{compiler} failed on {name}:\n{proc.stderr}"
    tmp.replace(exe)
    return exe


@functools.cache
def protocol_driver() -> Path:
    """The C++ driver of the committed header: `decode` and `stream` modes (see cpp/protocol_driver.cpp)."""
    return compile_cpp(CPP_DIR / "protocol_driver.cpp", "protocol_driver")


def run_driver(mode: str, stdin: str) -> list[str]:
    proc = subprocess.run([str(protocol_driver()), mode], input=stdin, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, f"driver {mode} exited {proc.returncode}: {proc.stderr}"
    return proc.stdout.splitlines()
