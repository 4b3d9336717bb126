"""The frame budget's clock, wall time against the thread's CPU time, in the same run on the same frames: the cost
per frame (the thread's CPU time, median and p99) and the frames cut short by each, on the tuning sources' timing
views at 320x240 (sources_time.py's kind: half with a ball, half noisy; never the held-out sources). The two
detectors are called in turn, the order alternating frame to frame. ``PYTHONPATH=.:bench/vision nice -n 15
.venv/bin/python bench/vision/budget_clock.py``; figures in bench/vision/HISTORY.md.
"""

from __future__ import annotations

import os
import statistics
import sys
import time

import cv2
import numpy as np
import packaged as pk
import timing_sources as ts
import vision_eval as ve

from pilot.common.config import HsvConfig, VisionConfig
from pilot.vision.hsv.detector import HsvBlobDetector

CLOCKS = (("wall", time.perf_counter), ("thread CPU", time.thread_time))


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, views=(100, "timing views per tuning source"), seed=(57, "seed"))
    cv2.setNumThreads(1)
    rng = np.random.default_rng(args.seed)
    budget = VisionConfig().budget_ms
    print(f"load average {os.getloadavg()[0]:.1f} at the start; budget {budget} ms")
    print("| source | clock | median CPU (ms) | p99 CPU (ms) | slowest CPU (ms) | p99 wall (ms) | frames cut short |")
    print("|---|---|---|---|---|---|---|")
    for s in pk.SOURCES:
        if s.split != "tuning":
            continue
        dets = [HsvBlobDetector(HsvConfig(), VisionConfig(), 60.0, clock) for _, clock in CLOCKS]
        cpu: list[list[float]] = [[] for _ in CLOCKS]
        wall: list[list[float]] = [[] for _ in CLOCKS]
        cut = [0 for _ in CLOCKS]
        for k, img in enumerate(ts.frames(rng, pk.views_of(s), args.views, (320, 240))):
            for i in (0, 1) if k % 2 else (1, 0):
                w, c = ts.clocked(dets[i].candidates, img)
                wall[i].append(w)
                cpu[i].append(c)
                cut[i] += dets[i].cut_short
        for i, (name, _) in enumerate(CLOCKS):
            print(f"| {s.name} | {name} | {statistics.median(cpu[i]):.2f} | {ts.pct(cpu[i], 0.99):.2f} | "
                  f"{max(cpu[i]):.2f} | {ts.pct(wall[i], 0.99):.2f} | {cut[i]} of {len(cpu[i])} |", flush=True)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
