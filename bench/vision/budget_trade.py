"""What the per-frame budget (``vision.budget_ms``) costs the colour detector: recall and detections on empty views
of the tuning sources (packaged.py; never the held-out ones) with the budget's clock on the thread's CPU time (what
the detector itself spends, whatever the shared machine's load), against the budget frozen (the rules alone), and
each budget's CPU time per frame (median, p99). ``PYTHONPATH=.:bench/vision .venv/bin/python
bench/vision/budget_trade.py``; figures in bench/vision/HISTORY.md.
"""

from __future__ import annotations

import statistics
import sys
import time

import cv2
import packaged as pk
import timing_sources as ts
import vision_eval as ve
import vision_imagery as vi

from pilot.common.config import ControllerConfig, HsvConfig, VisionConfig
from pilot.vision.hsv.detector import HsvBlobDetector

BUDGETS = (2.0, 3.0, 4.0, 6.0, 12.5, 1e9)


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, views=(60, "target views per condition"), seed=(31, "seed"))
    cv2.setNumThreads(1)
    names = tuple(n for s in pk.SOURCES if s.split == "tuning" for n in pk.views_of(s))
    views = ve.samples(names, args.seed, args.views, 5 * args.views, 0, "ball", (10.0, 120.0), vi.CONDITIONS)
    thr = ControllerConfig().acquire_confidence
    print("| budget (ms, CPU) | recall, >= 16 px, all conditions | empty views detected | median CPU (ms) | "
          "p99 CPU (ms) |\n|---|---|---|---|---|")
    for b in BUDGETS:
        det = HsvBlobDetector(HsvConfig(), VisionConfig(budget_ms=min(b, 1000.0)), 60.0,
                              time.thread_time if b < 1e9 else (lambda: 0.0))
        cpu: list[float] = []

        def timed(img: vi.Image, det: HsvBlobDetector = det, cpu: list[float] = cpu) -> list[object]:
            t0 = time.thread_time()
            out = det.candidates(img)
            cpu.append(1e3 * (time.thread_time() - t0))
            return out  # type: ignore[return-value]

        records = ve.run(timed, views)  # type: ignore[arg-type]
        targets = [r for r in records if r.kind == "target" and r.size >= 16]
        empty = [r for r in records if r.kind == "empty"]
        print(f"| {'none' if b >= 1e9 else b} | {sum(ve.correct(r, thr) for r in targets)} of {len(targets)} | "
              f"{sum(ve.detected(r, thr) for r in empty)} of {len(empty)} | {statistics.median(cpu):.2f} | "
              f"{ts.pct(cpu, 0.99):.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
