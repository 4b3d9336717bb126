"""A ball is plain inside (hsv/inside.py): the dahlia close up among scikit-learn's photos, heavily
compressed, is a round red heart of small red cups and their edges, which fired the detector in empty views; the
check costs no ball here."""

from __future__ import annotations

import numpy as np
import pytest
import vision_eval as ve
import vision_imagery as vi
from pilot_synth import matte_ball

import pilot.vision.hsv.inside as hsv_inside
from pilot.common.config import ControllerConfig
from pilot.vision.hsv.detector import HsvBlobDetector

THRESHOLD = ControllerConfig().acquire_confidence


def fired(views: list[vi.Sample]) -> int:
    """How many of the views have a detection the pilot would act on."""
    return sum(ve.detected(r, THRESHOLD) for r in ve.run(HsvBlobDetector().candidates, views))


def empty_views(condition: str, seed: int, n: int = 300) -> list[vi.Sample]:
    rng = np.random.default_rng(seed)
    return [vi.empty_sample(rng, vi.VALIDATION, condition) for _ in range(n)]


@pytest.mark.parametrize("noise", [0.0, 20.0])
def test_a_plain_ball_is_plain_inside_through_sensor_noise(noise: float) -> None:
    """Noise of 20 grey levels (more than the simulator's dim room at full gain) makes no edges after smoothing."""
    bg = np.full((240, 320, 3), 120.0)
    img = matte_ball(bg, 160, 120, 30, (40.0, 40.0, 210.0), 0.3)
    img += np.random.default_rng(3).normal(0.0, noise, img.shape)
    frame = np.asarray(np.clip(img, 0, 255), np.uint8)
    assert not hsv_inside.busy_inside(frame, 160, 120, 60)


def test_a_disc_of_small_cups_is_busy_inside() -> None:
    """A red disc packed with small cups, dark hollows 4 px across 7 px apart (a dahlia's heart), is edges all over
    inside (a third of it); the same disc plain is not; a blob under ``FROM`` is never read."""
    img = np.full((240, 320, 3), 120, np.uint8)
    yy, xx = np.mgrid[0:240, 0:320]
    disc = np.hypot(xx - 160, yy - 120) < 30
    img[disc] = (40, 40, 200)
    plain = img.copy()
    for cy in range(96, 145, 7):
        for cx in range(136, 185, 7):
            if np.hypot(cx - 160, cy - 120) < 26:
                img[np.hypot(xx - cx, yy - cy) < 2.0] = (10, 10, 70)
    assert hsv_inside.busy_inside(img, 160, 120, 60)
    assert not hsv_inside.busy_inside(plain, 160, 120, 60)
    assert not hsv_inside.busy_inside(img, 160, 120, hsv_inside.FROM - 1.0)


def test_compressed_dahlia_hearts_are_not_taken_for_balls(monkeypatch: pytest.MonkeyPatch) -> None:
    """300 empty views of the validation photos at JPEG quality 20-40: 8 fire with the check, 15 without it."""
    views = empty_views("jpeg", 15)
    with_check = fired(views)
    monkeypatch.setattr(hsv_inside, "EDGES_MAX", 1.1)  # no share can pass it: nothing is busy inside
    without = fired(views)
    assert with_check <= 8 and without >= with_check + 5


def test_the_inside_check_costs_no_ball_from_its_size(monkeypatch: pytest.MonkeyPatch) -> None:
    """Balls from ``FROM`` px on the tuning photos, under the conditions that make edges (noise, JPEG blocks, 30 %
    hidden behind an edge): the same found with the check and without it."""
    views = ve.samples(vi.TUNING, 41, 60, 0, 0, "ball", (hsv_inside.FROM, 120.0), ("noise", "jpeg", "occlusion"))
    def found() -> list[bool]:
        return [ve.correct(r, THRESHOLD) for r in ve.run(HsvBlobDetector().candidates, views)]

    with_check = found()
    monkeypatch.setattr(hsv_inside, "EDGES_MAX", 1.1)
    assert sum(with_check) >= 150 and with_check == found()
