"""Scoring detectors on the composed real-photo views: recall, false detections, position error.

A detection counts at or above a confidence threshold (the pilot's ``controller.acquire_confidence``);
on a target view it is correct within max(3 px, 30 % of the target's size) of the truth, and a
detection anywhere else is a miss. Records keep every confidence, so one pass serves a whole threshold
sweep. They also keep whether any candidate the detector reported lay at the truth: the recall a better
ranking of the same candidates could reach at most, which tells a miss of the score from a miss of the
candidates.
"""

from __future__ import annotations

import argparse
import math
import statistics
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
import vision_imagery as vi
from cv2.typing import MatLike

from pilot.vision.detection import Candidate

Candidates = Callable[[MatLike], list[Candidate]]  # a detector's every candidate in a frame, best first


@dataclass(frozen=True)
class Record:
    kind: str  # target, empty, distractor
    group: str  # the condition (targets, empty views) or the distractor kind
    size: float
    found: bool
    confidence: float
    error: float  # pixels from the truth (targets), inf when nothing was found
    photo: str = ""  # the photo the view is cut from (targets)
    reached: bool = False  # a candidate, whatever its score, lay at the truth (targets)


def samples(split: tuple[str, ...], seed: int, per_condition: int, empty: int, per_distractor: int,
            target: str, sizes: tuple[float, float], conditions: Iterable[str]) -> list[vi.Sample]:
    rng = np.random.default_rng(seed)
    out = [vi.target_sample(rng, split, c, target, sizes, edge=c == "edge")
           for c in conditions for _ in range(per_condition)]
    out += [vi.empty_sample(rng, split) for _ in range(empty)]
    out += [vi.distractor_sample(rng, split, k) for k in vi.DISTRACTOR_KINDS for _ in range(per_distractor)]
    return out


def run(candidates: Candidates, views: list[vi.Sample]) -> list[Record]:
    """Each view's best candidate (as the detector's ``detect`` reports it) and whether any lay at the truth."""
    records = []
    for s in views:
        cands = candidates(s.image)
        best = cands[0] if cands else None
        err = math.hypot(best.cx - s.cx, best.cy - s.cy) if best and s.kind == "target" else math.inf
        reached = s.kind == "target" and any(_at(c, s) for c in cands)
        records.append(Record(s.kind, s.condition, s.size, best is not None, best.score if best else 0.0, err,
                              s.photo, reached))
    return records


def _at(c: Candidate, s: vi.Sample) -> bool:
    return math.hypot(c.cx - s.cx, c.cy - s.cy) <= tolerance(s.size)


def tolerance(size: float) -> float:
    """How far from the truth a candidate may lie and still be at the target (pixels)."""
    return max(3.0, 0.3 * size)


def correct(r: Record, threshold: float) -> bool:
    return r.found and r.confidence >= threshold and r.error <= tolerance(r.size)


def detected(r: Record, threshold: float) -> bool:
    return r.found and r.confidence >= threshold


def counts(candidates: Candidates, views: list[vi.Sample], threshold: float) -> tuple[int, int]:
    """The target views with a correct detection, and the empty views with any (an A/B of one detector change)."""
    records = run(candidates, views)
    return (sum(r.kind == "target" and correct(r, threshold) for r in records),
            sum(r.kind == "empty" and detected(r, threshold) for r in records))


@dataclass(frozen=True)
class Row:
    group: str
    n: int
    rate: float  # recall (targets) or share of views with a detection (empty, distractor)
    median_error: float = math.nan
    p95_error: float = math.nan
    reached: float = math.nan  # share of targets with a candidate at the truth


def target_rows(records: list[Record], threshold: float, min_size: float,
                by: Callable[[Record], str] = lambda r: r.group) -> list[Row]:
    """Recall and position error per condition (or per what ``by`` names), in the order first met."""
    rows = []
    groups = dict.fromkeys(by(r) for r in records if r.kind == "target")
    for g in groups:
        rs = [r for r in records if r.kind == "target" and by(r) == g and r.size >= min_size]
        ok = [r for r in rs if correct(r, threshold)]
        errs = sorted(r.error for r in ok)
        med = statistics.median(errs) if errs else math.nan
        p95 = errs[min(len(errs) - 1, int(0.95 * len(errs)))] if errs else math.nan
        reached = sum(1 for r in rs if r.reached) / len(rs) if rs else math.nan
        rows.append(Row(g, len(rs), len(ok) / len(rs) if rs else math.nan, med, p95, reached))
    return rows


def photo_rows(records: list[Record], threshold: float, min_size: float) -> list[Row]:
    """Recall per photo over every condition but occlusion: where the misses are."""
    kept = [r for r in records if r.group != "occlusion" and r.size >= min_size]  # a photo with none: no row
    rows = target_rows(kept, threshold, min_size, by=lambda r: r.photo)
    return sorted(rows, key=lambda row: row.group)


def false_rows(records: list[Record], threshold: float, kind: str) -> list[Row]:
    rs = [r for r in records if r.kind == kind]
    groups = dict.fromkeys(r.group for r in rs)
    rows = [Row(g, n := sum(1 for r in rs if r.group == g),
                sum(1 for r in rs if r.group == g and detected(r, threshold)) / n) for g in groups]
    return [*rows, Row("all", len(rs), sum(1 for r in rs if detected(r, threshold)) / len(rs) if rs else math.nan)]


def overall(records: list[Record], threshold: float, min_size: float) -> tuple[float, float, float, float]:
    """Worst recall over the conditions but occlusion, recall under occlusion, empty rate, distractor rate."""
    rows = {r.group: r.rate for r in target_rows(records, threshold, min_size)}
    worst = min((v for k, v in rows.items() if k != "occlusion"), default=math.nan)
    empty = false_rows(records, threshold, "empty")[-1].rate
    distr = false_rows(records, threshold, "distractor")[-1].rate
    return worst, rows.get("occlusion", math.nan), empty, distr


def counts_args(doc: str | None, argv: list[str] | None, **defaults: tuple[int, str]) -> argparse.Namespace:
    """The command line of a goal script: one integer option per ``defaults`` entry (default, help)."""
    p = argparse.ArgumentParser(description=doc)
    for name, (default, text) in defaults.items():
        p.add_argument(f"--{name}", type=int, default=default, help=text)
    return p.parse_args(argv)
