"""The Rust codec's stream parser and decode() against lean hand-written floors, in instructions (callgrind), on
the shipped spec and on it plus 26 categories x 26 directions (bench/generator/run.py's synthetic_676).

Usage: python bench/rust_c/instructions.py [--no-write]; replaces the instruction section of
bench/rust_c/RESULTS.md. The floors are in bench/rust_c/lean.rs.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
BUILD = ROOT / "build" / "bench" / "rust_c" / "lean"
SECTION = "## Instructions against lean floors"
TABLE_HEAD = ("| spec | measure | codec | floor | ratio | goal | verdict | time ratio |",
              "|---|---|---:|---:|---:|---:|---|---:|")
GOALS = {"stream, clean": 2.0, "stream, 50 % garbage": 4.0, "decode, distinct frames": 2.0}


def run(cmd: list[str], cwd: Path = ROOT, env: dict[str, str] | None = None) -> str:
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env, timeout=1800)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    return proc.stdout


def variant_tree() -> Path:
    """The shipped spec plus 26 x 26 synthetic commands, generated fresh."""
    source = importlib.util.spec_from_file_location("bench_generator_run", ROOT / "bench" / "generator" / "run.py")
    assert source is not None and source.loader is not None
    module = importlib.util.module_from_spec(source)
    source.loader.exec_module(module)
    spec = BUILD / "26x26.yaml"
    spec.write_text(module.synthetic_676(), encoding="utf-8")
    out = BUILD / "26x26"
    shutil.rmtree(out, ignore_errors=True)
    run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out)])
    return out


def build(tree: Path, name: str) -> Path:
    """lean.rs compiled against a copy of the tree's crate (cargo never runs inside generated/)."""
    crate = BUILD / name / "crate"
    shutil.rmtree(crate, ignore_errors=True)
    shutil.copytree(tree / "rust", crate, ignore=shutil.ignore_patterns("target"))
    target = BUILD / name / "target"
    env = {**os.environ, "CARGO_TARGET_DIR": str(target)}
    run(["cargo", "build", "--release", "--locked", "--offline", "--quiet"], cwd=crate, env=env)
    rlib = target / "release" / "libdrone_protocol.rlib"
    exe = BUILD / name / "lean"
    run(["rustc", "--edition", "2021", "-O", "-C", "codegen-units=1", "-g", "--extern", f"drone_protocol={rlib}",
         "-L", str(rlib.parent / "deps"), str(HERE / "lean.rs"), "-o", str(exe)])
    run([str(exe), "write", str(BUILD / name)])
    return exe


def count(exe: Path, mode: str, data: Path) -> tuple[int, str]:
    """Instructions inside the mode's function, and what it printed."""
    function = {"stream": "bench_stream", "decode": "bench_decode"}.get(mode, mode)
    log = exe.parent / f"callgrind.{mode}.{data.stem}"
    out = run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={log}", f"--toggle-collect={function}",
               str(exe), mode, str(data)])
    match = re.search(r"^(?:summary|totals): (\d+)", log.read_text(), re.M)
    if match is None:
        raise SystemExit(f"no instruction count in {log}")
    return int(match.group(1)), out.strip()


def measure(exe: Path) -> list[tuple[str, float, float, float]]:
    """(measure, codec's instructions per unit, floor's, the codec's time over the floor's) of each input."""
    times = {name: float(ours) / float(floor) for name, ours, floor in
             (line.split() for line in run([str(exe), "time", str(exe.parent)]).splitlines())}
    rows = []
    for label, mode, name in (("stream, clean", "stream", "clean"), ("stream, 50 % garbage", "stream", "garbage"),
                              ("decode, distinct frames", "decode", "distinct")):
        data = exe.parent / f"{name}.bin"
        units = data.stat().st_size if mode == "stream" else data.stat().st_size // 6
        ours, ours_out = count(exe, mode, data)
        floor, floor_out = count(exe, f"floor_{mode}", data)
        if ours_out != floor_out:
            raise SystemExit(f"{label}: the codec found {ours_out}, the floor {floor_out}")
        rows.append((label, ours / units, floor / units, times[name]))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    BUILD.mkdir(parents=True, exist_ok=True)
    lines = [SECTION, "",
             "`python bench/rust_c/instructions.py`: callgrind instruction counts of the function under test only,",
             "200000 stream bytes (clean: valid frames of random commands at random values; 50 % garbage: the same",
             "with 6 random bytes after each frame) and every command at up to 64 distinct values, shuffled (decode).",
             "The floors (`lean.rs`) check each byte as it arrives with tables and slide one byte on an invalid one,",
             "with no timeouts, error kinds or counts. Units: per byte (stream) or per frame (decode). The time ratio",
             "(best of 31 alternate runs, native) is information: the goals are on instructions.", "",
             *TABLE_HEAD]
    for spec, tree in (("shipped", ROOT / "generated"), ("26x26", variant_tree())):
        lines += [row(spec, *measured) for measured in measure(build(tree, spec))]
    publish(HERE / "RESULTS.md", lines, not args.no_write)


def row(spec: str, label: str, ours: float, floor: float, time: float) -> str:
    """A line of the table: instructions per unit of the codec and the floor, the verdict, the time ratio."""
    ratio, goal = ours / floor, GOALS[label]
    return (f"| {spec} | {label} | {ours:.1f} | {floor:.1f} | {ratio:.2f}x | ≤{goal:g}x | "
            f"{'met' if ratio <= goal else 'MISSED'} | {time:.2f}x |")


def publish(results: Path, lines: list[str], write: bool) -> None:
    """Print the section and, with `write`, put it in place of the results file's own (added at its end)."""
    text = "\n".join(lines) + "\n"
    print(text)
    if write:
        before = results.read_text(encoding="utf-8").split(SECTION)[0].rstrip("\n")
        results.write_text(f"{before}\n\n{text}", encoding="utf-8")

if __name__ == "__main__":
    main()
