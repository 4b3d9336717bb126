"""What the live view costs the flight loop, apart from what a crowd of clients costs the machine.

Flights of one condition against flights of another measure the machine's moving load, so one flight carries three
conditions in turns of ``--phase`` seconds, in a new random order each cycle. Two swarms of 300 clients
(bench.sidechan.swarm, nice 19), one on the pilot's live view and one on a decoy view in another process, are
held (SIGSTOP) and resumed (SIGCONT) so that at most one runs: ``pilot`` (the pilot serves 300 clients), ``decoy``
(the machine carries the same crowd, the pilot serves nobody), ``none`` (both held). ``pilot`` against ``decoy``
is what serving costs the loop; ``decoy`` against ``none`` is what the clients cost two shared cores. Reported per
condition: rate, tick period p50/p99/max, time in ``on_tick``, sleep lateness, thread and swarm CPU; per cycle the
ratio pilot/decoy with its quartiles; peak memory, tracebacks, load average.

    PILOT_VIRTUAL_DRONE=build/firmware/host/virtual_drone python -m bench.sidechan.liveview_cost
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import random
import resource
import signal
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from pilot.app.liveview import LiveView
from pilot.app.observers import StopSwitch, WallClockPacing
from pilot.app.runner import Observer, Tick
from pilot.app.sim_flight import fly

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SWARM = {"viewers": 75, "idle": 75, "slow": 75, "reset": 75}
CONDITIONS = ("none", "pilot", "decoy")
SETTLE_S = 0.3  # after a switch: ticks already under way belong to neither turn


class Probe:
    """The loop's side of the view, measured: the tick times, the time in ``on_tick``, the main thread's CPU."""

    def __init__(self, view: LiveView) -> None:
        self.view = view
        self.times: list[float] = []
        self.calls: list[float] = []
        self.cpu: list[float] = []

    def on_tick(self, tick: Tick) -> None:
        t0 = time.perf_counter()
        self.times.append(t0)
        self.cpu.append(time.thread_time())
        self.view.on_tick(tick)
        self.calls.append(time.perf_counter() - t0)


class LateSleep:
    """``time.sleep`` that records how much later than asked it returned (the scheduler and the lock)."""

    def __init__(self) -> None:
        self.late: list[tuple[float, float]] = []  # (when, how late)

    def __call__(self, seconds: float) -> None:
        t0 = time.perf_counter()
        time.sleep(seconds)
        t1 = time.perf_counter()
        self.late.append((t1, t1 - t0 - seconds))


def pct(values: Sequence[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def rss_peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def rss_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def _ordinary_priority() -> None:
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))


def start(args: list[str]) -> subprocess.Popen[str]:
    """A helper process (swarm, decoy) at the ordinary priority, whatever the pilot's (``--realtime``)."""
    return subprocess.Popen([sys.executable, "-m", *args], cwd=REPO, stdout=subprocess.PIPE, text=True,
                            preexec_fn=_ordinary_priority)


def finish(proc: subprocess.Popen[str] | None) -> dict[str, Any]:
    """SIGTERM, then the one JSON line it prints on the way out."""
    if proc is None:
        return {}
    proc.send_signal(signal.SIGTERM)
    out, _ = proc.communicate(timeout=30)
    lines = [line for line in out.splitlines() if line.startswith("{")]
    return json.loads(lines[-1]) if lines else {"error": f"exit {proc.returncode}, no report"}


def proc_cpu_s(pid: int) -> float:
    """A process's processor time so far (user + system), from /proc."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Turns:
    """Runs at most one of the two swarms at a time, in turns; records each turn's start and the CPU counters."""

    def __init__(self, swarms: dict[str, subprocess.Popen[str]], view: LiveView, phase_s: float, seed: int) -> None:
        self.swarms, self.view, self.phase_s = swarms, view, phase_s
        self.order = random.Random(seed)
        self.turns: list[tuple[float, str, float, dict[str, float]]] = []  # (start, condition, server CPU, swarms')
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self.peak_connections = self.peak_viewers = 0
        self.rss: dict[str, float] = {}  # the pilot process's largest resident size in each condition (MB)

    def _wait(self, seconds: float) -> bool:
        """Until the turn's end (watching the server's sockets), or True once the flight is over."""
        end = time.perf_counter() + seconds
        while (left := end - time.perf_counter()) > 0:
            if self._done.wait(min(left, 0.1)):
                return True
            self.peak_connections = max(self.peak_connections, self.view.server.connections)
            self.peak_viewers = max(self.peak_viewers, self.view.server.viewers)
            condition = self.turns[-1][1]
            self.rss[condition] = max(self.rss.get(condition, 0.0), rss_mb())
        return False

    def _set(self, condition: str) -> None:
        for name, proc in self.swarms.items():
            proc.send_signal(signal.SIGCONT if name == condition else signal.SIGSTOP)
        cpus = {name: proc_cpu_s(proc.pid) for name, proc in self.swarms.items()}
        self.turns.append((time.perf_counter(), condition, self.view.server.cpu_s, cpus))

    def _run(self) -> None:
        while not self._done.is_set():
            for condition in self.order.sample(CONDITIONS, len(CONDITIONS)):
                self._set(condition)
                if self._wait(self.phase_s):
                    break
        self._set("end")
        for proc in self.swarms.values():
            proc.send_signal(signal.SIGCONT)

    def __enter__(self) -> Turns:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._done.set()
        self._thread.join()


