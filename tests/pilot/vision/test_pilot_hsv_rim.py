"""The colour-ball detector's rim look (hsv/rim.py, hsv/measure.py): a ball whose colour mask is
frayed (JPEG blocks its colour out at the rim) is found by the brightness edge all round it, and only in a frame
where nothing else is."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt
import pytest

import pilot.vision.hsv.detector as hsv
import pilot.vision.hsv.measure as hsv_measure
import pilot.vision.hsv.rim as hsv_rim
from pilot.vision.hsv.rim import rim_support
from pilot.vision.hsv.score import RIM

Image = npt.NDArray[np.uint8]
WALL, RED = (200, 170, 60), (40, 40, 200)  # BGR: a teal wall, a red ball
CX, CY = 160, 120


def frayed_ball(r: int, band: int, block: int) -> Image:
    """A red disc whose outer ``band`` px are greyed, at the disc's own brightness, in a checkerboard of
    ``block`` px squares: its mask is frayed, its brightness outline whole (what JPEG's colour blocks do)."""
    img = np.full((240, 320, 3), WALL, np.uint8)
    cv2.circle(img, (CX, CY), r, RED, -1, cv2.LINE_AA)
    grey = int(cv2.cvtColor(np.array([[RED]], np.uint8), cv2.COLOR_BGR2GRAY)[0, 0])
    yy, xx = np.mgrid[0:240, 0:320]
    rim = np.hypot(xx - CX, yy - CY) >= r - band
    img[rim & ((xx // block + yy // block) % 2 == 0) & (img[..., 2] > 120)] = grey
    return img


def test_rim_support_tells_a_disc_from_a_square_and_from_noise() -> None:
    disc = np.full((240, 320, 3), WALL, np.uint8)
    cv2.circle(disc, (CX, CY), 16, RED, -1, cv2.LINE_AA)
    square = np.full((240, 320, 3), WALL, np.uint8)
    cv2.rectangle(square, (CX - 16, CY - 16), (CX + 16, CY + 16), RED, -1)
    noise = np.random.default_rng(0).integers(0, 256, (240, 320, 3), np.uint8)
    assert rim_support(disc, CX, CY, 16.0) >= 0.95
    assert rim_support(frayed_ball(16, 5, 3), CX, CY, 16.0) >= 0.95  # the brightness outline is whole
    # a square at its enclosing circle and at its inscribed one (its sides face the centre only near their
    # middles), and noise: below the rim's ramp, so the rim adds nothing to their score
    for support in (rim_support(square, CX, CY, 16.0 * 1.414), rim_support(square, CX, CY, 16.0),
                    rim_support(noise, CX, CY, 16.0)):
        assert support < RIM[0]


@pytest.mark.parametrize("r,band,block", [(16, 5, 3), (24, 7, 5)])
def test_a_frayed_ball_is_found_by_its_rim_and_only_by_it(r: int, band: int, block: int,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    img = frayed_ball(r, band, block)
    found = hsv.HsvBlobDetector().candidates(img)
    assert found and found[0].score >= 0.6  # the default acquisition threshold
    assert abs(found[0].cx - CX) <= 1.5 and abs(found[0].cy - CY) <= 1.5 and abs(found[0].size - 2 * r) <= 3
    monkeypatch.setattr(hsv, "RIM_LOOKS", 0)
    without = hsv.HsvBlobDetector().candidates(img)
    assert not without or without[0].score < 0.6  # its frayed outline alone does not make it a ball


def test_a_plain_ball_never_pays_for_a_rim(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[float] = []

    def counted(bgr: Image, cx: float, cy: float, r: float, colour: bool = False) -> float:
        calls.append(r)
        return rim_support(bgr, cx, cy, r, colour)

    monkeypatch.setattr(hsv_measure, "rim_support", counted)
    img = np.full((240, 320, 3), WALL, np.uint8)
    cv2.circle(img, (CX, CY), 16, RED, -1, cv2.LINE_AA)
    found = hsv.HsvBlobDetector().candidates(img)
    assert found and found[0].score >= 0.9 and not calls
    hsv.HsvBlobDetector().candidates(frayed_ball(16, 5, 3))
    assert calls  # the same counter sees the frayed ball's rim measured


def test_the_rim_does_not_make_a_red_square_a_ball() -> None:
    img = np.full((240, 320, 3), WALL, np.uint8)
    cv2.rectangle(img, (CX - 16, CY - 16), (CX + 16, CY + 16), RED, -1)
    found = hsv.HsvBlobDetector().candidates(img)
    assert not found or found[0].score < 0.6


def test_a_wide_blurred_rim_is_measured_at_half_resolution(monkeypatch: pytest.MonkeyPatch) -> None:
    """A 60 px ball blurred (sigma 4 px) has a rim that is a ramp, too gentle for a 3x3 Sobel at full resolution;
    halved, it is an edge all round, while a square blurred alike still shows only its sides' middles."""
    grey, ball = (120, 120, 120), (40, 40, 160)  # BGR: 44 grey levels apart
    sharp_disc = np.full((240, 320, 3), grey, np.uint8)
    cv2.circle(sharp_disc, (CX, CY), 30, ball, -1, cv2.LINE_AA)
    sharp_square = np.full((240, 320, 3), grey, np.uint8)
    cv2.rectangle(sharp_square, (CX - 30, CY - 30), (CX + 30, CY + 30), ball, -1)
    disc, square = cv2.GaussianBlur(sharp_disc, (0, 0), 4.0), cv2.GaussianBlur(sharp_square, (0, 0), 4.0)
    assert rim_support(disc, CX, CY, 30.0) >= 0.95
    assert max(rim_support(square, CX, CY, 30.0), rim_support(square, CX, CY, 30.0 * 1.414)) < RIM[0]
    monkeypatch.setattr(hsv_rim, "HALF_FROM", 1e9)  # at full resolution only
    assert rim_support(disc, CX, CY, 30.0) < RIM[0]
