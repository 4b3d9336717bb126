"""What each look of the colour-ball detector pays for, on the tuning sources only (packaged.py; never the held-out
ones): the detector with one look removed at a time (or several), recall per condition for balls from 16 px,
detections on empty and drawn-distractor views, and the CPU time per frame at 320x240 (median, p99; the budget's
clock frozen, so the rules alone are timed); ``--runs N`` adds the laser-on frames without the target on jittered
sequences (as laser_rules.py). ``PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/ablation.py [--only A,B]``;
figures in bench/vision/HISTORY.md. A look is removed by replacing it with what finding nothing returns.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from typing import Any

import cv2
import laser_rules as lr
import packaged as pk
import timing_sources as ts
import vision_eval as ve
import vision_imagery as vi
import vision_sequences as vs
from cv2.typing import MatLike

import pilot.vision.budget as budget
import pilot.vision.hsv.detector as hsv
from pilot.common.config import ControllerConfig
from pilot.vision.detection import Candidate

THRESHOLD = ControllerConfig().acquire_confidence


def _attrs(module_or_class: Any, **values: Any) -> Callable[[], Any]:
    """A context that sets attributes for its duration."""
    @contextmanager
    def patched() -> Iterator[None]:
        old = {k: getattr(module_or_class, k) for k in values}
        for k, v in values.items():
            setattr(module_or_class, k, v)
        try:
            yield
        finally:
            for k, v in old.items():
                setattr(module_or_class, k, v)
    return patched


def looks() -> dict[str, list[Callable[[], Any]]]:
    """Each removable look, as the patches that remove it (imported late: the detector's modules as they are)."""
    import pilot.vision.hsv.measure as measure
    import pilot.vision.hsv.refine as refine
    det, win = hsv.HsvBlobDetector, refine.WindowRefiner
    none: Callable[..., list[Any]] = lambda *a, **k: []  # noqa: E731
    return {
        "second": [_attrs(hsv, grown=lambda *a: None)],
        "noise": [_attrs(hsv, smoothed=lambda *a: None)],
        "rim": [_attrs(det, _rim_look=lambda self, found: found), _attrs(measure.BlobMeasure, _defer=lambda *a: None)],
        "circles": [_attrs(det, _circle_look=none)],
        "split": [_attrs(win, _split=none)],
        "colour_split": [_attrs(win, _colour_split=none)],
        "edges": [_attrs(win, _edge_split=none)],
        "inside": [_attrs(hsv, busy_inside=lambda *a: False)],
        "hollow": [_attrs(hsv, hollow=lambda *a: False)],
        "texture": [_attrs(hsv, textured=lambda *a: False), _attrs(measure, textured=lambda *a: False)],
        "core_colour": [_attrs(measure, core_saturation=lambda *a: a[-1], unclipped_hue=lambda *a: a[-1])],
        "half": [_attrs(hsv, HALF_TRY=10 ** 9)],
        "near": [_attrs(det, candidates_near=lambda self, *a: [])],
    }


def run(name: str, removed: list[str], views: list[vi.Sample], seqs: int, seed: int) -> str:
    table = looks()
    with ExitStack() as stack:
        for look in removed:
            for patch in table[look]:
                stack.enter_context(patch())
        det = hsv.HsvBlobDetector()
        cpu: list[float] = []

        def timed(img: MatLike) -> list[Candidate]:
            t0 = time.thread_time()
            out = det.candidates(img)
            cpu.append(1e3 * (time.thread_time() - t0))
            return out

        records = ve.run(timed, views)
        rows = {r.group: r.rate for r in ve.target_rows(records, THRESHOLD, 16.0)}
        empty = ve.false_rows(records, THRESHOLD, "empty")[-1]
        dis = ve.false_rows(records, THRESHOLD, "distractor")[-1]
        laser = ""
        if seqs:
            ss: list[vs.Sequence] = []
            for i, s in enumerate(x for x in pk.SOURCES if x.split == "tuning"):
                ss += vs.sequences(s.photos, seed + i, seqs, 8 * seqs, 2 * seqs)
            out = [lr.replay(s, True, ControllerConfig().confirm_frames) for s in ss]
            hits = sum(h for s, (_, h) in zip(ss, out, strict=True) if s.kind == "target")
            n_t = sum(s.kind == "target" for s in ss)
            laser = f" {sum(w for w, _ in out)} of {sum(len(s.detections) for s in ss)} | {hits} of {n_t} |"
    return (f"| {name} | " + " | ".join(f"{100 * rows[c]:.1f}" for c in vi.CONDITIONS)
            + f" | {100 * empty.rate:.2f} | {100 * dis.rate:.2f} | {statistics.median(cpu):.2f} | "
            f"{ts.pct(cpu, 0.99):.2f} |{laser}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--views", type=int, default=100, help="target views per condition")
    p.add_argument("--runs", type=int, default=0, help="target sequences per condition and source (0: none)")
    p.add_argument("--seed", type=int, default=51)
    p.add_argument("--only", default="", help="variants, comma-separated; a variant joins looks with +")
    args = p.parse_args(argv)
    cv2.setNumThreads(1)
    budget.CLOCK = lambda: 0.0
    names = tuple(n for s in pk.SOURCES if s.split == "tuning" for n in pk.views_of(s))
    views = ve.samples(names, args.seed, args.views, 5 * args.views, args.views, "ball", (10.0, 120.0),
                       vi.CONDITIONS)
    n = sum(1 for v in views if v.kind == "target" and v.size >= 16)
    print(f"{n} balls from 16 px ({args.views} views a condition), {5 * args.views} empty views, "
          f"{args.views * len(vi.DISTRACTOR_KINDS)} distractor views\n")
    variants = args.only.split(",") if args.only else ["none", *looks()]
    print("| removed | " + " | ".join(vi.CONDITIONS) + " | empty % | distractor % | median CPU ms | p99 CPU ms |"
          + (" laser-on frames | runs confirmed |" if args.runs else ""))
    print("|---|" + "---|" * (len(vi.CONDITIONS) + 4 + (2 if args.runs else 0)))
    for v in variants:
        removed = [] if v == "none" else v.split("+")
        print(run(v, removed, views, args.runs, args.seed), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
