"""The generator killed (SIGKILL) at moments spread over its run: the output folder must hold all old or
all new files, and the next run must leave all new files and no debris.

Two specs differ by one servo's description (every generated file carries the spec's fingerprint, so every
file changes). The output folder starts with spec A's files and two files the generator does not write (a
``__pycache__`` file and a note); each round runs ``python -m generator`` with spec B and kills it after a
delay drawn uniformly over a measured run's length (seeded), or, with ``--aimed``, over the window in which
the new folder exists beside the old one (found by polling during a measured run, widened by 20 ms each
side). Then it counts the folders left mixed (files of both specs), corrupt, or missing the two other files,
with debris (the folder beside, a staging folder, temporary files), and what ``--check`` said; then runs the
generator again and checks all new files and no debris.

    python -m bench.sidechan.generator_kills [--kills 200] [--aimed 100]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

from generator.writing import STAGING, beside, debris, exchange

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SERVO = "description: Horizontal servo carrying the camera and the laser"


def _generate(spec: Path, out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out), *extra],
                          cwd=REPO, capture_output=True, text=True, check=False)


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*")
            if p.is_file() and STAGING not in p.parts and not p.name.endswith(".tmp")}


EXTRA = {"python/__pycache__/kept.pyc": b"bytecode", "notes.txt": b"a file of the user's"}


def _write_window(spec: Path, template: Path, work: Path) -> tuple[float, float]:
    """When, after the start of a run, the new folder exists beside the old one: (first seen, last seen)."""
    out = work / "window"
    shutil.copytree(template, out)
    seen: list[float] = []
    done = threading.Event()

    def poll(t0: float) -> None:
        while not done.is_set():
            if os.path.lexists(beside(out)):
                seen.append(time.perf_counter() - t0)
            time.sleep(0.0002)

    t0 = time.perf_counter()
    watcher = threading.Thread(target=poll, args=(t0,))
    watcher.start()
    _generate(spec, out)
    done.set()
    watcher.join()
    shutil.rmtree(out)
    if not seen:
        raise RuntimeError("the run never built its folder beside the old one")
    return seen[0], seen[-1]


def campaign(kills: int, seed: int, work: Path, aimed: bool = False) -> dict[str, float]:
    spec_a, spec_b = work / "a.yaml", work / "b.yaml"
    text = (REPO / "spec" / "drone.yaml").read_text(encoding="utf-8")
    assert SERVO in text
    spec_a.write_text(text, encoding="utf-8")
    spec_b.write_text(text.replace(SERVO, SERVO + " (B)"), encoding="utf-8")
    old_dir, new_dir = work / "old", work / "new"
    assert _generate(spec_a, old_dir).returncode == 0
    for rel, data in EXTRA.items():
        (old_dir / rel).parent.mkdir(parents=True, exist_ok=True)
        (old_dir / rel).write_bytes(data)
    t0 = time.perf_counter()
    assert _generate(spec_b, new_dir).returncode == 0
    run_s = time.perf_counter() - t0
    old, new = _files(old_dir), _files(new_dir)
    changed = {rel for rel in new if old.get(rel) != new[rel]}
    first, last = _write_window(spec_b, old_dir, work) if aimed else (0.0, run_s * 1.1)
    low, high = (max(0.0, first - 0.02), last + 0.02) if aimed else (first, last)
    rng = random.Random(seed)
    counts: dict[str, float] = {
        "kills": kills, "run_s": round(run_s, 2), "window_s": round(high - low, 3), "files_changed": len(changed),
        "all_old": 0, "all_new": 0, "mixed": 0, "corrupt": 0, "other_files_lost": 0, "debris_after_kill": 0,
        "interrupted_after_kill": 0, "check_reported_debris": 0, "not_new_after_next_run": 0,
        "debris_after_next_run": 0}
    out = work / "out"
    for _ in range(kills):
        shutil.rmtree(out, ignore_errors=True)
        shutil.copytree(old_dir, out)
        proc = subprocess.Popen([sys.executable, "-m", "generator", "--spec", str(spec_b), "--out", str(out)],
                                cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(low, high))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        now = _files(out)
        kinds = {"old" if now.get(rel) == old[rel] else "new" if now.get(rel) == new[rel] else "bad"
                 for rel in changed}
        if "bad" in kinds:
            counts["corrupt"] += 1
        elif kinds == {"old"}:
            counts["all_old"] += 1
        elif kinds == {"new"}:
            counts["all_new"] += 1
        else:
            counts["mixed"] += 1
        counts["other_files_lost"] += any(now.get(rel) != data for rel, data in EXTRA.items())
        left = debris(out)
        counts["interrupted_after_kill"] += any(x.startswith("interrupted") for x in left)
        counts["debris_after_kill"] += bool(left)
        if left:
            check = _generate(spec_b, out, "--check")
            counts["check_reported_debris"] += check.returncode == 1 and all(line in check.stdout for line in left)
        again = _generate(spec_b, out)
        counts["not_new_after_next_run"] += again.returncode != 0 or _files(out) != new | EXTRA
        counts["debris_after_next_run"] += (bool(debris(out)) or os.path.lexists(beside(out))
                                            or (out / STAGING).exists())
    return counts


def _exchange_supported(work: Path) -> bool:
    a, b = work / "probe-a", work / "probe-b"
    a.mkdir()
    b.mkdir()
    try:
        return exchange(a, b)
    finally:
        a.rmdir()
        b.rmdir()


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="generator_kills")
    p.add_argument("--kills", type=int, default=200)
    p.add_argument("--seed", type=int, default=53)
    p.add_argument("--aimed", type=int, default=100, help="and this many kills aimed at the writing phase")
    p.add_argument("--json", action="store_true", help="print the counts as JSON only, write nothing")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="generator-kills-") as work:
        supported = _exchange_supported(Path(work))
        counts = campaign(args.kills, args.seed, Path(work))
        (Path(work) / "aimed").mkdir()
        aimed = campaign(args.aimed, args.seed + 1, Path(work) / "aimed", aimed=True) if args.aimed else None
    if args.json:
        print(json.dumps(counts if aimed is None else {"spread": counts, "aimed": aimed}))
        return 0
    how = ("the new folder exchanged with the old one in one step (renameat2 RENAME_EXCHANGE)" if supported else
           "NO folder exchange on this system: the journalled moves")
    columns = [("spread", counts)] + ([("aimed", aimed)] if aimed else [])
    text = "\n".join(["# The generator killed mid-run (`make bench-sidechan`)", "",
                      f"Writing: {how}. Spread: {args.kills} SIGKILLs at moments drawn uniformly over 1.1 x a "
                      f"measured run ({counts['run_s']} s; seed {args.seed}); spec A's files in place with two "
                      "files the generator does not write, spec B being written "
                      f"({counts['files_changed']} files change)."
                      + (f" Aimed: {args.aimed} SIGKILLs drawn uniformly over the {aimed['window_s']} s in which "
                         f"the new folder stood beside the old one in a measured run, +-20 ms (seed {args.seed + 1})."
                         if aimed else ""), "",
                      "| what | " + " | ".join(name for name, _ in columns) + " |",
                      "|---|" + "---|" * len(columns),
                      *(f"| {k} | " + " | ".join(str(c[k]) for _, c in columns) + " |" for k in counts), ""])
    print(text)
    (HERE / "RESULTS-generator-kills.md").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
