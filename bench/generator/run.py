"""Generator benchmarks (issue 8, "Measure"): every figure a median of process runs, against `python -c pass`.

    python bench/generator/run.py [--runs N] [--results FILE | --no-write]

  shipped      `python -m generator --spec spec/drone.yaml --out DIR` (goal <= 0.5 s), with the compiled
               templates cached (every run after the first) and without (DRONE_PROTOCOL_GEN_NO_CACHE=1)
  676          the same for the shipped spec plus 26 categories x 26 directions (goal <= 3 s)
  laughs       rejecting an 11 kB billion-laughs spec (goal <= 1 s)
  hostile      rejecting a 10,000-deep nesting and a 20 MB scalar (goal <= 2 s each)
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[2]


LAUGHS = "lol0: &a0 [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"lol{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]\n" for i in range(1, 10))


def synthetic_676() -> str:
    """26 categories (A..Z) x 26 directions (a..z), each a 0..9999 value: 676 commands."""
    spec: dict[str, Any] = yaml.safe_load((ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    spec["fields"]["level"] = {"width": 4, "unit": "none", "range": [0, 9999], "parameter": "level",
                               "description": "A level"}
    letters = "abcdefghijklmnopqrstuvwxyz"
    for c in letters:
        spec["categories"][c.upper()] = {
            "name": f"group_{c}", "hardware": "none", "description": "A synthetic category", "field": "level",
            "directions": {d: {"name": f"op_{d}", "description": "A synthetic command"} for d in letters}}
    return yaml.safe_dump(spec, sort_keys=False, allow_unicode=True)


def median_seconds(args: list[str], runs: int, expect: int, env: dict[str, str] | None = None) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        proc = subprocess.run(args, cwd=ROOT, capture_output=True, check=False,
                              env=None if env is None else {**os.environ, **env})
        times.append(time.perf_counter() - t0)
        if proc.returncode != expect:
            raise RuntimeError(f"{args} exited {proc.returncode}, not {expect}: {proc.stderr.decode()[-500:]}")
    return statistics.median(times)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--results", type=Path, default=Path(__file__).with_name("RESULTS.md"))
    parser.add_argument("--no-write", action="store_true")
    opts = parser.parse_args()
    py, runs = sys.executable, opts.runs
    rows: list[tuple[str, str, str, str, str]] = []
    with tempfile.TemporaryDirectory(prefix="bench_generator_") as tmp:
        root = Path(tmp)
        floor = median_seconds([py, "-c", "pass"], runs, 0)

        def row(what: str, seconds: float, goal: float) -> None:
            rows.append((what, f"{seconds * 1000:.0f} ms", f"{seconds / floor:.1f}x", f"<= {goal:g} s",
                         "met" if seconds <= goal else "MISSED"))

        shipped = median_seconds([py, "-m", "generator", "--out", str(root / "out")], runs, 0)
        row("generate the shipped spec (process, templates cached)", shipped, 0.5)
        cold = median_seconds([py, "-m", "generator", "--out", str(root / "cold")], runs, 0,
                              {"DRONE_PROTOCOL_GEN_NO_CACHE": "1"})
        row("generate the shipped spec (process, no template cache)", cold, 0.5)
        big = root / "big.yaml"
        big.write_text(synthetic_676(), encoding="utf-8")
        row("shipped + 676 synthetic commands (process, templates cached)",
            median_seconds([py, "-m", "generator", "--spec", str(big), "--out", str(root / "big")], runs, 0), 3.0)
        for name, data in (("billion laughs (11 kB)", LAUGHS.encode()),
                           ("10,000-deep nesting", b"a: " + b"[" * 10_000 + b"]" * 10_000 + b"\n"),
                           ("a 20 MB scalar", b"a: " + b"x" * 20_000_000 + b"\n")):
            path = root / "hostile.yaml"
            path.write_bytes(data)
            seconds = median_seconds([py, "-m", "generator", "--spec", str(path), "--out", str(root / "h")], runs, 2)
            row(f"reject {name} (process)", seconds, 1.0 if "laughs" in name else 2.0)
    width = max(len(r[0]) for r in rows)
    lines = [f"| {'measure':{width}} | median | vs python -c pass | goal | |", f"|{'-' * (width + 2)}|---|---|---|---|"]
    lines += [f"| {r[0]:{width}} | {r[1]} | {r[2]} | {r[3]} | {r[4]} |" for r in rows]
    table = "\n".join(lines)
    print(table)
    print(f"python -c pass: {floor * 1000:.0f} ms (median of {runs})")
    if not opts.no_write:
        opts.results.write_text(
            "# Generator benchmarks\n\n`python bench/generator/run.py` (`make bench-generator`); medians of "
            f"{runs} runs each.\n\n{table}\n\n`python -c pass`: {floor * 1000:.0f} ms. Machine: {platform.machine()}, "
            f"Python {platform.python_version()}, {platform.system()}; shared with other jobs (2 cores).\n",
            encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
