"""The Python codec against its floors in instructions (valgrind callgrind), not seconds.

Times on a shared 2-core machine move by 2x between runs; instruction counts of the same script are the same on
every run, with one hash seed (PYTHONHASHSEED=0: bytes keys hash differently in each interpreter otherwise). Each
measure runs its loop REPS times in a fresh interpreter under callgrind, minus an interpreter that
builds the same inputs and runs nothing: the difference is the loop alone. Ratios compare a subject with its floor
over the same frames. Each measure runs on the shipped spec and on the shipped spec plus 26 categories x 26
directions (bench/generator/run.py's synthetic_676, generated to a temporary folder); with --against REV, the codec
that REV's generator makes of both specs is measured in the same run. Writes bench/protocol/PYTHON_INSTRUCTIONS.md.

    python -m bench.protocol.python_instructions [--against REV] [--no-write]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from bench.generator.run import synthetic_676

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
REPS = 5
FRAMES = 1000

WORKLOAD = r'''
import random, sys
import drone_protocol as dp
rng = random.Random(1)
specs = list(dp.COMMANDS.values())
frames = [dp.encode(s.category, s.direction, rng.randint(s.minimum, s.maximum))
          for s in (rng.choice(specs) for _ in range(FRAMES))]
other = random.Random(2)  # its own draws: the other inputs stay those of the runs before it
distinct = list(dict.fromkeys(dp.encode(s.category, s.direction, other.randint(s.minimum, s.maximum))
                              for s in (other.choice(specs) for _ in range(50 * FRAMES))))[:FRAMES]
assert len(distinct) == FRAMES, "the spec has too few distinct frames"
stream = b"".join(frames)
garbage = b"".join(bytes(rng.randrange(256) for _ in range(len(f))) + f for f in frames)
single = [stream[i:i + 1] for i in range(len(stream))]
chunks = [stream[i:i + 4096] for i in range(0, len(stream), 4096)]
garbage_chunks = [garbage[i:i + 4096] for i in range(0, len(garbage), 4096)]

ranges = {s.prefix: (s.name, s.minimum, s.maximum) for s in specs}

def floor():  # the codec's checks, hand-written: command by its two bytes, digits only, range
    get = ranges.get
    for f in frames:
        r = get(f[:2])
        if r is not None:
            d = f[2:]
            if d.isdigit():
                v = int(d)
                if r[1] <= v <= r[2]:
                    (r[0], v)

def bare():  # no check at all: the floor of issue 54's first figures
    for f in frames:
        (f[0], f[1], int(f[2:]))

def decode_cold(frames=frames):
    dp.codec.DECODED.clear()
    for f in frames:
        dp.decode(f)

def feed(parts):
    dp.codec.DECODED.clear()
    feed = dp.StreamDecoder().feed
    for part in parts:
        feed(part, 0.0)

run = {"none": lambda: None, "floor": floor, "bare": bare, "decode_cold": decode_cold,
       "decode_distinct": lambda: decode_cold(distinct),
       "feed_one_byte": lambda: feed(single), "feed_4k_clean": lambda: feed(chunks),
       "feed_4k_half_garbage": lambda: feed(garbage_chunks)}[sys.argv[1]]
for _ in range(REPS):
    run()
'''

# (measure, subject, goal as a multiple of the floor)
MEASURES = (
    ("decode(), 1000 random frames (a repeat found in the memo), memo cleared first", "decode_cold", 2.0),
    ("decode(), 1000 distinct frames, memo cleared first (each decoded in full)", "decode_distinct", 2.0),
    ("StreamDecoder, clean stream in 4 kB reads, cold", "feed_4k_clean", 2.0),
    ("StreamDecoder, 50 % garbage in 4 kB reads, cold", "feed_4k_half_garbage", 4.0),
    ("StreamDecoder, one byte per call", "feed_one_byte", 10.0),
)


def instructions(script: Path, mode: str, path: Path) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        # one hash seed: dict probes of bytes keys moved the counts by 2-5 % from run to run
        proc = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable,
                               str(script), mode], capture_output=True, text=True, check=True,
                              env={**os.environ, "PYTHONHASHSEED": "0", "PYTHONPATH": str(path)})
    found = re.search(r"Collected : (\d+)", proc.stderr)
    if found is None:
        raise SystemExit(f"callgrind printed no total for {mode}:\n{proc.stderr}")
    return int(found.group(1))


def generate(generator_root: Path, spec: Path, out: Path) -> Path:
    """The Python package folder of `spec` made by the generator in `generator_root`."""
    subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out)], cwd=generator_root,
                   check=True, capture_output=True)
    return out / "python"


def per_frame(script: Path, path: Path) -> dict[str, float]:
    modes = ("none", "floor", "bare", *(m for _, m, _ in MEASURES))
    with ThreadPoolExecutor(2) as pool:  # instruction counts do not depend on the load
        counts = dict(zip(modes, pool.map(lambda m: instructions(script, m, path), modes), strict=True))
    return {m: (counts[m] - counts["none"]) / (REPS * FRAMES) for m in modes if m != "none"}


def table(after: dict[str, float], before: dict[str, float] | None) -> str:
    floor, bare = after["floor"], after["bare"]
    rows = ["| measure | instructions per frame | floor (checked) | ratio | goal | verdict "
            f"| against slice + int ({bare:,.0f}) |" + (" before (same run) |" if before else ""),
            "|---|---:|---:|---:|---:|---|---:|" + ("---:|" if before else "")]
    for name, mode, goal in MEASURES:
        ratio = after[mode] / floor
        was = f" {before[mode]:,.0f} ({before[mode] / before['floor']:.2f}x) |" if before else ""
        rows.append(f"| {name} | {after[mode]:,.0f} | {floor:,.0f} | {ratio:.2f}x | <= {goal:.0f}x | "
                    f"{'met' if ratio <= goal else 'MISSED'} | {after[mode] / bare:.2f}x |{was}")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--against", metavar="REV", help="also measure the codec REV's generator makes")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    if shutil.which("valgrind") is None:
        raise SystemExit("valgrind is missing: sudo apt-get install -y valgrind")
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        script = base / "workload.py"
        script.write_text(f"REPS = {REPS}\nFRAMES = {FRAMES}\n" + WORKLOAD)
        big = base / "synthetic_676.yaml"
        big.write_text(synthetic_676(), encoding="utf-8")
        shipped = ROOT / "spec" / "drone.yaml"
        roots = {"after": ROOT}
        if args.against:
            old = base / "against"
            old.mkdir()
            archive = subprocess.run(["git", "archive", args.against, "generator"], cwd=ROOT, check=True,
                                     capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", str(old)], input=archive, check=True)
            roots["before"] = old
        results = {(when, which): per_frame(script, generate(root, spec, base / f"{when}-{which}"))
                   for when, root in roots.items() for which, spec in (("shipped", shipped), ("676", big))}
    tables = {which: table(results["after", which], results.get(("before", which))) for which in ("shipped", "676")}
    for which, text in tables.items():
        print(f"{which}:\n{text}\n")
    if not args.no_write:
        against = (f"; \"before\" is the codec of `{args.against}`'s generator, measured in the same run"
                   if args.against else "")
        (HERE / "PYTHON_INSTRUCTIONS.md").write_text(
            "# The Python codec against its floor, in instructions\n\n"
            f"`python -m bench.protocol.python_instructions`: callgrind instruction counts of {FRAMES} random valid "
            f"frames x {REPS}, each loop minus an interpreter that only builds the inputs (Python "
            f"{sys.version.split()[0]}, hash seed 0). The floor does per frame what the codec must: the command "
            "by its two bytes (a dict), digits only (`bytes.isdigit()`), `int()`, the range, a result; the last "
            "column is against `(f[0], f[1], int(f[2:]))`, which checks nothing (the floor before). \"cold\" "
            f"and \"memo cleared first\" clear the decoder's memo of frames before each loop{against}.\n\n"
            "The shipped spec:\n\n" + tables["shipped"] + "\n\n"
            "The shipped spec plus 26 categories x 26 directions (`bench/generator/run.py`'s `synthetic_676`):\n\n"
            + tables["676"] + "\n\nHistory of these figures: bench/protocol/HISTORY.md.\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
