"""Pilot benchmarks (``make bench-pilot``), one thread for OpenCV, figures to bench/pilot/RESULTS.md.

1. Detection per frame at 320x240 and 640x480: the whole HSV colour-blob pipeline (two hue ranges,
   opening, contours, moments) against the floor of ``cvtColor`` + one ``inRange`` on the same frame,
   as a ratio (target: at most 2x); the ArUco detector for reference.
2. Latency from a frame's arrival to its command's last byte written (and flushed) to the serial
   port: the real pilot loop flying the simulated room, the virtual drone on a pseudo-terminal.
3. Simulated flights per minute: the closed-loop flights, one process and a pool of two.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from pilot.config import HsvConfig
from pilot.detect import ArucoMarkerDetector, HsvBlobDetector
from pilot.runner import Tick
from pilot.sim.camera import CameraModel
from pilot.sim.flight import FlightJob, fly, fly_many
from pilot.sim.room import SCENARIOS, make_scenario
from pilot.sim.still import StillView

HERE = Path(__file__).resolve().parent


def time_per_call(fn: object, image: np.ndarray, repeat: int) -> float:
    """Median seconds per call over ``repeat`` calls, after a warm-up."""
    assert callable(fn)
    for _ in range(20):
        fn(image)
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(image)
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def frame_of(width: int, height: int) -> np.ndarray:
    """A simulated view with the target, its marker and distractors in it, two metres from the target."""
    sc = make_scenario("distractor", 3)
    view = StillView(sc, CameraModel(width, height))
    x, y, _ = sc.start
    tx, ty, tz = sc.target.position
    heading = float(np.arctan2(ty - y, tx - x))
    d = float(np.hypot(tx - x, ty - y))
    k = (d - 2.0) / d
    view.place(x + (tx - x) * k, y + (ty - y) * k, tz - 0.2, heading)
    img = view.render(0.0)
    view.close()
    return img


def bench_detection(repeat: int) -> list[str]:
    cv2.setNumThreads(1)
    cfg = HsvConfig()
    lo, hi = (np.array(v, np.uint8) for v in cfg.ranges[0])
    rows = [
        "| frame | cvtColor+inRange floor (ms) | HSV blob pipeline (ms) | ratio | ArUco (ms) |",
        "|---|---|---|---|---|",
    ]
    for w, h in ((320, 240), (640, 480)):
        img = frame_of(w, h)
        hsv_det = HsvBlobDetector(cfg)
        aruco = ArucoMarkerDetector()
        assert hsv_det.detect(img).found and aruco.detect(img).found

        def floor(image: np.ndarray) -> None:
            cv2.inRange(cv2.cvtColor(image, cv2.COLOR_BGR2HSV), lo, hi)

        t_floor = time_per_call(floor, img, repeat)
        t_pipe = time_per_call(hsv_det.detect, img, repeat)
        t_aruco = time_per_call(aruco.detect, img, max(50, repeat // 5))
        rows.append(
            f"| {w}x{h} | {t_floor * 1e3:.3f} | {t_pipe * 1e3:.3f} | {t_pipe / t_floor:.2f}x | {t_aruco * 1e3:.2f} |"
        )
    return rows


class LatencyProbe:
    def __init__(self) -> None:
        self.samples: list[float] = []

    def on_tick(self, tick: Tick) -> None:
        if tick.sent_t is not None:
            self.samples.append(tick.sent_t - tick.frame_t)


def bench_latency(seeds: int) -> list[str]:
    rows = ["| frame size | ticks with a command | median (ms) | p99 (ms) | max (ms) |", "|---|---|---|---|---|"]
    for w, h in ((320, 240), (640, 480)):
        probe = LatencyProbe()
        for seed in range(seeds):
            fly("distractor", seed, camera=CameraModel(w, h), observers=[probe])
        s = sorted(probe.samples)
        p99 = s[min(len(s) - 1, int(0.99 * len(s)))]
        rows.append(
            f"| {w}x{h} | {len(s)} | {statistics.median(s) * 1e3:.3f} | {p99 * 1e3:.3f} | {s[-1] * 1e3:.3f} |"
        )
    return rows


def bench_flights(seeds: int) -> list[str]:
    jobs = [FlightJob(name, seed) for name in SCENARIOS for seed in range(seeds)]
    rows = ["| processes | flights | simulated s | wall s | flights/min | sim speed-up |", "|---|---|---|---|---|---|"]
    for processes in (1, 2):
        t0 = time.perf_counter()
        results = fly_many(jobs, processes=processes)
        wall = time.perf_counter() - t0
        sim = sum(r.sim_seconds for r in results)
        ok = sum(r.success for r in results)
        assert ok >= 0.9 * len(results), f"only {ok}/{len(results)} flights succeeded"
        rows.append(
            f"| {processes} | {len(results)} | {sim:.0f} | {wall:.1f} | {len(results) / wall * 60:.0f} | "
            f"{sim / wall:.0f}x |"
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="fewer repetitions")
    p.add_argument("--no-write", action="store_true", help="print only, do not write RESULTS.md")
    args = p.parse_args(argv)
    repeat = 200 if args.quick else 2000
    seeds = 1 if args.quick else 3
    sections = [
        "# Pilot benchmarks",
        "",
        f"Machine: {platform.machine()}, {platform.processor() or 'cpu'}; Python {platform.python_version()}; "
        f"OpenCV {cv2.__version__}, one OpenCV thread; {os.cpu_count()} CPUs, load average "
        f"{os.getloadavg()[0]:.1f} at the start (other work on the machine makes the figures noisier). "
        "Generated by `make bench-pilot` (bench/pilot/run.py).",
        "",
        "## Detection per frame (median)",
        "",
        *bench_detection(repeat),
        "",
        "## Frame arrival to the command's last byte written and flushed (pilot loop, virtual drone on a pty)",
        "",
        *bench_latency(seeds),
        "",
        "## Simulated flights (closed loop, stepped clock; 7 scenarios x seeds)",
        "",
        *bench_flights(seeds),
        "",
    ]
    text = "\n".join(sections)
    print(text)
    if not args.no_write:
        (HERE / "RESULTS.md").write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
