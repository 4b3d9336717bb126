"""The live view under load: simulated flights with and without 300 hostile clients, the loop's rate.

Each round flies the same simulated flight (scenario ahead, seed 2, the firmware's host build as the drone)
twice with ``--serve`` on: once with no client, once with ``bench.sidechan.swarm`` (in its own process)
keeping 300 clients going (connected viewers, idle sockets, slow readers, resets), at the lowest priority
(``nice 19``: on the 2 shared cores of this machine the clients would otherwise take the processor the
simulated drone and the pilot need; a real crowd runs on other machines). Paced flights hold the
loop to real time, as a real camera does (the rate and the longest gap between two ticks say whether it
keeps up); unpaced ones run as fast as the machine allows (what the server's thread costs the loop).
Reports the rates, the longest gap, tracebacks, the pilot process's memory, and writes RESULTS.md.

    PILOT_VIRTUAL_DRONE=build/firmware/host/virtual_drone python -m bench.sidechan.liveview_load
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

from bench.tools.run import Rate
from pilot.app.liveview import LiveView
from pilot.app.observers import StopSwitch, WallClockPacing
from pilot.app.runner import Observer
from pilot.app.sim_flight import fly

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SWARM = {"viewers": 75, "idle": 75, "slow": 75, "reset": 75}


class Gaps(Rate):
    @property
    def max_gap_ms(self) -> float:
        return max(b - a for a, b in zip(self.times, self.times[1:], strict=False)) * 1000


def rss_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def one_flight(paced: bool, load: bool, executable: str | None, seconds: float) -> dict[str, object]:
    gaps = Gaps()
    log: list[str] = []
    tracebacks = [0]
    hook = threading.excepthook
    threading.excepthook = lambda args: tracebacks.__setitem__(0, tracebacks[0] + 1)
    view = LiveView("127.0.0.1", 0, StopSwitch(), log=log.append)
    observers: list[Observer] = [gaps, view]
    if paced:
        observers.append(WallClockPacing())
    swarm = None
    peak = {"rss": rss_mb(), "connections": 0, "viewers": 0}

    def watch() -> None:
        while swarm is not None and swarm.poll() is None:
            peak["rss"] = max(peak["rss"], rss_mb())
            peak["connections"] = max(peak["connections"], view.server.connections)
            peak["viewers"] = max(peak["viewers"], view.server.viewers)
            time.sleep(0.1)

    if load:
        args = [f"--{k}={v}" for k, v in SWARM.items()]
        swarm = subprocess.Popen(["nice", "-n", "19", sys.executable, "-m", "bench.sidechan.swarm", view.url, *args,
                                  f"--seconds={seconds}"], cwd=REPO, stdout=subprocess.PIPE, text=True)
        time.sleep(2.0)  # the crowd is in before take-off
        threading.Thread(target=watch, daemon=True).start()
    rss0 = rss_mb()
    try:
        flight = fly("ahead", 2, executable=executable, observers=observers, max_seconds=seconds)
    finally:
        view.close()
        threading.excepthook = hook
    clients: dict[str, object] = {}
    if swarm is not None:
        out, _ = swarm.communicate(timeout=seconds + 60)
        clients = json.loads(out)
    return {"paced": paced, "load": load, "hz": round(gaps.hz, 2), "max_gap_ms": round(gaps.max_gap_ms, 1),
            "ticks": len(gaps.times), "disarmed": not flight.final_armed, "altitude": round(flight.final_altitude, 2),
            "summary": flight.summary(), "tracebacks": tracebacks[0], "log_lines": len(log),
            "rss_before_mb": round(rss0, 1), "rss_peak_mb": round(max(peak["rss"], rss_mb()), 1),
            "peak_connections": peak["connections"], "peak_viewers": peak["viewers"],
            "dropped_frames": view.server.dropped, "refused": view.server.refused,
            "evicted": view.server.evicted, "server_cpu_s": round(view.server.cpu_s, 2),
            "wall_s": round(flight.wall_seconds, 1), "load_average_1min": round(os.getloadavg()[0], 1),
            "clients": clients}


def synthetic(pairs: int, seconds: float) -> str:
    """A paced 20 Hz loop that only feeds the view (320x240 noise frames, about 50 KB of JPEG each), alone and
    with the 300 clients, alternating so that the machine's load drifts alike over both."""
    import drone_protocol as dp
    import numpy as np

    from pilot.app.runner import Tick
    from pilot.control.controller import State
    from pilot.vision.detect import Detection
    from pilot.vision.sources import Frame

    noise = [np.random.default_rng(i).integers(0, 255, (240, 320, 3), dtype=np.uint8) for i in range(8)]
    rates: dict[bool, list[float]] = {False: [], True: []}
    gaps: dict[bool, float] = {False: 0.0, True: 0.0}
    calls: dict[bool, float] = {False: 0.0, True: 0.0}
    log: list[str] = []
    with LiveView("127.0.0.1", 0, StopSwitch(), log=log.append) as view:
        for i in range(2 * pairs):
            crowd = i % 2 == 1
            swarm = None
            if crowd:
                args = [f"--{k}={v}" for k, v in SWARM.items()]
                swarm = subprocess.Popen(["nice", "-n", "19", sys.executable, "-m", "bench.sidechan.swarm", view.url,
                                          *args, f"--seconds={seconds + 2}"], cwd=REPO, stdout=subprocess.DEVNULL)
                time.sleep(1.5)
            times: list[float] = []
            start = time.perf_counter()
            for n in range(int(seconds * 20)):
                t0 = time.perf_counter()
                frame = Frame(noise[n % 8], t0, n)
                view.on_tick(Tick(n, t0, frame, Detection(True, 160.0, 120.0, 20.0, 0.9), State.TRACK,
                                  dp.hold_altitude(), (), t0, None))
                calls[crowd] = max(calls[crowd], time.perf_counter() - t0)
                times.append(t0)
                time.sleep(max(0.0, start + (n + 1) * 0.05 - time.perf_counter()))
            rates[crowd].append((len(times) - 1) / (times[-1] - times[0]))
            gaps[crowd] = max(gaps[crowd], max(b - a for a, b in itertools.pairwise(times)))
            if swarm is not None:
                swarm.wait(timeout=60)
    alone, crowded = statistics.median(rates[False]), statistics.median(rates[True])
    return "\n".join([
        "", "## A paced loop that only feeds the view", "",
        f"{pairs} pairs of {seconds:g} s: a 20 Hz loop handing 320x240 frames to the view, alone then with the 300 "
        f"clients (load average {os.getloadavg()[0]:.1f} at the end).", "",
        "| clients | rate (Hz, median) | vs alone | longest gap (ms) | longest on_tick (ms) |", "|---|---|---|---|---|",
        f"| 0 | {alone:.3f} | | {gaps[False] * 1000:.0f} | {calls[False] * 1000:.1f} |",
        f"| 300 | {crowded:.3f} | {100 * (crowded / alone - 1):+.2f} % | {gaps[True] * 1000:.0f} "
        f"| {calls[True] * 1000:.1f} |", "",
        f"Log lines from the server: {len(log)} (at most one a second), tracebacks: 0 unless shown above.", ""])


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="liveview_load")
    p.add_argument("--synthetic-pairs", type=int, default=0, help="only the paced loop that feeds the view")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--seconds", type=float, default=30.0)
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args(argv)
    if args.synthetic_pairs:
        text = synthetic(args.synthetic_pairs, 5.0)
        print(text)
        if not args.no_write:
            with (HERE / "RESULTS.md").open("a") as f:
                f.write(text)
        return 0
    executable = os.environ.get("PILOT_VIRTUAL_DRONE")
    runs: list[dict[str, object]] = []
    for r in range(args.rounds):
        for paced in (True, False):
            for load in (False, True):
                run = one_flight(paced, load, executable, args.seconds)
                runs.append(run)
                print(f"round {r + 1} {'paced' if paced else 'unpaced'} {'300 clients' if load else 'no client'}: "
                      f"{run['hz']} Hz, longest gap {run['max_gap_ms']} ms, {run['tracebacks']} tracebacks, "
                      f"rss {run['rss_before_mb']}->{run['rss_peak_mb']} MB, {run['clients']}", flush=True)
    text = render(runs, args.rounds, args.seconds)
    print(text)
    if not args.no_write:
        (HERE / "RESULTS.md").write_text(text)
    return 0


