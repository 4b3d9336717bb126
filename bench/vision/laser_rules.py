"""What the laser's steadiness rule (pilot/vision/gating.py) does on the tuning sources only (packaged.py; never the
held-out ones): jittered sequences of their photos through the whole pipeline, the gate replayed with the rule and
without, at 1, 2 and 3 confirming frames (the default is 3; fewer show the gate's exposure), centring and range
lifted on runs without the ball; and frame to frame, how much a ball's measured size and centre change.
``PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/laser_rules.py``; figures in bench/vision/HISTORY.md.
"""

from __future__ import annotations

import dataclasses
import math
import sys

import cv2
import packaged as pk
import vision_eval as ve
import vision_sequences as vs

import pilot.vision.budget as budget
from pilot.common.config import ControllerConfig
from pilot.vision.gating import STEADY_SIZE, Gate


def replay(seq: vs.Sequence, steadiness: bool, n: int) -> tuple[int, bool]:
    """Laser-on frames without the target, and whether a target run was confirmed on the ball."""
    cfg = dataclasses.replace(ControllerConfig(), confirm_frames=n)
    if seq.kind != "target":
        cfg = dataclasses.replace(cfg, fire_tolerance=1.0, fire_range_max_m=1e9)
    gate = Gate(cfg, steadiness)
    wrong, hit = 0, False
    for i, d in enumerate(seq.detections):
        gate.observe(d)
        if not gate.confirmed():
            continue
        on = seq.kind == "target" and math.hypot(d.cx - seq.truth[i][0], d.cy - seq.truth[i][1]) <= max(
            3.0, 0.3 * seq.size)
        wrong += not on
        hit = hit or on
    return wrong, hit


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, runs=(10, "target runs per condition and source"), seed=(41, "seed"))
    cv2.setNumThreads(1)
    budget.CLOCK = lambda: 0.0  # the rules alone, whatever the machine's load
    seqs: list[vs.Sequence] = []
    for i, s in enumerate(x for x in pk.SOURCES if x.split == "tuning"):
        seqs += vs.sequences(s.photos, args.seed + i, args.runs, 8 * args.runs, 2 * args.runs)
    targets = [s for s in seqs if s.kind == "target"]
    frames = sum(len(s.detections) for s in seqs)
    print(f"{len(targets)} target runs of {vs.TARGET_FRAMES} frames, {len(seqs) - len(targets)} runs without the "
          f"ball of {vs.NEGATIVE_FRAMES}; {frames} frames\n")
    print("| steadiness | N | laser-on frames without the target | target runs confirmed on the ball |")
    print("|---|---|---|---|")
    for steadiness in (False, True):
        for n in (1, 2, 3):
            out = [replay(s, steadiness, n) for s in seqs]
            hits = sum(h for s, (_, h) in zip(seqs, out, strict=True) if s.kind == "target")
            print(f"| {'on' if steadiness else 'off'} | {n} | {sum(w for w, _ in out)} of {frames} | {hits} of "
                  f"{len(targets)} ({100 * hits / len(targets):.1f} %) |")
    sizes, steps = changes(targets)
    print(f"\nA ball's frame-to-frame change ({len(sizes)} pairs of measured frames on it, acquired): size ratio "
          f"p99 {quantile(sizes, 0.99):.3f}, p99.9 {quantile(sizes, 0.999):.3f}, largest {max(sizes):.3f}; "
          f"step over size p99 {quantile(steps, 0.99):.3f}, largest {max(steps):.3f}; size ratio within "
          f"{STEADY_SIZE}: {100 * sum(r <= STEADY_SIZE for r in sizes) / len(sizes):.1f} %")
    return 0


def changes(targets: list[vs.Sequence]) -> tuple[list[float], list[float]]:
    """Size ratios (larger over smaller) and centre steps (over the larger size) between consecutive frames that
    both measure the ball with a confidence at or above the acquisition threshold."""
    th = ControllerConfig().acquire_confidence
    sizes, steps = [], []
    for s in targets:
        for i in range(1, len(s.detections)):
            a, b = s.detections[i - 1], s.detections[i]
            both = all(d.found and not d.predicted and d.confidence >= th and d.size > 0 and math.hypot(
                d.cx - s.truth[k][0], d.cy - s.truth[k][1]) <= max(3.0, 0.3 * s.size) for k, d in ((i - 1, a), (i, b)))
            if both:
                big, small = max(a.size, b.size), min(a.size, b.size)
                sizes.append(big / small)
                steps.append(math.hypot(a.cx - b.cx, a.cy - b.cy) / big)
    return sizes, steps


def quantile(v: list[float], q: float) -> float:
    return sorted(v)[min(len(v) - 1, int(q * len(v)))]


if __name__ == "__main__":
    sys.exit(main())
