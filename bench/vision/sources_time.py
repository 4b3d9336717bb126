"""Cost per frame of the colour detector on each set of packaged stills (sources_run.py): its default budget
(``vision.budget_ms``, on the thread's CPU clock) as the pilot runs it, against the cvtColor+inRange floor measured
in turn on the same frames, at 320x240 per set and at 640x480 over all sets. Wall time on a shared machine includes
other processes' turns; the thread's CPU time does not: both are given, the goals read on CPU time.
"""

from __future__ import annotations

import statistics

import cv2
import numpy as np
import timing_sources as ts

from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.verify import VerifiedSource, shipped

SEED = 99


def measure(names: tuple[str, ...], n: int, size: tuple[int, int], rng: np.random.Generator
            ) -> tuple[list[float], list[float], list[float], list[float], int]:
    """Floor wall and CPU, detector wall and CPU (ms per frame; its candidates through the learned verifier, as
    the pilot runs it), and the frames the budget cut short."""
    det = VerifiedSource(HsvBlobDetector(), shipped())
    fw, fc, dw, dc, cut = [], [], [], [], 0
    for img in ts.frames(rng, names, n, size):
        w, c = ts.clocked(ts.floor, img)
        fw.append(w)
        fc.append(c)
        w, c = ts.clocked(det.candidates, img)
        dw.append(w)
        dc.append(c)
        cut += det.cut_short
    return fw, fc, dw, dc, cut


def row(label: str, m: tuple[list[float], list[float], list[float], list[float], int]) -> str:
    _, fc, dw, dc, cut = m
    med = statistics.median
    return (f"| {label} | {med(fc):.3f} | {med(dw):.2f} / {med(dc):.2f} | {med(dc) / med(fc):.2f}x | "
            f"{ts.pct(dw, 0.99):.2f} / {ts.pct(dc, 0.99):.2f} | {max(dc):.2f} | {cut} of {len(dc)} |")


def table(sets: list[tuple[str, tuple[str, ...]]], n: int) -> list[str]:
    cv2.setNumThreads(1)
    rng = np.random.default_rng(SEED)
    out = ["| set | floor median, CPU (ms) | HSV median, wall / CPU (ms) | ratio (CPU medians) | HSV p99, wall / CPU "
           "(ms) | HSV slowest, CPU (ms) | frames cut short |", "|---|---|---|---|---|---|---|"]
    every: dict[tuple[int, int], list[tuple[list[float], list[float], list[float], list[float], int]]] = {}
    for size, k in (((320, 240), n), ((640, 480), max(4, n // 5))):
        for label, names in sets:
            m = measure(names, k, size, rng)
            every.setdefault(size, []).append(m)
            if size == (320, 240):
                out.append(row(label, m))
    for (w, h), ms in every.items():
        fw, fc = [x for m in ms for x in m[0]], [x for m in ms for x in m[1]]
        dw, dc = [x for m in ms for x in m[2]], [x for m in ms for x in m[3]]
        out.append(row(f"all sets, {w}x{h}", (fw, fc, dw, dc, sum(m[4] for m in ms))))
    return out


def main(argv: list[str] | None = None) -> int:
    """The cost table alone, every set of sources_run.py (``PYTHONPATH=.:bench/vision .venv/bin/python
    bench/vision/sources_time.py --views 200``): a change's cost measured without the accuracy runs."""
    import sources_run
    import vision_eval as ve

    args = ve.counts_args(main.__doc__, argv, views=(200, "views timed per set at 320x240"))
    print("\n".join(table([(s.label, s.names) for s in sources_run.sets() if s.names], args.views)))
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(main())
