"""The generator killed (SIGKILL) at moments spread over its run: the output folder must hold all old or
all new files, and the next run must leave all new files and no debris.

Two specs differ by one servo's description (every generated file carries the spec's fingerprint, so every
file changes). The output folder starts with spec A's files; each round runs ``python -m generator`` with
spec B and kills it after a delay drawn uniformly over a measured run's length (seeded). Then it counts
the folders left mixed (files of both specs: a kill while the files move into place, after the commit
point; the committed manifest is there for the next run to finish, and ``--check`` says so), with debris
(a staging folder or temporary files), and what ``--check`` said; then runs the generator again and
checks all new files and no debris.

    python -m bench.sidechan.generator_kills --kills 200
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from generator.writing import MANIFEST, STAGING, debris

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SERVO = "description: Horizontal servo carrying the camera and the laser"


def _generate(spec: Path, out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out), *extra],
                          cwd=REPO, capture_output=True, text=True, check=False)


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*")
            if p.is_file() and STAGING not in p.parts and not p.name.endswith(".tmp")}


def campaign(kills: int, seed: int, work: Path) -> dict[str, float]:
    spec_a, spec_b = work / "a.yaml", work / "b.yaml"
    text = (REPO / "spec" / "drone.yaml").read_text(encoding="utf-8")
    assert SERVO in text
    spec_a.write_text(text, encoding="utf-8")
    spec_b.write_text(text.replace(SERVO, SERVO + " (B)"), encoding="utf-8")
    old_dir, new_dir = work / "old", work / "new"
    assert _generate(spec_a, old_dir).returncode == 0
    t0 = time.perf_counter()
    assert _generate(spec_b, new_dir).returncode == 0
    run_s = time.perf_counter() - t0
    old, new = _files(old_dir), _files(new_dir)
    changed = {rel for rel in new if old.get(rel) != new[rel]}
    rng = random.Random(seed)
    counts = {"kills": kills, "run_s": round(run_s, 2), "files_changed": len(changed), "all_old": 0, "all_new": 0,
              "mixed": 0, "mixed_without_manifest": 0, "corrupt": 0, "debris_after_kill": 0,
              "interrupted_after_kill": 0, "check_reported_debris": 0, "not_new_after_next_run": 0,
              "debris_after_next_run": 0}
    out = work / "out"
    for _ in range(kills):
        shutil.rmtree(out, ignore_errors=True)
        shutil.copytree(old_dir, out)
        proc = subprocess.Popen([sys.executable, "-m", "generator", "--spec", str(spec_b), "--out", str(out)],
                                cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.0, run_s * 1.1))
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
        else:  # cut while moving files into place: the committed manifest lets the next run finish
            counts["mixed"] += 1
            counts["mixed_without_manifest"] += not (out / STAGING / MANIFEST).is_file()
        left = debris(out)
        counts["interrupted_after_kill"] += any(x.startswith("interrupted") for x in left)
        counts["debris_after_kill"] += bool(left)
        if left:
            check = _generate(spec_b, out, "--check")
            counts["check_reported_debris"] += check.returncode == 1 and str(out / STAGING) in check.stdout
        again = _generate(spec_b, out)
        counts["not_new_after_next_run"] += again.returncode != 0 or _files(out) != new
        counts["debris_after_next_run"] += bool(debris(out)) or (out / STAGING).exists()
    return counts


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="generator_kills")
    p.add_argument("--kills", type=int, default=200)
    p.add_argument("--seed", type=int, default=53)
    p.add_argument("--json", action="store_true", help="print the counts as JSON only, write nothing")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="generator-kills-") as work:
        counts = campaign(args.kills, args.seed, Path(work))
    if args.json:
        print(json.dumps(counts))
        return 0
    text = "\n".join(["# The generator killed mid-run (`make bench-sidechan`)", "",
                      f"{args.kills} SIGKILLs at moments drawn uniformly over 1.1 x a measured run "
                      f"({counts['run_s']} s; seed {args.seed}), spec A's files in place, spec B being written "
                      f"({counts['files_changed']} files change).", "",
                      "| what | count |", "|---|---|", *(f"| {k} | {v} |" for k, v in counts.items()), ""])
    print(text)
    (HERE / "RESULTS-generator-kills.md").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
