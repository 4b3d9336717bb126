"""Disk full at random moments of a recorded flight: every flight must still end landed and disarmed, with
its summary, and say once that the recording stopped.

Each run mounts a small tmpfs, fills it to leave a random amount of room (seeded), and flies the pilot's
command line (scenario ahead, seed 2, the firmware's host build as the drone) with ``--record`` on it, so
the disk fills at a random moment of the flight. Needs the right to mount (root in a container).

    PILOT_VIRTUAL_DRONE=firmware/build/host/virtual_drone python -m bench.sidechan.disk_full --runs 10
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SIZE_MB = 16
ROOM = (20_000, 9_000_000)  # bytes left free: a full recording of this flight takes about 8 MB


def one(room: int, executable: str | None) -> dict[str, object]:
    with tempfile.TemporaryDirectory(prefix="sidechan-disk-") as mount:
        subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={SIZE_MB}m", "tmpfs", mount], check=True)
        try:
            free = os.statvfs(mount).f_bavail * os.statvfs(mount).f_frsize
            Path(mount, "filler").write_bytes(b"\0" * max(0, free - room))
            argv = [sys.executable, "-m", "pilot", "--scenario", "ahead", "--seed", "2", "--record",
                    f"{mount}/rec", "--no-status", "--max-seconds", "60"]
            if executable:
                argv += ["--virtual-drone", executable]
            proc = subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=600, check=False)
        finally:
            subprocess.run(["umount", mount], check=False)
    out, err = proc.stdout, proc.stderr
    return {
        "room_bytes": room, "exit": proc.returncode,
        "landed_disarmed": "drone:     laser off, disarmed, altitude 0.00 m" in out,
        "summary": out.startswith("ahead      seed   2 "),
        "stopped_lines": err.count("pilot: recording stopped:"),
        "tracebacks": (out + err).count("Traceback"),
        "stderr": err.strip().splitlines()[:2],
    }


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="disk_full")
    p.add_argument("--runs", type=int, default=10)
    p.add_argument("--seed", type=int, default=53)
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args(argv)
    rng = random.Random(args.seed)
    executable = os.environ.get("PILOT_VIRTUAL_DRONE")
    runs = []
    for i in range(args.runs):
        run = one(rng.randint(*ROOM), executable)
        runs.append(run)
        print(f"run {i + 1}: {run}", flush=True)
    ok = [r for r in runs if r["landed_disarmed"] and r["summary"] and r["tracebacks"] == 0]
    full = [r for r in runs if r["stopped_lines"] == 1]
    lines = ["# Disk full during a recorded flight (`make bench-sidechan`)", "",
             f"{args.runs} flights (ahead, seed 2), a {SIZE_MB} MB tmpfs left with {ROOM[0]:,}..{ROOM[1]:,} bytes "
             f"free (random seed {args.seed}).", "",
             f"- ended landed and disarmed, with the summary, no traceback: **{len(ok)}/{len(runs)}**",
             f"- the disk filled during the flight (one 'recording stopped' line): {len(full)}/{len(runs)}", "",
             "| room (bytes) | exit | landed, disarmed | summary | 'stopped' lines | tracebacks |",
             "|---|---|---|---|---|---|",
             *(f"| {r['room_bytes']:,} | {r['exit']} | {r['landed_disarmed']} | {r['summary']} | "
               f"{r['stopped_lines']} | {r['tracebacks']} |" for r in runs), ""]
    text = "\n".join(lines)
    print(text)
    if not args.no_write:
        (HERE / "RESULTS-disk-full.md").write_text(text)
    return 0 if len(ok) == len(runs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