def one_flight(decoy_url: str, executable: str | None, seconds: float, paced: bool, phase_s: float,
               seed: int) -> dict[str, Any]:
    log: list[str] = []
    tracebacks = [0]
    hook = threading.excepthook
    threading.excepthook = lambda args: tracebacks.__setitem__(0, tracebacks[0] + 1)
    view = LiveView("127.0.0.1", 0, StopSwitch(), log=log.append)
    probe = Probe(view)
    sleep = LateSleep()
    observers: list[Observer] = [probe]
    if paced:
        observers.append(WallClockPacing(sleep=sleep))
    swarms = {name: start(["bench.sidechan.swarm", url, *(f"--{k}={v}" for k, v in SWARM.items()),
                           "--seconds=900", "--nice=19"]) for name, url in (("pilot", view.url), ("decoy", decoy_url))}
    time.sleep(2.0)  # both crowds connect before take-off
    load0 = os.getloadavg()[0]
    try:
        with Turns(swarms, view, phase_s, seed) as turns:
            flight = fly("ahead", 2, executable=executable, observers=observers, max_seconds=seconds)
    finally:
        view.close()
        threading.excepthook = hook
    clients = {name: finish(proc) for name, proc in swarms.items()}
    per = judge(probe, sleep, turns.turns)
    return {"paced": paced, "ticks": len(probe.times), "wall_s": round(flight.wall_seconds, 1),
            "turns": len(turns.turns) - 1, "conditions": per,
            "server_longest_busy_ms": round(1000 * view.server.longest_busy_s, 2),
            "rss_peak_mb": round(rss_peak_mb(), 1), "rss_mb": {k: round(v, 1) for k, v in turns.rss.items()},
            "peak_connections": turns.peak_connections,
            "peak_viewers": turns.peak_viewers,
            "dropped_frames": view.server.dropped, "refused": view.server.refused, "encoded": view.encoded,
            "tracebacks": tracebacks[0] + sum("Traceback" in line for line in log), "log_lines": len(log),
            "disarmed": not flight.final_armed, "load_average": [round(load0, 1), round(os.getloadavg()[0], 1)],
            "clients": clients}


def judge(probe: Probe, sleep: LateSleep, turns: list[tuple[float, str, float, dict[str, float]]]) -> dict[str, Any]:
    """Each tick to the turn it fell in (past the settling time); the figures of each condition, and the rate of
    each turn (for the per-cycle ratios)."""
    first, last = probe.times[0], probe.times[-1]  # the loop's start-up and landing belong to no turn
    windows = [(max(a[0] + SETTLE_S, first), min(b[0], last), a[1], b[2] - a[2],
                {k: b[3][k] - a[3][k] for k in a[3]}, b[0] - a[0]) for a, b in itertools.pairwise(turns)]
    out: dict[str, Any] = {}
    for condition in CONDITIONS:
        mine = [w for w in windows if w[2] == condition and w[1] > w[0]]
        inside = [i for i, t in enumerate(probe.times) if any(lo <= t < hi for lo, hi, *_ in mine)]
        periods = [probe.times[i] - probe.times[i - 1] for i in inside if i > 0]
        cpu = [probe.cpu[i] - probe.cpu[i - 1] for i in inside if i > 0]
        late = [x for t, x in sleep.late if any(lo <= t < hi for lo, hi, *_ in mine)]
        span = sum(hi - lo for lo, hi, *_ in mine)
        turn_s = sum(w[5] for w in mine)  # whole turns: the processor counters are read at the switches
        out[condition] = {
            "seconds": round(span, 1), "ticks": len(inside), "hz": round(len(inside) / span, 3) if span else None,
            "turn_hz": [round(sum(lo <= t < hi for t in probe.times) / (hi - lo), 2) for lo, hi, *_ in mine],
            "period_ms": [round(1000 * pct(periods, q), 1) for q in (0.5, 0.99, 1.0)],
            "on_tick_us": [round(1e6 * pct([probe.calls[i] for i in inside], q)) for q in (0.5, 0.99, 1.0)],
            "sleep_late_ms": [round(1000 * pct(late, q), 2) for q in (0.5, 0.99, 1.0)],
            "main_cpu_ms_per_tick": round(1000 * statistics.fmean(cpu), 2) if cpu else None,
            "server_cpu_pct": round(100 * sum(w[3] for w in mine) / turn_s, 1) if turn_s else None,
            "swarm_cpu_pct": round(100 * sum(sum(w[4].values()) for w in mine) / turn_s, 1) if turn_s else None,
        }
    return out


