"""Lossy-link bench (``make bench-lossy``, or ``python -m bench.lossy.run``): the pilot flies the simulated
room against the virtual drone through a proxy (bench/lossy/proxy.py) that drops, inserts and flips bytes, and
each flight is measured on the virtual drone's outputs against the pilot's state: laser-on outside the fire
state, arming-state disagreements, flights completed. bench/lossy/README.md defines each figure and its goal;
``--integrity crc8`` flies a crc8 copy of the spec in a child process. Writes bench/lossy/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import drone_protocol as dp

from bench.lossy.proxy import LossyProxy
from bench.lossy.substitution import BEGIN as SUBSTITUTION
from pilot.app.runner import run
from pilot.common.config import PilotConfig
from pilot.control.controller import Controller
from pilot.link.serial_link import Link, keepalive_ms
from pilot.sim.room import SCENARIOS, make_scenario
from pilot.sim.virtual import Change, Outputs, VirtualDrone
from pilot.sim.world import BOOT_MS, SimWorld
from pilot.vision.detect import make_detector

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
RATES = (0.0, 0.01, 0.02, 0.10)
DISAGREE_LIMIT_MS = 200



@dataclass
class FlightFigures:
    scenario: str
    seed: int
    rate: float
    integrity: str
    completed: bool = False  # reached and lit, and ended confirmed safe
    lit: bool = False
    ended_safe: bool = False
    laser_outside_ms: int = 0
    laser_episodes: int = 0
    laser_excess_ms: int = 0
    disagreements: int = 0
    disagree_longest_ms: int = 0
    disagree_over_limit: int = 0
    damages: int = 0
    frames_sent: int = 0
    sim_s: float = 0.0
    reason: str = ""
    episodes: list[tuple[int, int, int]] = field(default_factory=list)  # start, ms, damages


class Meter:
    """Follows the drone's outputs ms by ms through each step, against the pilot's state during that step."""

    def __init__(self, proxy: LossyProxy, tick_ms: int, figures: FlightFigures) -> None:
        self.proxy, self.tick_ms, self.f = proxy, tick_ms, figures
        self.controller: Controller | None = None
        self.outputs: Outputs | None = None
        self._laser_start: int | None = None
        self._disagree_start: int | None = None

    def on_step(self, t0: int, t1: int, changes: list[Change]) -> None:
        c = self.controller
        want = c.want_laser if c is not None else False
        view = c.drone.armed if c is not None else None
        t = t0
        for change in [*changes, None]:
            end = t1 if change is None else max(t0, min(t1, change.t_ms))
            if self.outputs is not None and end > t:
                self._segment(t, end, self.outputs, want, view)
            t = end
            if change is not None:
                self.outputs = change.outputs

    def _segment(self, a: int, b: int, out: Outputs, want: bool, view: bool | None) -> None:
        if out.laser and not want:
            self.f.laser_outside_ms += b - a
            if self._laser_start is None:
                self._laser_start = a
        else:
            self._end_laser(a)
        if view is not None and view != out.armed:
            if self._disagree_start is None:
                self._disagree_start = a
        else:
            self._end_disagree(a)

    def _end_laser(self, t: int) -> None:
        if self._laser_start is None:
            return
        start, self._laser_start = self._laser_start, None
        hits = sum(1 for d in self.proxy.damages if start - self.tick_ms <= d.t_ms <= t)
        allowed = self.tick_ms * (1 + hits)
        self.f.laser_episodes += 1
        self.f.laser_excess_ms += max(0, t - start - allowed)
        self.f.episodes.append((start, t - start, hits))

    def _end_disagree(self, t: int) -> None:
        if self._disagree_start is None:
            return
        length, self._disagree_start = t - self._disagree_start, None
        self.f.disagreements += 1
        self.f.disagree_longest_ms = max(self.f.disagree_longest_ms, length)
        self.f.disagree_over_limit += length > DISAGREE_LIMIT_MS

    def finish(self, t: int) -> None:
        self._end_laser(t)
        self._end_disagree(t)


def fly(job: tuple[str, int, float, str, str]) -> FlightFigures:
    scenario_name, seed, rate, integrity, exe = job
    cfg = PilotConfig()
    figures = FlightFigures(scenario_name, seed, rate, integrity)
    tick_ms = round(1000.0 / cfg.link.rate_hz)
    vd = VirtualDrone(exe)
    proxy = LossyProxy(vd.pty, rate, seed=seed * 1000 + round(rate * 1000))
    meter = Meter(proxy, tick_ms, figures)
    direct_step = vd.step

    def lossy_step(ms: int, sent: int | None = None) -> list[Change]:
        t0 = vd.t_ms
        proxy.up(t0)
        changes = direct_step(ms, sent)
        proxy.down(vd.t_ms)
        meter.on_step(t0, vd.t_ms, changes)
        return changes

    vd.step = lossy_step  # type: ignore[method-assign]
    try:
        with SimWorld(make_scenario(scenario_name, seed), vd, tick_ms=tick_ms) as world:
            link = Link(proxy.path, clock=world.now, on_open=lambda: world.advance(BOOT_MS),
                        ready_clock=time.monotonic, ready_sleep=time.sleep, reconnect_s=cfg.link.reconnect_s)
            with link:
                proxy.enabled = True
                controller = Controller(cfg.controller, clock=world.now)
                meter.controller = controller
                result = run(world.camera(), make_detector(cfg), controller, link, world, max_seconds=60.0,
                             keepalive_ms=keepalive_ms(cfg.link.keepalive_fraction))
                # the firmware's failsafe after the pilot stops: a second of silence, still measured
                world.advance(dp.FAILSAFE_TIMEOUT_MS + tick_ms)
            meter.finish(vd.t_ms)
            score = world.score
            figures.lit = score.longest_on_target_ms >= cfg.controller.fire_ms and result.fired  # strict: unbroken
            figures.ended_safe = result.safe and not world.outputs.laser and not world.outputs.armed
            figures.completed = figures.lit and figures.ended_safe
            figures.damages = len(proxy.damages)
            figures.frames_sent = len(link.sent)
            figures.sim_s = world.now()
            figures.reason = result.reason
    finally:
        proxy.close()
    return figures


def campaign(exe: str, integrity: str, seeds: int, processes: int,
             rates: tuple[float, ...] = RATES) -> list[FlightFigures]:
    jobs = [(SCENARIOS[s % len(SCENARIOS)], 1 + s, rate, integrity, exe) for rate in rates for s in range(seeds)]
    ctx = multiprocessing.get_context("spawn")  # a forked child would inherit MuJoCo's GL context
    with ctx.Pool(processes) as pool:
        return pool.map(fly, jobs, chunksize=1)


def crc8_campaign(seeds: int, processes: int, work: Path, rates: tuple[float, ...] = RATES) -> list[FlightFigures]:
    """Regenerate a crc8 copy of the spec, build its virtual drone, fly in a child that imports that codec."""
    spec = (REPO / "spec" / "drone.yaml").read_text(encoding="utf-8")
    assert "  integrity: none\n" in spec, "the shipped spec's integrity line moved"
    (work / "drone.yaml").write_text(spec.replace("  integrity: none\n", "  integrity: crc8\n"), encoding="utf-8")
    out = work / "generated"
    py = sys.executable
    subprocess.run([py, "-m", "generator", "--spec", str(work / "drone.yaml"), "--out", str(out)], cwd=REPO,
                   check=True, capture_output=True)
    subprocess.run(["make", "-s", "firmware-host", f"FW_BUILD={work / 'fw'}",
                    f"DRONE_PROTOCOL_DIR={out / 'arduino' / 'DroneProtocol'}"], cwd=REPO, check=True,
                   capture_output=True)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(out / "python"), str(REPO)]))
    child = subprocess.run([py, "-m", "bench.lossy.run", "--child", "--virtual-drone", str(work / "fw" / "host" /
                            "virtual_drone"), "--seeds", str(seeds), "--processes", str(processes),
                            "--rates", ",".join(f"{r:g}" for r in rates)],
                           cwd=REPO, env=env, check=True, capture_output=True, text=True)
    return [FlightFigures(**{**d, "episodes": [tuple(e) for e in d["episodes"]]}) for d in json.loads(child.stdout)]


def summarise(rows: list[FlightFigures]) -> list[dict[str, Any]]:
    table = []
    for integrity in sorted({r.integrity for r in rows}, key=lambda m: m != "none"):
        for rate in sorted({r.rate for r in rows}):
            sel = [r for r in rows if r.integrity == integrity and r.rate == rate]
            if not sel:
                continue
            table.append({
                "integrity": integrity, "rate": rate, "flights": len(sel),
                "completed": sum(r.completed for r in sel), "ended_safe": sum(r.ended_safe for r in sel),
                "damages": sum(r.damages for r in sel),
                "laser_outside_ms": sum(r.laser_outside_ms for r in sel),
                "laser_episodes": sum(r.laser_episodes for r in sel),
                "laser_excess_ms": sum(r.laser_excess_ms for r in sel),
                "disagreements": sum(r.disagreements for r in sel),
                "disagree_longest_ms": max(r.disagree_longest_ms for r in sel),
                "disagree_over_limit": sum(r.disagree_over_limit for r in sel),
            })
    return table


def markdown(table: list[dict[str, Any]], seeds: int, took_s: float) -> str:
    lines = [
        "# Lossy-link bench (make bench-lossy)",
        "",
        f"{seeds} simulated flights per row (scenarios {', '.join(SCENARIOS)} in turn, seeds 1..{seeds}), the pilot "
        "and the virtual drone joined by a pty proxy that drops, inserts or flips each byte (a third each) with the "
        "given probability, both directions. Laser-on outside the pilot's fire state is allowed one reply round "
        f"trip (one {1000 // 20} ms tick) per episode plus one per damaged byte during it; \"excess\" is what is left "
        f"(goal 0 ms). Disagreements: the pilot's armed view (from the replies' status) against the firmware's "
        f"(goal: none over {DISAGREE_LIMIT_MS} ms). Completed: reached and lit the target, and ended with the drone "
        "confirming laser off and disarmed.",
        "",
        f"Machine: {platform.machine()}, Python {platform.python_version()}, {took_s:.0f} s for the whole run.",
        "",
        "| integrity | loss/byte | completed | ended safe | damaged bytes | laser-on outside fire (ms, episodes) "
        "| excess beyond allowance (ms) | arming disagreements | longest (ms) | over 200 ms |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in table:
        lines.append(
            f"| {row['integrity']} | {row['rate']:.0%} | {row['completed']}/{row['flights']} | "
            f"{row['ended_safe']}/{row['flights']} | {row['damages']} | {row['laser_outside_ms']} "
            f"({row['laser_episodes']}) | {row['laser_excess_ms']} | {row['disagreements']} | "
            f"{row['disagree_longest_ms']} | {row['disagree_over_limit']} |"
        )
    return "\n".join(lines) + "\n"


def _rates(text: str) -> tuple[float, ...]:
    try:
        rates = tuple(float(r) for r in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not comma-separated numbers: {text!r}") from None
    if not all(0.0 <= r < 1.0 for r in rates):
        raise argparse.ArgumentTypeError(f"a loss rate is a probability under 1: {text!r}")
    return rates


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", type=int, default=8, help="flights per loss rate (default 8)")
    p.add_argument("--processes", type=int, default=2)
    p.add_argument("--virtual-drone", default=str(REPO / "firmware" / "build" / "host" / "virtual_drone"))
    p.add_argument("--rates", type=_rates, default=RATES, help="loss rates per byte, comma-separated "
                   "(default 0,0.01,0.02,0.1)")
    p.add_argument("--integrity", choices=("none", "crc8", "both"), default="both")
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args()
    if args.child:
        child_rows = campaign(args.virtual_drone, dp.INTEGRITY, args.seeds, args.processes, args.rates)
        print(json.dumps([asdict(r) for r in child_rows]))
        return
    started = time.monotonic()
    rows: list[FlightFigures] = []
    if args.integrity in ("none", "both"):
        rows += campaign(args.virtual_drone, dp.INTEGRITY, args.seeds, args.processes, args.rates)
    if args.integrity in ("crc8", "both"):
        with tempfile.TemporaryDirectory(prefix="lossy-crc8-") as work:
            rows += crc8_campaign(args.seeds, args.processes, Path(work), args.rates)
    table = summarise(rows)
    text = markdown(table, args.seeds, time.monotonic() - started)
    print(text)
    worst = [(r.integrity, r.rate, r.scenario, r.seed, r.reason) for r in rows if not r.completed]
    print("not completed:", worst)
    if not args.no_write:
        results = HERE / "RESULTS.md"
        old = results.read_text(encoding="utf-8") if results.exists() else ""
        kept = old[old.find(SUBSTITUTION):] if SUBSTITUTION in old else ""  # substitution.py's section
        results.write_text(text + ("\n" + kept if kept else ""), encoding="utf-8")


if __name__ == "__main__":
    main()
