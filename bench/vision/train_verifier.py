"""Train the ball verifier (pilot/vision/verify.py) on the tuning sources only (packaged.py; never the held-out ones).

Composites of the bench's shaded ball (vision_imagery.py: every condition, balls 16-120 px) on the tuning sources'
stills; the colour-ball detector's first ``MAX_VERIFIED`` candidates of each view are the examples: those on the ball
positive, every other one (on empty views, drawn-distractor views and off the ball) negative, exactly what the
detector confuses (those it would act on weigh more). Seed sets of composites: two train the network
(scikit-learn's MLPClassifier, a bench dependency; its weights go to pilot/vision/verifier.yaml), the next chooses
the threshold: the highest at which no condition's recall (balls from 16 px, at the acquisition confidence) falls by
more than ``--max-loss`` points. The validation
table, with and without the verifier, is printed; figures go to bench/vision/HISTORY.md.
``make bench-verifier`` (``BENCH_VERIFIER_FLAGS=--views 60`` for a smoke run; ``--no-write`` keeps the model).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import pickle
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
import packaged as pk
import vision_eval as ve
import vision_imagery as vi

import pilot.vision.budget as budget
import pilot.vision.verify as verify
import pilot.vision.verify_features as vf
from pilot.common.config import ControllerConfig, HsvConfig
from pilot.vision.hsv.detector import HsvBlobDetector

THRESHOLD = ControllerConfig().acquire_confidence
MIN_SCORE = 0.02  # the candidates collected: from this score (the pilot's from hsv.min_score, 0.2)
HARD = 10.0  # the extra weight of a negative the pilot's detector reports, and again of one it would act on
KEPT = 8  # candidates collected per view, best first
EMPTY, PER_DISTRACTOR = 15, 2  # empty views and views per distractor kind, per target view of a condition
CONDITIONS = (*vi.CONDITIONS, "stand")  # the bench's conditions, and the ball on its stand
TUNING = tuple(f for s in pk.SOURCES if s.split == "tuning" for f in pk.views_of(s))
FloatArray = npt.NDArray[np.float32]


@dataclass(frozen=True)
class View:
    kind: str  # target, empty, distractor
    group: str  # condition or distractor kind
    size: float
    scores: tuple[float, ...]  # the detector's score of each candidate looked at, best first
    at_truth: tuple[bool, ...]
    rows: tuple[int, ...]  # each candidate's row in the feature matrix


def collect(samples: list[vi.Sample]) -> tuple[list[View], FloatArray, npt.NDArray[np.int32]]:
    """The detector's candidates on ``samples``: per view what it found, and every candidate's features and label.
    The detector reports candidates from ``MIN_SCORE`` (the pilot's from ``hsv.min_score``): the near misses are
    negatives too."""
    det = HsvBlobDetector(HsvConfig(min_score=MIN_SCORE))
    out: list[View] = []
    feats: list[FloatArray] = []
    labels: list[int] = []
    for s in samples:
        cands = det.candidates(s.image)[:KEPT]
        at = tuple(s.kind == "target" and math.hypot(c.cx - s.cx, c.cy - s.cy) <= ve.tolerance(s.size)
                   for c in cands)
        rows = tuple(range(len(feats), len(feats) + len(cands)))
        feats += [vf.features(s.image, c) for c in cands]
        labels += [int(a) for a in at]
        out.append(View(s.kind, s.condition, s.size, tuple(c.score for c in cands), at, rows))
    return out, np.asarray(feats, np.float32).reshape(-1, vf.LENGTH), np.asarray(labels, np.int32)


def stand_sample(rng: np.random.Generator, condition: str) -> vi.Sample:
    """The pilot's target as it is built (pilot/sim/room.py): the ball on a thin grey pole, its ArUco plate most
    often 1.5 diameters below it (above, for a low ball), the ball lit as the bench's or flat (diffuse light)."""
    img = vi.view(rng, TUNING)
    d = float(np.exp(rng.uniform(math.log(16.0), math.log(120.0))))
    cx, cy = rng.uniform(d / 2 + 2, vi.W - d / 2 - 2), rng.uniform(d / 2 + 2, vi.H - d / 2 - 2)
    down = 1.0 if rng.random() < 0.8 else -1.0
    grey = tuple(int(v) for v in rng.uniform(90, 200) * np.ones(3))
    cv2.line(img, (round(cx), round(cy)), (round(cx), round(cy + down * 4 * d)), grey, max(1, round(0.06 * d)))
    if rng.random() < 0.8:
        vi.marker(img, cx + rng.uniform(-0.1, 0.1) * d, cy + down * 1.5 * d, d * rng.uniform(0.9, 1.1), rng)
    if rng.random() < 0.5:
        vi.shaded_ball(img, cx, cy, d, rng)
    else:
        hsv = np.array([[[rng.uniform(-5, 5) % 180, rng.uniform(140, 240), rng.uniform(100, 235)]]], np.uint8)
        colour = tuple(int(v) for v in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR).reshape(3))
        cv2.circle(img, (round(16 * cx), round(16 * cy)), round(8 * d), colour, -1, cv2.LINE_AA, 4)
    out, hm = vi.degrade(img, condition, rng)
    tx, ty = vi.map_point(hm, cx, cy)
    return vi.Sample(out, "target", "stand", d, tx, ty)


