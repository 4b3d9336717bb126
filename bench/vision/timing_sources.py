"""Cost per frame on every photo source, red-heavy ones included (``PYTHONPATH=.:bench/vision .venv/bin/python
bench/vision/timing_sources.py``, figures in RESULTS.md): the colour detector with its default budget
(``vision.budget_ms``) against the floor any colour detector pays (cvtColor + inRange), one thread, per photo and
overall, at 320x240 and 640x480. Half the views hold a ball, half have sensor noise (the smoothed look's trigger).
Wall time on a shared machine includes other processes' turns; CPU time (the thread's) does not: both are given.
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable

import cv2
import numpy as np
import vision_eval as ve
import vision_imagery as vi

from pilot.vision.hsv.detector import HsvBlobDetector

FLOOR_RANGE = (np.array((0, 120, 70), np.uint8), np.array((8, 255, 255), np.uint8))
SOURCES = vi.TUNING + vi.HELD_OUT + vi.VALIDATION + vi.BENCH


def frames(rng: np.random.Generator, names: tuple[str, ...], n: int, size: tuple[int, int]) -> list[vi.Image]:
    """``n`` views of ``names`` at ``size``: every other one with a ball 16-80 px, half of each kind noisy."""
    out = []
    for k in range(n):
        img = vi.target_sample(rng, names, "clean", "ball", (16, 80)).image if k % 2 else vi.view(rng, names)
        if k % 4 >= 2:
            img = np.clip(img.astype(np.int16) + rng.normal(0, 12, img.shape), 0, 255).astype(np.uint8)
        out.append(np.asarray(cv2.resize(img, size), np.uint8))
    return out


def clocked(fn: Callable[[vi.Image], object], img: vi.Image) -> tuple[float, float]:
    w0, c0 = time.perf_counter(), time.thread_time()
    fn(img)
    return 1e3 * (time.perf_counter() - w0), 1e3 * (time.thread_time() - c0)


def floor(img: vi.Image) -> object:
    return cv2.inRange(cv2.cvtColor(img, cv2.COLOR_BGR2HSV), FLOOR_RANGE[0], FLOOR_RANGE[1])


def pct(v: list[float], q: float) -> float:
    s = sorted(v)
    return s[min(len(s) - 1, int(q * len(s)))]


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, views=(100, "views per photo at 320x240"), seed=(99, "seed"))
    cv2.setNumThreads(1)
    rng = np.random.default_rng(args.seed)
    print("| photo | floor median (ms) | HSV median, wall / CPU (ms) | HSV p99, wall / CPU (ms) | frames cut short |")
    print("|---|---|---|---|---|")
    every: dict[tuple[int, int], tuple[list[float], list[float], list[float]]] = {}
    for size, names, n in (((320, 240), SOURCES, args.views), ((640, 480), SOURCES, max(4, args.views // 5))):
        det = HsvBlobDetector()
        fl, wall, cpu = every.setdefault(size, ([], [], []))
        for name in names:
            f0, w0, c0, cut = [], [], [], 0
            for img in frames(rng, (name,), n, size):
                f0.append(clocked(floor, img)[0])
                w, c = clocked(det.candidates, img)
                w0.append(w)
                c0.append(c)
                cut += det.cut_short
            fl += f0
            wall += w0
            cpu += c0
            if size == (320, 240):
                print(f"| {name} | {statistics.median(f0):.3f} | {statistics.median(w0):.2f} / "
                      f"{statistics.median(c0):.2f} | {pct(w0, 0.99):.2f} / {pct(c0, 0.99):.2f} | {cut} of {n} |",
                      flush=True)
    print()
    print("| frame | floor median (ms) | HSV median, wall / CPU (ms) | ratio (wall) | HSV p99, wall / CPU (ms) |")
    print("|---|---|---|---|---|")
    for (w, h), (fl, wall, cpu) in every.items():
        print(f"| {w}x{h} | {statistics.median(fl):.3f} | {statistics.median(wall):.2f} / {statistics.median(cpu):.2f} "
              f"| {statistics.median(wall) / statistics.median(fl):.2f}x | {pct(wall, 0.99):.2f} / "
              f"{pct(cpu, 0.99):.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
