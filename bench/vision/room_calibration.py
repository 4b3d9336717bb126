"""Learning the room, measured (``PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/room_calibration.py``,
figures in RESULTS.md): for each photo taken as a user's room, ``pilot
--calibrate``'s learning (pilot/vision/calibrate_room.py) on 6 frames of the ball held in the middle of a view of
it and 6 views without it, then the detector with and without the model on other views of that room: empty (every
condition), and with the ball anywhere (recall, targets from 16 px). The goal: at most 0.1 % confirmed detections
(a candidate at the acquisition threshold) on a calibrated room's own empty views.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import vision_eval as ve
import vision_imagery as vi

import pilot.vision.budget as budget
from pilot.common.config import VisionConfig, load
from pilot.common.errors import ConfigError
from pilot.vision.calibrate_room import learn_room
from pilot.vision.hsv.detector import HsvBlobDetector

ROOMS = ("coffee", "motorcycle_left", "chelsea", "astronaut", "retina", "china", "flower", "largedemo-wiring")
THRESHOLD = 0.6  # controller.acquire_confidence


def calibration_frames(rng: np.random.Generator, name: str, folder: Path) -> tuple[list[str], list[str]]:
    ball, room = [], []
    for i in range(6):
        img = vi.view(rng, (name,))
        vi.shaded_ball(img, vi.W / 2 + rng.uniform(-8, 8), vi.H / 2 + rng.uniform(-6, 6), rng.uniform(36, 46), rng)
        cv2.imwrite(str(folder / f"ball{i}.png"), img)
        ball.append(str(folder / f"ball{i}.png"))
        cv2.imwrite(str(folder / f"room{i}.png"), vi.view(rng, (name,)))
        room.append(str(folder / f"room{i}.png"))
    return ball, room


def measure(name: str, seed: int, empty: int, targets: int) -> str:
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        ball, room = calibration_frames(rng, name, folder)
        try:
            report = learn_room(ball, room, folder / "pilot.yaml", None, (vi.W, vi.H))
        except ConfigError as exc:
            return f"| {name} | refused: {exc} | | | | |"
        with_model = HsvBlobDetector(load(folder / "pilot.yaml").hsv, VisionConfig())
        plain = HsvBlobDetector()
        views = [vi.empty_sample(rng, (name,)) for _ in range(empty)]
        views += [vi.target_sample(rng, (name,), str(c), "ball", (16.0, 120.0))
                  for c in rng.choice(vi.CONDITIONS[:-1], targets)]
        a, b = ve.run(with_model.candidates, views), ve.run(plain.candidates, views)
        fa = ve.false_rows(a, THRESHOLD, "empty")[-1].rate
        fb = ve.false_rows(b, THRESHOLD, "empty")[-1].rate
        ra = sum(ve.correct(r, THRESHOLD) for r in a if r.kind == "target") / max(1, targets)
        rb = sum(ve.correct(r, THRESHOLD) for r in b if r.kind == "target") / max(1, targets)
        return (f"| {name} | {report.ball_pixels:.0%} / {report.room_pixels:.3%} | {fa:.2%} | {fb:.2%} | {ra:.1%} | "
                f"{rb:.1%} |")


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, empty=(1000, "empty views per room"),
                          targets=(200, "views with the ball per room"), seed=(7, "seed"))
    budget.CLOCK = lambda: 0.0  # judged on what the detector sees: the budget's figures are run.py's timing
    print("| room | ball's / room's pixels kept | empty views detected, model | without | recall, model | without |")
    print("|---|---|---|---|---|---|")
    for k, name in enumerate(ROOMS):
        print(measure(name, args.seed + k, args.empty, args.targets), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
