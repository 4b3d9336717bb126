"""Benchmarks of the codec's wheel and of the live view (``make bench-tools``), figures to bench/tools/RESULTS.md.

1. The standalone codec wheel (``pip wheel generated/python``): its size (goal: under 50 kB), and the time
   of ``import drone_protocol`` in a fresh venv holding only that wheel against ``import json`` in the same
   venv (goal: at most 2x). Whole interpreter runs in subprocesses, interleaved, median of many; reported
   both as whole-process ratios and as the increment over a bare ``python -c pass``, the stricter one.
2. The live view (``--serve``) on a simulated flight against the virtual drone, headless Chromium as the
   viewer: the pilot loop's rate without ``--serve``, with it but nobody watching, and with a browser
   watching (goal: the rate drops by less than 5 %), flown unpaced (as fast as the machine goes, the
   harshest case) and paced to the wall clock (the real 20 Hz loop); and the latency from a frame's arrival
   in the pilot to the browser showing it (paced flight).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import venv
from collections.abc import Sequence
from pathlib import Path

import drone_protocol as dp

from pilot.app.liveview import LiveView
from pilot.app.observers import StopSwitch, WallClockPacing
from pilot.app.runner import Observer, Tick
from pilot.app.sim_flight import fly

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
WHEEL_GOAL_KB = 50.0
IMPORT_GOAL = 2.0
DROP_GOAL = 0.05


def codec_wheel(work: Path) -> Path:
    src = work / "codec"
    shutil.copytree(ROOT / "generated" / "python", src, ignore=shutil.ignore_patterns("__pycache__"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(work / "dist"), str(src)],
                   check=True, capture_output=True)
    (wheel,) = (work / "dist").glob("*.whl")
    return wheel


def import_times(python: Path, runs: int) -> dict[str, float]:
    """Median wall seconds of a whole interpreter run for each statement, interleaved run by run."""
    statements = {"pass": "pass", "json": "import json", "codec": f"import {dp.PROTOCOL_NAME}"}
    samples: dict[str, list[float]] = {k: [] for k in statements}
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONDONTWRITEBYTECODE")}
    for _ in range(3):  # warm the bytecode caches
        for code in statements.values():
            subprocess.run([str(python), "-c", code], check=True, env=env)
    for _ in range(runs):
        for name, code in statements.items():
            t0 = time.perf_counter()
            subprocess.run([str(python), "-c", code], check=True, env=env)
            samples[name].append(time.perf_counter() - t0)
    return {k: statistics.median(v) for k, v in samples.items()}


class Rate:
    """Ticks per wall second from the first tick to the last."""

    def __init__(self) -> None:
        self.times: list[float] = []

    def on_tick(self, tick: Tick) -> None:
        self.times.append(time.perf_counter())

    @property
    def hz(self) -> float:
        return (len(self.times) - 1) / (self.times[-1] - self.times[0]) if len(self.times) > 1 else 0.0


def flight_rate(
    mode: str, paced: bool, executable: str | None, browser: object, seconds: float
) -> tuple[float, list[float]]:
    """One simulated flight; returns the loop rate and, with a browser watching, its frame latencies (ms)."""
    rate = Rate()
    observers: list[Observer] = [rate]
    view = None
    if mode != "no --serve":
        view = LiveView("127.0.0.1", 0, StopSwitch())
        observers.append(view)
    if paced:  # last, as in the command line: the view gets each tick before the pacing sleep
        observers.append(WallClockPacing())
    latencies: list[float] = []
    try:
        if mode == "browser watching":
            assert view is not None
            browser.get(view.url)  # type: ignore[attr-defined]
            browser.execute_script("window.liveView.latencies.length = 0")  # type: ignore[attr-defined]
        flight = fly("ahead", 2, executable=executable, observers=observers, max_seconds=seconds)
        if not flight.success or flight.error:  # a rate of a failed flight measures nothing
            raise SystemExit(f"bench-tools: the flight failed ({mode}): {flight.summary()} {flight.error or ''}")
        if mode == "browser watching":
            latencies = list(browser.execute_script("return window.liveView.latencies"))  # type: ignore[attr-defined]
            browser.get("about:blank")  # type: ignore[attr-defined]
    finally:
        if view is not None:
            view.close()
    return rate.hz, latencies


def chromium(profile: Path) -> object:
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    options = Options()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={profile}"):
        options.add_argument(flag)
    return webdriver.Chrome(options=options, service=Service(executable_path="/usr/bin/chromedriver"))


def pct(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="fewer repetitions")
    p.add_argument("--no-write", action="store_true", help="print only, do not write RESULTS.md")
    args = p.parse_args(argv)
    executable = os.environ.get("PILOT_VIRTUAL_DRONE")
    runs, flights = (15, 1) if args.quick else (61, 3)
    lines = [f"# Codec wheel and live view benchmarks\n\n{platform.machine()}, {os.cpu_count()} cores, "
             f"Python {platform.python_version()}; `make bench-tools` writes this file.\n"]

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        wheel = codec_wheel(work)
        size_kb = wheel.stat().st_size / 1000
        env_dir = work / "venv"
        venv.EnvBuilder(with_pip=True).create(env_dir)
        python = env_dir / "bin" / "python"
        subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-index", str(wheel)], check=True)
        t = import_times(python, runs)
        whole = t["codec"] / t["json"]
        extra_codec, extra_json = t["codec"] - t["pass"], t["json"] - t["pass"]
        increment = extra_codec / extra_json if extra_json > 0 else float("inf")
        lines += [
            "## The standalone codec wheel\n",
            "| figure | value | goal | met |", "|---|---|---|---|",
            f"| wheel size ({wheel.name}) | {size_kb:.1f} kB | < {WHEEL_GOAL_KB:g} kB | "
            f"{'yes' if size_kb < WHEEL_GOAL_KB else 'NO'} |",
            f"| `python -c 'import {dp.PROTOCOL_NAME}'` vs `'import json'`, whole process | "
            f"{t['codec'] * 1000:.1f} ms vs {t['json'] * 1000:.1f} ms: {whole:.2f}x | <= {IMPORT_GOAL:g}x | "
            f"{'yes' if whole <= IMPORT_GOAL else 'NO'} |",
            f"| the imports alone (minus `python -c pass`, {t['pass'] * 1000:.1f} ms) | "
            f"{extra_codec * 1000:.2f} ms vs {extra_json * 1000:.2f} ms: {increment:.2f}x | <= {IMPORT_GOAL:g}x | "
            f"{'yes' if increment <= IMPORT_GOAL else 'NO'} |",
            f"\nMedian of {runs} interleaved interpreter runs each, in a fresh venv holding only the wheel.\n",
        ]

    profile = Path(tempfile.mkdtemp(prefix="bench-chromium-"))
    browser = chromium(profile)
    results: dict[tuple[str, bool], list[float]] = {}
    latencies: list[float] = []
    try:
        for paced in (False, True):
            for _ in range(flights):
                for mode in ("no --serve", "nobody watching", "browser watching"):
                    hz, lat = flight_rate(mode, paced, executable, browser, 60.0)
                    results.setdefault((mode, paced), []).append(hz)
                    if paced:
                        latencies += lat
                    print(f"{'paced' if paced else 'unpaced'} {mode}: {hz:.1f} Hz", flush=True)
    finally:
        browser.quit()  # type: ignore[attr-defined]
        shutil.rmtree(profile, ignore_errors=True)
    lines += ["## The live view\n",
              f"Simulated flight `ahead` seed 2 against the virtual drone, {flights} flight(s) per cell, median "
              "loop rate (ticks per wall second); the viewer is headless Chromium showing the page.\n",
              "| loop | no --serve | --serve, nobody watching | --serve, browser watching | drop when watched | "
              f"goal < {DROP_GOAL:.0%} |", "|---|---|---|---|---|---|"]
    for paced in (False, True):
        base, idle, watched = (statistics.median(results[(m, paced)])
                               for m in ("no --serve", "nobody watching", "browser watching"))
        drop = 1 - watched / base
        lines.append(f"| {'paced to the wall clock (20 Hz)' if paced else 'unpaced (as fast as it goes)'} | "
                     f"{base:.1f} Hz | {idle:.1f} Hz | {watched:.1f} Hz | {drop:.1%} | "
                     f"{'yes' if drop < DROP_GOAL else 'NO'} |")
    if latencies:
        lines.append(f"\nFrame latency, arrival in the pilot to shown in the browser (paced flights, "
                     f"{len(latencies)} frames): median {statistics.median(latencies):.0f} ms, "
                     f"95th percentile {pct(latencies, 0.95):.0f} ms, max {max(latencies):.0f} ms "
                     "(the browser's Date.now() against the pilot's time.time(), 1 ms resolution).\n")
    text = "\n".join(lines) + "\n"
    print(text)
    if not args.no_write:
        (HERE / "RESULTS.md").write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