def _f(run: dict[str, object], key: str) -> float:
    return float(str(run[key]))


def _spread(runs: list[dict[str, object]]) -> str:
    quiet = [_f(r, "hz") for r in runs if not r["load"]]
    return f"{min(quiet):.1f}-{max(quiet):.1f} Hz" if quiet else "no rate"


def render(runs: list[dict[str, object]], rounds: int, seconds: float) -> str:
    lines = ["# The live view under load (`make bench-sidechan`)", "",
             f"{rounds} rounds; each: the simulated flight (ahead, seed 2, {seconds:g} s at most) paced "
             "and unpaced, with no client and with 300 (75 each: viewers, idle, slow, resetting), default limits "
             "(4 viewers, 32 sockets). The machine's 2 cores are shared: each run records the load average, "
             "and a paced flight that falls short of 20 Hz without any client says the machine, not the live "
             "view, was short of processor time. The server thread's own processor time is the view's cost. "
             f"The flights without a client alone ran at {_spread(runs)}: whole flights of one condition against "
             "another compare the machine's moments as much as the conditions; the turns of "
             "bench.sidechan.liveview_cost (below) separate the view's cost from the machine's.", "",
             "| mode | clients | rate (Hz, median) | rate vs no client | longest gap (ms, max) | tracebacks | "
             "peak RSS (MB) | peak sockets | frames dropped | server thread CPU (% of the flight) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for paced in (True, False):
        base = statistics.median(float(str(r["hz"])) for r in runs if r["paced"] == paced and not r["load"])
        for load in (False, True):
            sel = [r for r in runs if r["paced"] == paced and r["load"] == load]
            hz = statistics.median(float(str(r["hz"])) for r in sel)
            lines.append(
                f"| {'paced' if paced else 'unpaced'} | {300 if load else 0} | {hz:.2f} "
                f"| {100 * (hz / base - 1):+.1f} % | {max(float(str(r['max_gap_ms'])) for r in sel):.0f} "
                f"| {sum(int(str(r['tracebacks'])) for r in sel)} "
                f"| {max(float(str(r['rss_peak_mb'])) for r in sel):.0f} "
                f"| {max(int(str(r['peak_connections'])) for r in sel)} "
                f"| {sum(int(str(r['dropped_frames'])) for r in sel)} "
                f"| {max(100 * _f(r, 'server_cpu_s') / _f(r, 'wall_s') for r in sel):.1f} |")
    lines += ["", "Each run:", "", "```", *(json.dumps(r) for r in runs), "```", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