def samples(seed: int, views: int, stands: bool) -> list[vi.Sample]:
    """``views`` target views per condition with ``EMPTY`` times as many empty views and ``PER_DISTRACTOR`` times
    as many per distractor kind; or (``stands``) twice ``views`` views of the ball on its stand."""
    if not stands:
        return ve.samples(TUNING, seed, views, EMPTY * views, PER_DISTRACTOR * views, "ball", (16.0, 120.0),
                          vi.CONDITIONS)
    rng = np.random.default_rng(seed + 1000)
    return [stand_sample(rng, vi.CONDITIONS[k % (len(vi.CONDITIONS) - 1)]) for k in range(2 * views)]


def cached(folder: str, seed: int, views: int) -> tuple[list[View], FloatArray, npt.NDArray[np.int32]]:
    """``collect`` on the seed set's ``samples`` and its stands, kept in ``folder`` (none: not kept) for runs that
    only retrain."""
    parts = [cached_part(folder, seed, views, stands) for stands in (False, True)]
    offset = len(parts[0][1])
    shifted = [dataclasses.replace(v, rows=tuple(r + offset for r in v.rows)) for v in parts[1][0]]
    return parts[0][0] + shifted, np.concatenate([parts[0][1], parts[1][1]]), np.concatenate([parts[0][2],
                                                                                              parts[1][2]])


def cached_part(folder: str, seed: int, views: int, stands: bool
                ) -> tuple[list[View], FloatArray, npt.NDArray[np.int32]]:
    if not folder:
        return collect(samples(seed, views, stands))
    path = Path(folder) / f"verifier-{vf.VERSION}-{seed}-{views}{'-stands' if stands else ''}.pickle"
    if path.is_file():
        with path.open("rb") as f:
            got: tuple[list[View], FloatArray, npt.NDArray[np.int32]] = pickle.load(f)
            return got
    out = collect(samples(seed, views, stands))
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as f:
        pickle.dump(out, f)
    return out


def outcome(v: View, passed: npt.NDArray[np.bool_] | None) -> tuple[bool, bool]:
    """(a detection at the acquisition confidence, it lies on the ball) for the view's first passed candidate of
    the first ``MAX_VERIFIED`` the pilot's detector reports (from ``hsv.min_score``)."""
    reported = [k for k, s in enumerate(v.scores) if s >= HsvConfig().min_score][: verify.MAX_VERIFIED]
    for k in reported:
        if passed is None or passed[v.rows[k]]:
            return v.scores[k] >= THRESHOLD, v.at_truth[k]
    return False, False


def table(views: list[View], passed: npt.NDArray[np.bool_] | None) -> dict[str, float]:
    """Recall per condition (balls from 16 px) and the empty and distractor rates, in %."""
    out: dict[str, float] = {}
    for c in CONDITIONS:
        rs = [outcome(v, passed) for v in views if v.kind == "target" and v.group == c]
        out[c] = 100.0 * sum(d and a for d, a in rs) / max(1, len(rs))
    for kind in ("empty", "distractor"):
        rs = [outcome(v, passed) for v in views if v.kind == kind]
        out[kind] = 100.0 * sum(d for d, _ in rs) / max(1, len(rs))
    return out


