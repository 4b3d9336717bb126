"""The simpler colour-ball detector (pilot/vision/ball.py, ``hsv.simple``): a plain red ball is found at its
circle, a red square and a ball inside a red wall are not taken, and the budget bounds its blobs."""

from __future__ import annotations

import cv2
import numpy as np

from pilot.common.config import HsvConfig, PilotConfig, VisionConfig
from pilot.vision.ball import SimpleBallDetector
from pilot.vision.detect import make_detector

RED = (30, 20, 200)


def grey(seed: int = 0) -> np.ndarray:
    return np.clip(np.random.default_rng(seed).normal(120, 8, (240, 320, 3)), 0, 255).astype(np.uint8)


def test_a_plain_ball_is_found_at_its_circle() -> None:
    img = grey()
    cv2.circle(img, (200, 90), 20, RED, -1)
    found = SimpleBallDetector().candidates(img)
    assert found and found[0].score >= 0.6
    assert abs(found[0].cx - 200) < 1.5 and abs(found[0].cy - 90) < 1.5 and abs(found[0].size - 41) < 3


def test_a_square_and_a_wall_of_its_colour_are_not_balls() -> None:
    img = grey(1)
    cv2.rectangle(img, (40, 40), (80, 80), RED, -1)
    img[150:, :] = RED  # a red wall with nothing round on it
    assert not any(c.score >= 0.6 for c in SimpleBallDetector().candidates(img))


def test_the_budget_bounds_its_blobs_and_the_config_picks_it() -> None:
    img = grey(2)
    for k in range(5):  # apart: each ring clear of the others
        cv2.circle(img, (30 + 62 * k, 120), 10 + 2 * k, RED, -1)
    t = [0.0]

    def clock() -> float:
        t[0] += 0.01  # 10 ms a read: the budget is spent after the largest blob
        return t[0]

    det = SimpleBallDetector(vision=VisionConfig(budget_ms=5.0), clock=clock)
    found = det.candidates(img)
    assert det.cut_short and len(found) == 1 and abs(found[0].cx - (30 + 62 * 4)) < 2
    assert isinstance(make_detector(PilotConfig(hsv=HsvConfig(simple=True))).source, SimpleBallDetector)
