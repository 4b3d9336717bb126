"""The strict campaign's pieces: the held-out seeds, flights with another speed step, and the tables.

Held out: still-air seeds from ``HELD_OUT_STILL`` and gust seeds from ``HELD_OUT_GUSTS``; no tuning run of the pilot,
the detectors or the simulator flew them (the tuning campaigns used seeds 0-7, 500-503, 600-603, 700-707 and gust
seeds 1000-1003, bench/flight/HISTORY.md). A flight succeeds by the strict score of ``pilot.app.sim_flight``.

Another speed step (``respec``) is a whole other build: the spec with ``speeds.step_us`` changed is generated into a
temporary folder, the virtual drone is built from that Arduino library, and the flights' processes import that
``drone_protocol`` (``PYTHONPATH``), as a user who edited the spec would fly.
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
HELD_OUT_STILL = 3000
HELD_OUT_GUSTS = 4000
RATIO_LIMIT = 1.5  # a flight with another step takes at most this times the same seed's time at the shipped step


def respec(step_us: int, root: Path) -> Path:
    """Generate the spec with ``step_us`` into ``root`` and build the virtual drone from it; point the flights'
    processes at that ``drone_protocol``. Returns the virtual drone."""
    text = (REPO / "spec" / "drone.yaml").read_text(encoding="utf-8")
    edited, n = re.subn(r"(?m)^  step_us: \d+$", f"  step_us: {step_us}", text)
    if n != 1:
        raise SystemExit("bench/flight: spec/drone.yaml has no single speeds.step_us line to edit")
    spec = root / "drone.yaml"
    spec.write_text(edited, encoding="utf-8")
    generated = root / "generated"
    subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(generated)], cwd=REPO,
                   check=True)
    build = root / "fw"
    subprocess.run(["make", "-s", "firmware-host", f"FW_BUILD={build}",
                    f"DRONE_PROTOCOL_DIR={generated / 'arduino' / 'DroneProtocol'}"], cwd=REPO, check=True)
    # spawned processes start from this one's sys.path (multiprocessing passes it on), and from PYTHONPATH
    sys.path.insert(0, str(generated / "python"))
    os.environ["PYTHONPATH"] = os.pathsep.join([str(generated / "python"), str(REPO)])
    return build / "host" / "virtual_drone"


def _pct(n: int, d: int) -> str:
    return f"{n}/{d} ({100.0 * n / d:.1f} %)" if d else "0/0"


def _group(r: dict[str, Any]) -> str:
    gusts = f" + gusts {r['gusts']:g} m/s" if r["gusts"] else ""
    return f"{r['detector']}{gusts}"


def table(rows: Sequence[dict[str, Any]]) -> list[str]:
    """Strict success, time to target, non-target hits, walls and landings per detector (and gusts)."""
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        groups[_group(r)].append(r)
    lines = ["| flights | strict success | median time to target (s) | non-target hits | flights touching a wall | "
             "crashes | ended landed, disarmed, laser off |", "|---|---|---|---|---|---|---|"]
    for name, rs in sorted(groups.items()):
        times = [float(r["time_to_target_s"]) for r in rs if r.get("time_to_target_s") is not None]
        median = f"{statistics.median(times):.1f}" if times else "-"
        safe = sum(not r["final_laser"] and not r["final_fc_armed"] and not r["final_armed"] for r in rs)
        walls = _pct(sum(r["wall_hits"] > 0 for r in rs), len(rs))
        lines.append(f"| {name} | {_pct(sum(bool(r['success']) for r in rs), len(rs))} | {median} | "
                     f"{sum(int(r['non_target_hits']) for r in rs)} | {walls} | {sum(r['crashes'] > 0 for r in rs)} | "
                     f"{_pct(safe, len(rs))} |")
    return lines


def reasons(rows: Sequence[dict[str, Any]]) -> list[str]:
    """How many flights failed for each reason (a flight may have several)."""
    counts: dict[str, int] = defaultdict(int)
    for r in rows:
        for why in r.get("failures") or ():
            counts[re.sub(r"\d+", "N", why)] += 1
    return [f"- {why}: {n}" for why, n in sorted(counts.items(), key=lambda kv: -kv[1])] or ["- none"]


def compare(rows: Sequence[dict[str, Any]], base: Sequence[dict[str, Any]]) -> list[str]:
    """Each flight against the same seed and scenario at the shipped step: its simulated time (the time to target
    when both succeeded), and whether it stays within ``RATIO_LIMIT``."""
    by_key = {(r["scenario"], r["seed"], r["detector"]): r for r in base if not r["gusts"]}
    ratios: list[tuple[float, str]] = []
    for r in rows:
        b = by_key.get((r["scenario"], r["seed"], r["detector"]))
        if b is None:
            continue
        both = r.get("time_to_target_s") is not None and b.get("time_to_target_s") is not None
        mine, theirs = (r["time_to_target_s"], b["time_to_target_s"]) if both else (r["sim_seconds"], b["sim_seconds"])
        ratios.append((float(mine) / float(theirs), f"{r['scenario']} {r['seed']}"))
    if not ratios:
        return ["No flight of the shipped step to compare with."]
    worst = max(ratios)
    within = sum(ratio <= RATIO_LIMIT for ratio, _ in ratios)
    return [f"Against the same seeds at the shipped step ({len(ratios)} flights): {_pct(within, len(ratios))} within "
            f"{RATIO_LIMIT}x its time; median ratio {statistics.median(r for r, _ in ratios):.2f}, "
            f"worst {worst[0]:.2f} ({worst[1]})."]