def decoy(fps: float = 20.0) -> int:
    """A live view in its own process, fed 320x240 frames at ``fps`` until SIGTERM; prints its URL, then a report."""
    import drone_protocol as dp
    import numpy as np

    from pilot.control.controller import State
    from pilot.vision.detect import Detection
    from pilot.vision.sources import Frame

    rng = np.random.default_rng(53)  # a smooth scene with some noise: JPEGs of a rendered room's size
    base = np.linspace(0, 200, 320 * 240 * 3).reshape(240, 320, 3).astype(np.uint8)
    frames = [np.clip(base + rng.integers(0, 24, base.shape), 0, 255).astype(np.uint8) for _ in range(4)]
    stopping = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stopping.set())
    log: list[str] = []
    n = 0
    with LiveView("127.0.0.1", 0, StopSwitch(), log=log.append) as view:
        print(view.url, flush=True)
        start_t = time.perf_counter()
        while not stopping.is_set():
            t = time.perf_counter()
            view.on_tick(Tick(n, t, Frame(frames[n % 4], t, n), Detection(True, 160.0, 120.0, 20.0, 0.9),
                              State.TRACK, dp.hold_altitude(), (), t, None))
            n += 1
            stopping.wait(max(0.0, start_t + n / fps - time.perf_counter()))
        server_cpu = view.server.cpu_s
    print(json.dumps({"frames": n, "server_cpu_s": round(server_cpu, 2),
                      "cpu_s": round(time.process_time(), 2), "log_lines": len(log)}), flush=True)
    return 0


def rss_by_condition(runs: list[dict[str, Any]]) -> str:
    return ", ".join(f"{c} {max(r['rss_mb'].get(c, 0.0) for r in runs):.0f}" for c in CONDITIONS)


