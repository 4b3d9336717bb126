"""The source-separated evaluation (``make bench-vision-sources``), figures to bench/vision/RESULTS-sources.md.

Five packaged sources (packaged.py), split by source into tuning and held-out; each source's photos and each
video's frames are reported as a set of their own. Per set: the colour detector's recall per condition and its
detections on empty, drawn-distractor and natural-distractor views (vision_imagery.py composes them, as for
RESULTS.md), the gate on jittered sequences and on runs of real video frames (laser-on frames without the target),
ArUco clean, motion-blurred and with a corner covered, and the cost per frame against the cvtColor+inRange floor.
The colour detector's candidates pass the learned verifier (pilot/vision/verify.py) as the pilot runs them; its
single-view figures are also given for the rules alone, from the same candidates.
The accuracy runs freeze the budget's clock (the rules judged alone, the same on any machine's load); the cost runs
keep the default budget (``vision.budget_ms``) on the thread's CPU clock, as the pilot flies.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import packaged as pk
import sources_seq as sq
import sources_time as st
import vision_eval as ve
import vision_imagery as vi
import vision_sequences as vs
from cv2.typing import MatLike

import pilot.vision.budget as budget
import pilot.vision.verify as verify
from pilot.common.config import ControllerConfig
from pilot.vision.aruco import ArucoMarkerDetector
from pilot.vision.detection import Candidate
from pilot.vision.hsv.detector import HsvBlobDetector

HERE = Path(__file__).resolve().parent
ARUCO_GOALS = ("clean", "motion_blur", "corner")
CONDITIONS = vi.CONDITIONS


@dataclass(frozen=True)
class Set:
    label: str
    source: pk.Source
    names: tuple[str, ...]  # stills for target, empty and drawn-distractor views
    naturals: tuple[str, ...] = ()  # natural-distractor photos
    video: str = ""  # a video's runs feed the pipeline too


@dataclass
class Result:
    hsv: list[ve.Record]  # the colour detector's candidates through the learned verifier, as the pilot runs it
    aruco: list[ve.Record]
    seqs: list[vs.Sequence]
    rules: list[ve.Record] = field(default_factory=list)  # the same views, the rules alone (no verifier)


def verified_records(views: list[vi.Sample]) -> tuple[list[ve.Record], list[ve.Record]]:
    """The colour detector on ``views`` once: its records through the learned verifier and without it."""
    det, verifier = HsvBlobDetector(), verify.shipped()
    found: dict[int, list[Candidate]] = {}

    def rules(image: MatLike) -> list[Candidate]:
        found[id(image)] = det.candidates(image)
        return found[id(image)]

    def checked(image: MatLike) -> list[Candidate]:
        return [c for c in found.pop(id(image))[: verify.MAX_VERIFIED] if verifier.passes(image, c)]

    plain = ve.run(rules, views)
    return ve.run(checked, views), plain


def sets() -> list[Set]:
    out = []
    for s in pk.SOURCES:
        out.append(Set(f"{s.name} photos", s, s.photos, s.distractors))
        if s.videos:
            out.append(Set(f"{s.name} videos", s, tuple(f for v in s.videos for f in pk.video_frames(v))))
            out += [Set(f"{s.name} {v.split('/')[-1]}", s, (), video=v) for v in s.videos]
    return out


def pct(v: float) -> str:
    return "n/a" if v != v else f"{100 * v:.1f} %"


def evaluate(st_: Set, seed: int, n: int) -> Result:
    if st_.video:
        return Result([], [], sq.video_runs(st_.video, seed, n // 10, n // 5))
    rng = np.random.default_rng(seed + 50)
    ball = ve.samples(st_.names, seed, n, 5 * n, n // 2, "ball", (10.0, 120.0), CONDITIONS)
    for name in st_.naturals:
        ball += [natural(vi.empty_sample(rng, (name,)), "distractor", "natural") for _ in range(n // 2)]
    markers = ve.samples(st_.names, seed + 1, n, 0, 0, "marker", (24.0, 120.0), ARUCO_GOALS)
    negatives = [s for s in ball if s.kind != "target"]
    hsv, rules = verified_records(ball)
    aruco = ve.run(ArucoMarkerDetector().candidates, markers + negatives)
    seqs = vs.sequences(st_.names, seed + 2, n // 20, n // 5, n // 40)
    return Result(hsv, aruco, seqs, rules)


def natural(s: vi.Sample, kind: str, condition: str) -> vi.Sample:
    """An empty view of a natural-distractor photo, counted as a distractor view."""
    return vi.Sample(s.image, kind, condition, photo=s.photo)


def rate(records: list[ve.Record], kind: str, group: str | None, threshold: float) -> tuple[float, int]:
    rs = [r for r in records if r.kind == kind and (group is None or r.group == group)]
    return (sum(ve.detected(r, threshold) for r in rs) / len(rs) if rs else float("nan")), len(rs)


def hsv_rows(results: dict[str, Result], threshold: float, rules: bool = False) -> list[str]:
    out = ["| set | " + " | ".join(CONDITIONS) + " | worst but occlusion |", "|---" * (len(CONDITIONS) + 2) + "|"]
    for label, r in results.items():
        if not r.hsv:
            continue
        rows = {row.group: row for row in ve.target_rows(r.rules if rules else r.hsv, threshold, 16)}
        worst = min(CONDITIONS[:-1], key=lambda c: rows[c].rate)
        out.append(f"| {label} | " + " | ".join(f"{pct(rows[c].rate)} ({rows[c].n})" for c in CONDITIONS)
                   + f" | {pct(rows[worst].rate)} ({worst}) |")
    return out


def false_rows(results: dict[str, Result], threshold: float) -> list[str]:
    out = ["| set | empty views | drawn distractors | natural distractors | empty sequences confirmed | distractor "
           "sequences confirmed | laser-on frames without the target |", "|---|---|---|---|---|---|---|"]
    cfg = ControllerConfig()
    for label, r in results.items():
        e, ne = rate(r.hsv, "empty", None, threshold)
        d = [x for x in r.hsv if x.kind == "distractor" and x.group != "natural"]
        nat, nn = rate(r.hsv, "distractor", "natural", threshold)
        dr = sum(ve.detected(x, threshold) for x in d) / len(d) if d else float("nan")
        _, se, sd = vs.rates(r.seqs, cfg.acquire_confidence, cfg.confirm_frames)
        frames = sum(len(s.detections) for s in r.seqs)
        laser = sum(sq.laser_frames(s) for s in r.seqs)
        out.append(f"| {label} | {pct(e)} of {ne} | {pct(dr)} of {len(d)} | "
                   f"{pct(nat) + f' of {nn}' if nn else '-'} | {pct(se)} of {sum(s.kind == 'empty' for s in r.seqs)} | "
                   f"{pct(sd)} of {sum(s.kind == 'distractor' for s in r.seqs)} | {laser} of {frames} |")
    return out


def rules_rows(results: dict[str, Result], threshold: float) -> list[str]:
    """Empty and drawn-distractor views with a detection, the rules alone and through the verifier."""
    out = ["| set | empty views, rules alone | with the verifier | drawn distractors, rules alone | with the verifier "
           "| natural distractors, rules alone | with the verifier |", "|---|---|---|---|---|---|---|"]
    for label, r in results.items():
        if not r.hsv:
            continue
        cells = []
        for kind, group in (("empty", None), ("distractor", "drawn"), ("distractor", "natural")):
            for records in (r.rules, r.hsv):
                rs = [x for x in records if x.kind == kind and (group is None or (x.group == "natural") == (
                    group == "natural"))]
                cells.append(f"{pct(sum(ve.detected(x, threshold) for x in rs) / len(rs))} of {len(rs)}" if rs
                             else "-")
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    return out


def seq_rows(results: dict[str, Result]) -> list[str]:
    cfg = ControllerConfig()
    out = ["| set | " + " | ".join(vs.SEQ_CONDITIONS) + " |", "|---" * (len(vs.SEQ_CONDITIONS) + 1) + "|"]
    for label, r in results.items():
        share, _, _ = vs.rates(r.seqs, cfg.acquire_confidence, cfg.confirm_frames)
        if label.endswith(".avi"):
            out.append(f"| {label} | {pct(share.get('video', float('nan')))} (the video's own frames) |"
                       + " |" * (len(vs.SEQ_CONDITIONS) - 1))
        else:
            out.append(f"| {label} | " + " | ".join(pct(share.get(c, float("nan"))) for c in vs.SEQ_CONDITIONS) + " |")
    return out


def aruco_rows(results: dict[str, Result]) -> list[str]:
    out = ["| set | clean | motion_blur | corner | false positives (empty and distractor views) |",
           "|---|---|---|---|---|"]
    for label, r in results.items():
        if not r.aruco:
            continue
        rows = {row.group: row for row in ve.target_rows(r.aruco, 0.5, 0)}
        fp = [x for x in r.aruco if x.kind != "target"]
        out.append(f"| {label} | " + " | ".join(f"{pct(rows[c].rate)} ({rows[c].n})" for c in ARUCO_GOALS)
                   + f" | {sum(ve.detected(x, 0.5) for x in fp)} of {len(fp)} |")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--views", type=int, default=200, help="target views per condition and set")
    ap.add_argument("--timing", type=int, default=200, help="views timed per set at 320x240")
    ap.add_argument("--no-write", action="store_true", help="print, do not write RESULTS-sources.md")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    threshold = ControllerConfig().acquire_confidence
    t0 = time.perf_counter()
    wall = budget.CLOCK
    budget.CLOCK = lambda: 0.0  # accuracy: the rules alone, whatever the machine's load
    results = {s.label: evaluate(s, 11 + 7 * i, args.views) for i, s in enumerate(sets())}
    budget.CLOCK = wall
    timing = st.table([(s.label, s.names) for s in sets() if s.names], args.timing)
    out = ["# Vision on five packaged sources, split by source", "",
           f"Machine: {platform.machine()}; Python {platform.python_version()}; OpenCV {cv2.__version__}, one thread. "
           f"Generated by `make bench-vision-sources` (bench/vision/sources_run.py --views {args.views} --timing "
           f"{args.timing}) in {time.perf_counter() - t0:.0f} s.", "", "## Sources", "",
           "| source | installs with | split | stills | shows |", "|---|---|---|---|---|"]
    for s in pk.SOURCES:
        videos = f" + {len(pk.views_of(s)) - len(s.photos)} frames of {len(s.videos)} videos" if s.videos else ""
        naturals = f" + {len(s.distractors)} natural distractors" if s.distractors else ""
        out.append(f"| {s.name} | {s.installs} | {s.split} | {len(s.photos)} photos{naturals}{videos} | {s.shows} |")
    out += ["", f"Per set: {args.views} target views per condition (balls 10-120 px, log-uniform; recall for those of "
            f"16 px or more, their number in brackets), {5 * args.views} empty views and {args.views // 2} per drawn "
            f"distractor kind (1-3 objects: {', '.join(vi.DISTRACTOR_KINDS)}), {args.views // 2} views of each "
            f"natural-distractor photo, every condition but occlusion applied to the views without a target. "
            f"Confidence threshold {threshold} (`controller.acquire_confidence`), budget's clock frozen.", "",
            "## HSV recall, targets >= 16 px (candidates through the learned verifier, pilot/vision/verify.py)", "",
            *hsv_rows(results, threshold), "",
            "## HSV recall without the learned verifier (the rules alone, the same views)", "",
            *hsv_rows(results, threshold, rules=True), "",
            "## HSV detections on views without the target, without and with the verifier", "",
            *rules_rows(results, threshold), "",
            "## HSV detections without the target (with the verifier)", "",
            "Views: a detection at or above the threshold in one frame. Sequences: the whole pipeline (frame checks, "
            "detector, tracker) and the gate at the configured threshold and N, centring and range lifted; "
            f"photo sets: {args.views // 5} empty and {args.views // 40} per drawn-distractor kind of "
            f"{vs.NEGATIVE_FRAMES} jittered frames; videos: {args.views // 5} runs of {vs.NEGATIVE_FRAMES} real "
            "frames. Laser-on frames: the gate confirmed on a run with no ball, or away from the ball.", "",
            *false_rows(results, threshold), "",
            "## The gate on target sequences: confirmed on the ball within "
            f"{vs.TARGET_FRAMES} frames", "", *seq_rows(results), "",
            "## ArUco (markers 24-120 px; corner: 12 % of the black square covered)", "", *aruco_rows(results), "",
            "## Cost per frame (default budget on the thread's CPU clock; wall time beside it)", "", *timing, ""]
    text = "\n".join(out)
    print(text)
    if not args.no_write:
        (HERE / "RESULTS-sources.md").write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
