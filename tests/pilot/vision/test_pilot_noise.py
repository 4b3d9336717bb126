"""A noisy frame (a camera's gain in dim light): its noise measured, a dark ball found through it on the frame
smoothed, and the laser's aim check read smoothed too (pilot/vision/hsv/noise.py, pilot/vision/hsv/detector.py)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
import vision_eval as ve
import vision_imagery as vi
from pilot_synth import matte_ball

import pilot.vision.hsv.colour as hsv_colour
import pilot.vision.hsv.detector as hsv_module
from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.hsv.noise import NOISY, noise_level

GREY_OF_CHANNEL_NOISE = math.sqrt(0.299**2 + 0.587**2 + 0.114**2)  # grey's share of independent channel noise
DARK_RED = (16.0, 14.0, 60.0)  # BGR: the simulator's dim room's ball where lit, at the camera's full gain


def dim_frame(seed: int, sigma: float, ball: bool = True, centred: bool = False) -> tuple[np.ndarray, float, float]:
    """A dim room's frame: a grey wall over a darker floor, a dark red ball 22 px across (about 4 m away) and
    sensor noise of ``sigma`` per channel; with the ball's centre."""
    rng = np.random.default_rng(seed)
    bg = np.zeros((240, 320, 3))
    bg[:130] = (45.0, 47.0, 48.0)
    bg[130:] = (24.0, 27.0, 26.0)
    cx, cy = (160.0, 120.0) if centred else (160.0 + rng.uniform(-40, 40), 100.0 + rng.uniform(-20, 20))
    if ball:
        bg = matte_ball(bg, cx, cy, 11.0, DARK_RED, 0.4)
    noisy = np.clip(bg + rng.normal(0.0, sigma, bg.shape), 0, 255).astype(np.uint8)
    return noisy, cx, cy


@pytest.mark.parametrize("sigma", [6.0, 12.0, 20.0])
def test_noise_level_reads_the_noise_of_a_flat_frame(sigma: float) -> None:
    rng = np.random.default_rng(1)
    frame = np.clip(128.0 + rng.normal(0.0, sigma, (240, 320, 3)), 0, 255).astype(np.uint8)
    assert noise_level(frame) == pytest.approx(sigma * GREY_OF_CHANNEL_NOISE, rel=0.2)


@pytest.mark.parametrize("name", vi.TUNING)
def test_noise_level_leaves_a_clean_photo_under_the_bar_and_its_noisy_copy_over_it(name: str) -> None:
    photo = cv2.resize(vi.photo(name), (320, 240), interpolation=cv2.INTER_AREA)
    noisy = np.clip(photo + np.random.default_rng(2).normal(0.0, 10.0, photo.shape), 0, 255).astype(np.uint8)
    assert noise_level(photo) < NOISY <= noise_level(noisy)


@pytest.mark.parametrize("name", vi.TUNING)
def test_noise_level_is_immerkaers_estimate_to_the_grey_level(name: str) -> None:
    """The two passes of [1, -2, 1] (noise.py) give the 3x3 mask's response exactly, at the frame's border too."""
    mask = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32)
    photo = cv2.resize(vi.photo(name), (321, 239), interpolation=cv2.INTER_AREA)
    for frame in (photo, np.clip(photo + np.random.default_rng(3).normal(0.0, 9.0, photo.shape), 0, 255)
                  .astype(np.uint8)):
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        response = cv2.convertScaleAbs(cv2.filter2D(grey, cv2.CV_16S, mask))
        median = int(np.searchsorted(np.cumsum(np.bincount(response.ravel(), minlength=256)), response.size / 2.0))
        assert noise_level(frame) == 1.4826 * median / 6.0


def found_at(det: HsvBlobDetector, frame: np.ndarray, cx: float, cy: float) -> bool:
    cands = det.candidates(frame)
    return bool(cands) and cands[0].score >= 0.6 and math.hypot(cands[0].cx - cx, cands[0].cy - cy) <= 3.0


@pytest.mark.parametrize("sigma", [10.0, 15.0])
def test_a_dark_ball_in_a_noisy_frame_is_found_on_the_frame_smoothed(
    sigma: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    frames = [dim_frame(seed, sigma) for seed in range(12)]
    det = HsvBlobDetector()
    assert sum(found_at(det, *f) for f in frames) >= 11
    monkeypatch.setattr(hsv_module, "smoothed", lambda image: None)  # without the smoothed look: noise frays it
    assert sum(found_at(det, *f) for f in frames) <= 2


def test_a_noisy_frame_without_a_ball_shows_none() -> None:
    det = HsvBlobDetector()
    for seed in range(12):
        frame, _, _ = dim_frame(seed, 15.0, ball=False)
        assert all(c.score < 0.6 for c in det.candidates(frame))


def test_the_aim_check_reads_a_noisy_frame_smoothed(monkeypatch: pytest.MonkeyPatch) -> None:
    det = HsvBlobDetector()
    on = [dim_frame(seed, 15.0, centred=True)[0] for seed in range(8)]
    off = [dim_frame(seed, 15.0, ball=False)[0] for seed in range(8)]
    assert all(det.aim_on_target(f, 22.0) for f in on)
    assert not any(det.aim_on_target(f, 22.0) for f in off)
    monkeypatch.setattr(hsv_colour, "noisy", lambda image: False)  # read as it is: noise hides the ball's middle
    assert not any(det.aim_on_target(f, 22.0) for f in on)


def test_real_photos_in_a_dark_room_at_full_gain(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tuning photos at a quarter of the light, the gain at 4 and noise of 10-20 per channel (bench/vision's
    full-gain views): most balls found, more than without the smoothed look, nothing in the empty views."""
    views = ve.samples(vi.TUNING, 17, 150, 0, 0, "ball", (16.0, 120.0), (vi.FULL_GAIN,))
    rng = np.random.default_rng(18)
    views += [vi.empty_sample(rng, vi.TUNING, vi.FULL_GAIN) for _ in range(60)]

    def rates() -> tuple[float, float]:
        records = ve.run(HsvBlobDetector().candidates, views)
        return ve.target_rows(records, 0.6, 16)[0].rate, ve.false_rows(records, 0.6, "empty")[-1].rate

    recall, empty = rates()
    monkeypatch.setattr(hsv_module, "smoothed", lambda image: None)
    recall_without, _ = rates()
    assert recall >= 0.75 and empty == 0.0
    assert recall >= recall_without + 0.03  # 150 views: 4.6 points here, 12 on bench/vision's 400