def train(x: FloatArray, y: npt.NDArray[np.int32], hidden: int, seed: int) -> verify.Verifier:
    from sklearn.neural_network import MLPClassifier

    mean = x.mean(axis=0)
    scale = np.maximum(x.std(axis=0), 1e-3)
    net = MLPClassifier((hidden,), alpha=1e-2, max_iter=500, early_stopping=True, random_state=seed)
    score = x[:, vf.LENGTH - 2]  # the detector's own score: a negative it would act on weighs more
    weight = np.where(y == 1, 1.0, 1.0 + HARD * (score >= HsvConfig().min_score) + HARD * (score >= THRESHOLD))
    net.fit((x - mean) / scale, y, sample_weight=weight)
    w0, w1 = (np.asarray(w, np.float32) for w in net.coefs_)
    b0, b1 = (np.asarray(b, np.float32) for b in net.intercepts_)
    return verify.Verifier(mean.astype(np.float32), scale.astype(np.float32), w0, b0, w1, b1, 0.5)


def scores(v: verify.Verifier, x: FloatArray) -> FloatArray:
    hidden = np.maximum(((x - v.mean) / v.scale) @ v.w0 + v.b0, 0.0)
    return np.asarray(1.0 / (1.0 + np.exp(-np.clip(hidden @ v.w1 + v.b1, -60, 60))), np.float32).ravel()


def cost(v: verify.Verifier, seed: int, n: int) -> str:
    """The verifier's CPU time per candidate (features and network), on the detector's candidates of ``n`` views."""
    samples = ve.samples(TUNING, seed, n, n, n // 5, "ball", (10.0, 120.0), ("clean", "noise"))
    det, times = HsvBlobDetector(), []
    for s in samples:
        for c in det.candidates(s.image)[: verify.MAX_VERIFIED]:
            t = time.thread_time()
            v.score(s.image, c)
            times.append(1000.0 * (time.thread_time() - t))
    times.sort()
    return (f"cost per candidate (CPU of the thread, {len(times)} candidates): median {times[len(times) // 2]:.3f} ms, "
            f"p99 {times[min(len(times) - 1, int(0.99 * len(times)))]:.3f} ms, largest {times[-1]:.3f} ms")


def row(name: str, t: dict[str, float]) -> str:
    return f"| {name} | " + " | ".join(f"{t[k]:.1f}" for k in (*CONDITIONS, "empty", "distractor")) + " |"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--views", type=int, default=300, help="target views per condition and seed set")
    ap.add_argument("--seed", type=int, default=61, help="the first training seed set")
    ap.add_argument("--sets", type=int, default=2, help="training seed sets (seed, seed + 1, ...; the next one "
                    "validates)")
    ap.add_argument("--hidden", type=int, default=32, help="the network's hidden units")
    ap.add_argument("--max-loss", type=float, default=0.5, help="recall points a condition may lose")
    ap.add_argument("--cache", default="", help="a folder keeping the collected candidates between runs")
    ap.add_argument("--no-write", action="store_true", help="print only, do not write pilot/vision/verifier.yaml")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    budget.CLOCK = lambda: 0.0  # the rules alone, whatever the machine's load
    t0 = time.perf_counter()
    train_sets = [cached(args.cache, args.seed + k, args.views) for k in range(args.sets)]
    x = np.concatenate([t[1] for t in train_sets])
    y = np.concatenate([t[2] for t in train_sets])
    val, xv, yv = cached(args.cache, args.seed + args.sets, args.views)
    print(f"training: {int(y.sum())} candidates on the ball, {int(len(y) - y.sum())} others; validation: "
          f"{int(yv.sum())} and {int(len(yv) - yv.sum())} ({time.perf_counter() - t0:.0f} s)")
    model = train(x, y, args.hidden, args.seed)
    sv = scores(model, xv)
    base = table(val, None)
    print("\n| verifier | " + " | ".join(CONDITIONS) + " | empty % | distractor % |\n" + "|---" * 14 + "|")
    print(row("none", base))
    chosen = 0.0
    for t in (0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5):
        r = table(val, sv >= t)
        print(row(f"threshold {t}", r))
        if all(base[c] - r[c] <= args.max_loss for c in CONDITIONS):
            chosen = t
    if chosen == 0.0:
        print("\nno threshold keeps every condition's recall: the verifier does not pay; nothing written")
        return 1
    model = verify.Verifier(model.mean, model.scale, model.w0, model.b0, model.w1, model.b1, chosen)
    print(f"\nthreshold {chosen} (validation seed set {args.seed + args.sets}); {time.perf_counter() - t0:.0f} s")
    print(cost(model, args.seed + args.sets + 1, 100))
    if not args.no_write:
        verify.save(model, verify.MODEL)
        print(f"wrote {verify.MODEL}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
