"""The dev seed sets of bench/vision: where a change to the colour-ball detector is measured before a report run.

Record the code as it is, change it, record again and compare (``make bench-vision-dev`` records as ``current``)::

    PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/vision_dev.py record before  # about 3 min, 2 cores
    PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/vision_dev.py compare before after

The sets (``TARGET_SETS``, ``NEGATIVE_SETS``, ``SHAPE_SETS``; bench/vision/HISTORY.md describes them) use the tuning
and validation photos only, never the held-out or bench photos nor the report's seeds.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from multiprocessing import Pool
from pathlib import Path
from typing import NamedTuple

import cv2
import numpy as np
import vision_eval as ve
import vision_imagery as vi

from pilot.common.config import ControllerConfig
from pilot.vision.hsv.detector import HsvBlobDetector

OUT = Path("build/vision-dev")
TARGET_SETS = {"tun": (vi.TUNING, 21), "val": (vi.VALIDATION, 25), "tun2": (vi.TUNING, 31),
               "tunx": (vi.TUNING, 81), "valx": (vi.VALIDATION, 83)}
NEGATIVE_SETS = {"dt": (vi.TUNING, 91), "dv": (vi.VALIDATION, 92), "dt2": (vi.TUNING, 93)}
SHAPE_SETS = {"rst": (vi.TUNING, 95), "rsv": (vi.VALIDATION, 96)}
PER_CONDITION = 250
EMPTY, PER_DISTRACTOR, SHAPES = 1000, 400, 1500  # further negatives: per set, and per distractor kind
MIN_SIZE = 16.0  # px: the goal's targets

Cands = list[tuple[float, float, float, float]]  # cx, cy, size, score: best first


class View(NamedTuple):
    kind: str
    group: str  # the condition, or the distractor kind
    size: float
    cx: float
    cy: float
    photo: str
    candidates: Cands


def sets() -> list[str]:
    return [*TARGET_SETS, *NEGATIVE_SETS, *SHAPE_SETS]


def views_of(name: str, per_condition: int = PER_CONDITION) -> list[vi.Sample]:
    """The views of one dev set (``per_condition`` scales a target set, for a smoke run)."""
    if name in TARGET_SETS:
        photos, seed = TARGET_SETS[name]
        return ve.samples(photos, seed, per_condition, 2 * per_condition, per_condition // 5, "ball",
                          (10.0, 120.0), vi.CONDITIONS)
    if name in SHAPE_SETS:
        photos, seed = SHAPE_SETS[name]
        rng = np.random.default_rng(seed)
        return [vi.distractor_sample(rng, photos, "red_shape") for _ in range(SHAPES)]
    photos, seed = NEGATIVE_SETS[name]
    rng = np.random.default_rng(seed)
    every = len(vi.CONDITIONS) - 1  # every condition but occlusion, in turn
    out = [vi.empty_sample(rng, photos, vi.CONDITIONS[i % every]) for i in range(EMPTY)]
    return out + [vi.distractor_sample(rng, photos, k) for k in vi.DISTRACTOR_KINDS for _ in range(PER_DISTRACTOR)]


def record(samples: list[vi.Sample]) -> list[View]:
    cv2.setNumThreads(1)
    detector = HsvBlobDetector()
    out = []
    for s in samples:
        cands = [(c.cx, c.cy, c.size, c.score) for c in detector.candidates(s.image)]
        out.append(View(s.kind, s.condition, s.size, s.cx, s.cy, s.photo, cands))
    return out


def save(views: list[View], run: str, name: str, out: Path = OUT) -> None:
    (out / run).mkdir(parents=True, exist_ok=True)
    (out / run / f"{name}.json").write_text(json.dumps([list(v) for v in views]))


def _record_set(job: tuple[str, str]) -> str:
    run, name = job
    save(record(views_of(name)), run, name)
    return name


def load(run: str, name: str, out: Path = OUT) -> list[View]:
    path = out / run / f"{name}.json"
    if not path.is_file():
        raise SystemExit(f"{path}: no such record (vision_dev.py record {run})")
    return [View(k, g, s, x, y, p, [tuple(c) for c in cs]) for k, g, s, x, y, p, cs in json.loads(path.read_text())]


def as_record(v: View) -> ve.Record:
    """The view as bench/vision's record of its best candidate, which ``vision_eval``'s rules read."""
    best = v.candidates[0] if v.candidates else None
    error = math.hypot(best[0] - v.cx, best[1] - v.cy) if best is not None and v.kind == "target" else math.inf
    return ve.Record(v.kind, v.group, v.size, best is not None, best[3] if best else 0.0, error, v.photo)


def correct(v: View, threshold: float) -> bool:
    """A target view whose best candidate scores ``threshold`` at the truth (bench/vision's rule)."""
    return v.kind == "target" and ve.correct(as_record(v), threshold)


def detected(v: View, threshold: float) -> bool:
    return ve.detected(as_record(v), threshold)


class Diff(NamedTuple):
    balls: tuple[int, int, int]  # found before, found after, of how many (targets from MIN_SIZE)
    gained: list[str]  # the groups of the balls gained
    lost: list[str]
    false: tuple[int, int]  # views with no target that have a detection, before and after
    new_false: list[str]  # the groups of the views that have one only after
    gone_false: list[str]
    differ: int  # views whose candidates differ at all


def compare(a: list[View], b: list[View], threshold: float) -> Diff:
    if len(a) != len(b):
        raise SystemExit(f"the records hold {len(a)} and {len(b)} views: not the same set")
    pairs = list(zip(a, b, strict=True))
    balls = [(x, y) for x, y in pairs if x.kind == "target" and x.size >= MIN_SIZE]
    others = [(x, y) for x, y in pairs if x.kind != "target"]
    return Diff(
        (sum(correct(x, threshold) for x, _ in balls), sum(correct(y, threshold) for _, y in balls), len(balls)),
        [x.group for x, y in balls if correct(y, threshold) and not correct(x, threshold)],
        [x.group for x, y in balls if correct(x, threshold) and not correct(y, threshold)],
        (sum(detected(x, threshold) for x, _ in others), sum(detected(y, threshold) for _, y in others)),
        [x.group for x, y in others if detected(y, threshold) and not detected(x, threshold)],
        [x.group for x, y in others if detected(x, threshold) and not detected(y, threshold)],
        sum(x.candidates != y.candidates for x, y in pairs),
    )


def _counted(groups: list[str]) -> str:
    return ", ".join(f"{g} {groups.count(g)}" for g in sorted(set(groups))) or "none"


def recorded(run: str, out: Path = OUT) -> list[str]:
    """The dev sets a record holds, in the order of ``sets()``."""
    return [name for name in sets() if (out / run / f"{name}.json").is_file()]


def report(before: str, after: str, threshold: float, out: Path = OUT) -> list[str]:
    """Set by set, then in total: the balls gained and lost, and the false detections, over the sets both records
    hold."""
    held = recorded(after, out)
    both = [name for name in recorded(before, out) if name in held]
    if not both:
        raise SystemExit(f"the records {before!r} and {after!r} hold no dev set in common (vision_dev.py record)")
    lines = []
    gained = lost = negatives = 0
    false = [0, 0]  # on the target sets, before and after
    further = [0, 0]  # of the further negatives
    for name in both:
        a = load(before, name, out)
        d = compare(a, load(after, name, out), threshold)
        line = f"false detections {d.false[0]} -> {d.false[1]}; records differing {d.differ}"
        if name in TARGET_SETS:
            line = f"balls {d.balls[0]} -> {d.balls[1]} of {d.balls[2]} (+{len(d.gained)} -{len(d.lost)}); {line}"
            gained, lost = gained + len(d.gained), lost + len(d.lost)
            false = [false[0] + d.false[0], false[1] + d.false[1]]
        else:
            negatives += len(a)
            further = [further[0] + d.false[0], further[1] + d.false[1]]
        lines.append(f"{name:5s} {line}")
        if d.gained or d.lost:
            lines.append(f"      balls gained: {_counted(d.gained)}; lost: {_counted(d.lost)}")
        if d.new_false or d.gone_false:
            lines.append(f"      false detections new: {_counted(d.new_false)}; gone: {_counted(d.gone_false)}")
    lines.append(f"total: balls +{gained} -{lost}; false detections {false[0]} -> {false[1]} on the target sets, "
                 f"{further[0]} -> {further[1]} of the {negatives:,} further negatives")
    if missing := [name for name in sets() if name not in both]:
        lines.append(f"not in both records: {', '.join(missing)}")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="record the dev sets with the detector as it is")
    rec.add_argument("name", help="the record's name (a directory of build/vision-dev)")
    rec.add_argument("--sets", nargs="+", choices=sets(), default=sets(),
                     help="only these sets (the target sets alone take about half the time)")
    cmp = sub.add_parser("compare", help="balls gained and lost, false detections, between two records")
    for arg in ("before", "after"):
        cmp.add_argument(arg)
    cmp.add_argument("--threshold", type=float, default=ControllerConfig().acquire_confidence,
                     help="the score that counts as a detection (default: the controller's acquire_confidence)")
    args = ap.parse_args(argv)
    if args.command == "record":
        with Pool(2) as pool:
            for name in pool.imap_unordered(_record_set, [(args.name, n) for n in args.sets]):
                print(f"recorded {name}", flush=True)
        return 0
    print("\n".join(report(args.before, args.after, args.threshold)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