def summary(runs: list[dict[str, Any]], paced: bool) -> list[str]:
    sel = [r for r in runs if r["paced"] == paced]
    if not sel:
        return []
    lines = [f"### {'Paced to real time (20 Hz)' if paced else 'Unpaced (as fast as the machine allows)'}: "
             f"{len(sel)} flights, {sum(r['turns'] for r in sel)} turns", "",
             "| turn | seconds | rate (Hz) | vs none | vs decoy | tick period p50/p99/max (ms) "
             "| on_tick p50/p99/max (us) | sleep wakes late p50/p99/max (ms) | main thread CPU per tick (ms) "
             "| server thread CPU (% of the turn) | swarms' CPU (% of the turn) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    hz = {c: sum(r["conditions"][c]["ticks"] for r in sel) / sum(r["conditions"][c]["seconds"] for r in sel)
          for c in CONDITIONS}
    for c in CONDITIONS:
        rs = [r["conditions"][c] for r in sel]

        def med(key: str, i: int, rs: list[dict[str, Any]] = rs) -> float:
            return float(statistics.median(r[key][i] for r in rs))

        lines.append(
            f"| {c} | {sum(r['seconds'] for r in rs):.0f} | {hz[c]:.2f} | {100 * (hz[c] / hz['none'] - 1):+.1f} % "
            f"| {100 * (hz[c] / hz['decoy'] - 1):+.1f} % "
            f"| {med('period_ms', 0):.1f} / {med('period_ms', 1):.1f} / {max(r['period_ms'][2] for r in rs):.0f} "
            f"| {med('on_tick_us', 0):.0f} / {med('on_tick_us', 1):.0f} / {max(r['on_tick_us'][2] for r in rs)} "
            f"| {med('sleep_late_ms', 0):.2f} / {med('sleep_late_ms', 1):.2f} / "
            f"{max(r['sleep_late_ms'][2] for r in rs):.1f} "
            f"| {statistics.median(r['main_cpu_ms_per_tick'] for r in rs):.2f} "
            f"| {statistics.median(r['server_cpu_pct'] for r in rs):.1f} "
            f"| {statistics.median(r['swarm_cpu_pct'] for r in rs):.0f} |")
    ratios = sorted(100 * (p / d - 1) for r in sel for p, d in zip(r["conditions"]["pilot"]["turn_hz"],
                                                                   r["conditions"]["decoy"]["turn_hz"], strict=False)
                    if d)
    if ratios:
        q1, q2, q3 = (ratios[int(q * (len(ratios) - 1))] for q in (0.25, 0.5, 0.75))
        lines += ["", f"Turn by turn (the n-th pilot turn against the n-th decoy turn, {len(ratios)} pairs): the "
                  f"pilot's rate {q2:+.1f} % (median; quartiles {q1:+.1f} %, {q3:+.1f} %) of the decoy's."]
    cost, own = (100 * (hz["pilot"] / hz[c] - 1) for c in ("none", "decoy"))
    lines += ["", f"Goal, the loop's rate within 5 % of no viewers: {cost:+.1f} % with the 300 clients on the "
              f"pilot's view ({'met' if abs(cost) <= 5 else 'missed'}), of which the view's own "
              f"(against the same crowd on the decoy) {own:+.1f} %; {sum(r['tracebacks'] for r in sel)} tracebacks."]
    return [*lines, ""]


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="liveview_cost")
    p.add_argument("--flights", type=int, default=2, help="flights per mode")
    p.add_argument("--seconds", type=float, default=50.0, help="simulated seconds per flight")
    p.add_argument("--phase", type=float, default=2.0, help="seconds per turn")
    p.add_argument("--modes", choices=("paced", "unpaced", "both"), default="both",
                   help="paced to real time, unpaced (as fast as the machine allows: the more sensitive), or both")
    p.add_argument("--switch-interval", type=float, help="sys.setswitchinterval for the pilot's process (s)")
    p.add_argument("--realtime", type=int, metavar="PRIORITY",
                   help="the pilot's process (its loop, the server thread, the virtual drone) at SCHED_FIFO PRIORITY: "
                        "the other engineers' processes and the crowd no longer take its processor, only its own "
                        "threads can (the view's own cost)")
    p.add_argument("--decoy", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args(argv)
    if args.decoy:
        return decoy()
    executable = os.environ.get("PILOT_VIRTUAL_DRONE")
    if args.switch_interval:
        sys.setswitchinterval(args.switch_interval)
    if args.realtime:  # before any thread or child: they inherit it (the swarms and the decoy are set back)
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(args.realtime))
        except PermissionError:
            print("liveview_cost: SCHED_FIFO needs root or CAP_SYS_NICE: measured at the ordinary priority",
                  file=sys.stderr)
            args.realtime = None
    load0 = os.getloadavg()
    decoy_proc = start(["bench.sidechan.liveview_cost", "--decoy"])
    assert decoy_proc.stdout is not None
    decoy_url = decoy_proc.stdout.readline().strip()
    runs: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    try:
        for n in range(args.flights):
            for paced in {"paced": (True,), "unpaced": (False,), "both": (True, False)}[args.modes]:
                run = one_flight(decoy_url, executable, args.seconds, paced, args.phase, seed=53 + n)
                runs.append(run)
                print(json.dumps(run), flush=True)
    finally:
        decoy_report = finish(decoy_proc)
    minutes = (time.perf_counter() - t0) / 60
    text = "\n".join([
        "", "## The view's cost to the loop, apart from the crowd's cost to the machine "
        "(`python -m bench.sidechan.liveview_cost`)", "",
        f"The same simulated flight (ahead, seed 2, {args.seconds:g} s), {args.flights} times per mode, each flight "
        f"in turns of {args.phase:g} s: the 300-client swarm on the pilot's live view (pilot), the same swarm on a "
        "decoy live view in another process (decoy), or no swarm running (none); the first "
        f"{SETTLE_S:g} s of a turn is left out. pilot against decoy is what serving costs the loop; decoy against "
        "none is what the crowd's processes cost 2 shared cores. "
        f"{f'The pilot at SCHED_FIFO {args.realtime}. ' if args.realtime else ''}Switch interval "
        f"{sys.getswitchinterval() * 1000:g} ms. Load average (1, 5, 15 min) {' '.join(f'{x:.1f}' for x in load0)} "
        f"at the start, {' '.join(f'{x:.1f}' for x in os.getloadavg())} at the end; {minutes:.1f} min in all. "
        f"Decoy process: {json.dumps(decoy_report)}.", "",
        *summary(runs, True), *summary(runs, False),
        f"Pilot process: peak RSS {max(r['rss_peak_mb'] for r in runs):.0f} MB (the largest in turns of each "
        f"condition: {rss_by_condition(runs)} MB),"
        " at most "
        f"{max(r['peak_connections'] for r in runs)} sockets and {max(r['peak_viewers'] for r in runs)} viewers; "
        "the server thread's longest stretch of processor time between two waits (encoding included; the "
        "interpreter lock is released in OpenCV's calls and handed over every switch interval on request) "
        f"{max(r['server_longest_busy_ms'] for r in runs):.1f} ms; "
        f"{sum(r['tracebacks'] for r in runs)} tracebacks, {sum(r['log_lines'] for r in runs)} log lines from "
        "the server.", "",
        "Each flight:", "", "```", *(json.dumps(r) for r in runs), "```", ""])
    print(text)
    if not args.no_write:
        with (HERE / "RESULTS.md").open("a") as f:
            f.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
