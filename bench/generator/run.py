"""Generator benchmarks (issue 8, "Measure"; issue 54, a cold run): medians of process runs, wall and CPU time
(user + sys of the child), each against `python -c pass` measured in the same rounds.

    python bench/generator/run.py [--runs N] [--parent REV] [--results FILE | --no-write]

  cold         `python -m generator` as on a fresh clone: a copy of generator/ and spec/ with no __pycache__ and
               PYTHONDONTWRITEBYTECODE=1 (every run compiles the generator's modules as the first one does), no
               user cache (goal <= 0.5 s); with --parent, the same for a git revision, interleaved round by round
  warm         the same with the bytecode Python keeps in __pycache__ after a first run
  compiled     every template compiled by Jinja (DRONE_PROTOCOL_GEN_NO_CACHE=1: no precompiled set, no cache)
  676          the shipped spec plus 26 categories x 26 directions (goal <= 3 s)
  laughs       rejecting an 11 kB billion-laughs spec (goal <= 1 s)
  hostile      rejecting a 10,000-deep nesting and a 20 MB scalar (goal <= 2 s each)
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
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


Timed = Callable[[], tuple[float, float]]


def runner(args: list[str], cwd: Path, expect: int, env: dict[str, str] | None = None) -> Timed:
    """A process run, timed: (wall seconds, CPU seconds of the child)."""
    full_env = {**os.environ, **(env or {})}

    def run() -> tuple[float, float]:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(args, cwd=cwd, capture_output=True, check=False, env=full_env)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != expect:
            raise RuntimeError(f"{args} exited {proc.returncode}, not {expect}: {proc.stderr.decode()[-500:]}")
        return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return run


def interleaved(runs: int, measures: dict[str, Timed]) -> dict[str, tuple[float, float]]:
    """Median (wall, CPU) of each measure, the measures taking turns round by round (one load for all)."""
    seen: dict[str, list[tuple[float, float]]] = {name: [] for name in measures}
    for _ in range(runs):
        for name, measure in measures.items():
            seen[name].append(measure())
    return {name: (statistics.median(w for w, _ in got), statistics.median(c for _, c in got))
            for name, got in seen.items()}


def checkout(root: Path, rev: str | None, name: str = "tree") -> Path:
    """generator/ and spec/ as a fresh clone has them (no __pycache__): the working tree's, or a revision's."""
    folder = root / (rev or name)
    folder.mkdir()
    if rev is None:
        for part in ("generator", "spec"):
            shutil.copytree(ROOT / part, folder / part, ignore=shutil.ignore_patterns("__pycache__"))
    else:
        archive = subprocess.run(["git", "archive", rev, "generator", "spec"], cwd=ROOT, capture_output=True,
                                 check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--parent", help="a git revision to time cold in the same rounds (e.g. HEAD~1)")
    parser.add_argument("--results", type=Path, default=Path(__file__).with_name("RESULTS.md"))
    parser.add_argument("--no-write", action="store_true")
    opts = parser.parse_args()
    py, runs = sys.executable, opts.runs
    rows: list[tuple[str, str, str, str, str]] = []
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench_generator_") as tmp:
        root = Path(tmp)
        cold_home = root / "home"  # no user cache: the parent kept its compiled templates in ~/.cache
        cold_home.mkdir()
        cold_env = {"PYTHONDONTWRITEBYTECODE": "1", "HOME": str(cold_home), "XDG_CACHE_HOME": str(cold_home / ".cache")}
        tree = checkout(root, None)
        warm_tree = checkout(root, None, "warm")
        generate = [py, "-m", "generator", "--out", str(root / "out")]
        measures = {"pass": runner([py, "-c", "pass"], ROOT, 0),
                    "cold": runner(generate, tree, 0, cold_env),
                    "warm": runner(generate, warm_tree, 0, {"PYTHONDONTWRITEBYTECODE": ""}),
                    "compiled": runner(generate, tree, 0, {**cold_env, "DRONE_PROTOCOL_GEN_NO_CACHE": "1"})}
        if opts.parent:
            parent = checkout(root, opts.parent)
            measures["parent"] = runner(generate, parent, 0, cold_env)
        measures["warm"]()  # its first run writes the bytecode
        got = interleaved(runs, measures)
        floor_wall, floor_cpu = got["pass"]

        def row(what: str, seconds: tuple[float, float], goal: float | None) -> None:
            wall, cpu = seconds
            verdict = "" if goal is None else ", ".join(
                f"{what} {'met' if seconds <= goal else 'MISSED'}" for what, seconds in (("wall", wall), ("CPU", cpu)))
            rows.append((what, f"{wall * 1000:.0f} ms / {cpu * 1000:.0f} ms",
                         f"{wall / floor_wall:.1f}x / {cpu / max(floor_cpu, 1e-3):.1f}x",
                         "" if goal is None else f"<= {goal:g} s", verdict))

        row("cold: fresh clone, first run (no bytecode, no cache)", got["cold"], 0.5)
        if opts.parent:
            row(f"cold, parent {opts.parent} (its fresh clone's first run)", got["parent"], None)
        row("warm: the generator's bytecode in __pycache__", got["warm"], 0.5)
        row("cold, every template compiled (DRONE_PROTOCOL_GEN_NO_CACHE=1)", got["compiled"], None)
        big = root / "big.yaml"
        big.write_text(synthetic_676(), encoding="utf-8")
        warm_env = {"PYTHONDONTWRITEBYTECODE": ""}  # from the repository, its bytecode kept as usual
        more = {"676": runner([py, "-m", "generator", "--spec", str(big), "--out", str(root / "big")], ROOT, 0,
                              warm_env)}
        for name, data in (("billion laughs (11 kB)", LAUGHS.encode()),
                           ("10,000-deep nesting", b"a: " + b"[" * 10_000 + b"]" * 10_000 + b"\n"),
                           ("a 20 MB scalar", b"a: " + b"x" * 20_000_000 + b"\n")):
            path = root / f"hostile{len(more)}.yaml"
            path.write_bytes(data)
            more[name] = runner([py, "-m", "generator", "--spec", str(path), "--out", str(root / "h")], ROOT, 2,
                                warm_env)
        more["676"]()  # its first run writes the bytecode
        got = interleaved(runs, more)
        row("shipped + 676 synthetic commands (warm)", got["676"], 3.0)
        for name in more:
            if name != "676":
                row(f"reject {name}", got[name], 1.0 if "laughs" in name else 2.0)
    width = max(len(r[0]) for r in rows)
    lines = [f"| {'measure':{width}} | wall / CPU | vs python -c pass | goal | |",
             f"|{'-' * (width + 2)}|---|---|---|---|"]
    lines += [f"| {r[0]:{width}} | {r[1]} | {r[2]} | {r[3]} | {r[4]} |" for r in rows]
    table = "\n".join(lines)
    floor = f"`python -c pass`: {floor_wall * 1000:.0f} ms wall, {floor_cpu * 1000:.0f} ms CPU"
    load = os.getloadavg()[0]
    print(table)
    print(f"{floor} (median of {runs}); load average {load_before:.1f} -> {load:.1f}")
    if not opts.no_write:
        opts.results.write_text(
            "# Generator benchmarks\n\n`python bench/generator/run.py` (`make bench-generator`); medians of "
            f"{runs} runs each, wall and CPU (user + sys), the measures of each table taking turns round by round."
            "\nCold: `python -m generator` in a copy of generator/ and spec/ with no `__pycache__`, "
            "PYTHONDONTWRITEBYTECODE=1 and an empty HOME, as a fresh clone's first run; warm: the same copy with "
            "the bytecode Python keeps after a first run."
            f"\n\n{table}\n\n{floor}; 1-minute load average "
            f"{load_before:.1f} at the start, {load:.1f} at the end. Machine: {platform.machine()}, "
            f"Python {platform.python_version()}, {platform.system()}; shared with other jobs (2 cores).\n",
            encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
