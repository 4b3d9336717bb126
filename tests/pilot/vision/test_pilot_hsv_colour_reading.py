"""How the colour-ball detector reads a blob's colour where the whole blob's mean would hold its score down
(hsv/measure.py): a small round blob's saturation on its core (blur blends a small ball's rim with what lies
behind it, which would make a red ball read as pale as a pink one; a large ball is read whole), and the hue
without the clipped pixels (an over-exposed red ball's lit side reads orange)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt
import pytest
from pilot_synth import matte_ball

import pilot.vision.hsv.measure as hsv_measure
from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.hsv.measure import blob_colour, core_saturation, unclipped_hue

Image = npt.NDArray[np.uint8]
CX, CY = 160, 120
GREY = np.array((120.0, 125.0, 130.0))


def blurred_ball(r: float, pale: float, sigma: float) -> Image:
    """A matte ball of radius ``r`` at (CX, CY) on grey, lit from the upper left, its blue and green ``pale`` times
    its red, blurred (Gaussian, ``sigma`` px)."""
    grey = np.broadcast_to(GREY, (240, 320, 3))
    img = np.asarray(np.clip(matte_ball(grey, CX, CY, r, (pale * 220.0, pale * 220.0, 220.0), 0.4), 0, 255), np.uint8)
    return np.asarray(cv2.GaussianBlur(img, (0, 0), sigma), np.uint8)


def best(img: Image) -> tuple[float, float, float]:
    """The best candidate's score and its offset from the ball's centre, and the saturation read on it."""
    det = HsvBlobDetector()
    found = det.candidates(img)
    assert found, "no candidate at all"
    c = found[0]
    f = next(f for f in det.features(img) if abs(f.cx - c.cx) < 1e-6 and abs(f.cy - c.cy) < 1e-6)
    return c.score, math.hypot(c.cx - CX, c.cy - CY), f.saturation


@pytest.mark.parametrize("r,pale,sigma", [(8, 0.25, 2.0), (9, 0.3, 2.0)])
def test_a_small_blurred_ball_is_read_on_its_core(r: float, pale: float, sigma: float,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    img = blurred_ball(r, pale, sigma)
    score, off, sat = best(img)
    assert score >= 0.6 and off <= 2.0  # the default acquisition threshold
    monkeypatch.setattr(hsv_measure, "CORE_BELOW", 0.0)  # read whole, as before
    whole_score, _, whole_sat = best(img)
    assert whole_score < 0.6
    assert sat >= whole_sat + 5.0


@pytest.mark.parametrize("r,pale", [(20, 0.3), (30, 0.4)])
def test_a_large_ball_is_read_whole(r: float, pale: float, monkeypatch: pytest.MonkeyPatch) -> None:
    """A pink ball's core is as pale as its rim, and a large ball's rim is a small part of it: read whole, the pink
    balls at the threshold stay below it."""
    img = blurred_ball(r, pale, 2.0)
    read = best(img)
    monkeypatch.setattr(hsv_measure, "CORE_BELOW", 0.0)
    assert best(img) == read


def test_core_saturation_reads_the_eroded_mask_and_falls_back_on_the_whole() -> None:
    mask = np.zeros((40, 40), np.uint8)
    cv2.circle(mask, (20, 20), 9, 255, -1)
    hsv = np.zeros((40, 40, 3), np.uint8)
    hsv[..., 0], hsv[..., 1], hsv[..., 2] = 3, 220, 200
    rim = cv2.subtract(mask, cv2.erode(mask, np.ones((3, 3), np.uint8)))
    hsv[rim > 0, 0], hsv[rim > 0, 1] = 9, 120  # a paler rim of another hue
    box = cv2.boundingRect(mask)
    hue, whole = blob_colour(hsv, mask, box)
    assert whole < 200.0 and hue > 3.0  # the rim counts in the whole blob's mean
    assert core_saturation(hsv, mask, box, float(cv2.countNonZero(mask)), whole) == pytest.approx(220.0)
    thin = np.zeros((40, 40), np.uint8)
    cv2.line(thin, (5, 20), (35, 20), 255, 1)  # nothing left once eroded: the whole blob's
    assert core_saturation(hsv, thin, cv2.boundingRect(thin), float(cv2.countNonZero(thin)), 123.0) == 123.0


def lit_ball(r: float, hue: int, gain: float) -> Image:
    """A matte ball of hue ``hue`` (OpenCV units) at (CX, CY) on a dull green-grey, lit from the upper left, the
    frame's exposure ``gain`` times too high (clipped at 255, as a camera's is)."""
    base = cv2.cvtColor(np.array([[[hue, 210, 210]]], np.uint8), cv2.COLOR_HSV2BGR).reshape(3).astype(np.float64)
    bg = np.broadcast_to(np.array((90.0, 110.0, 100.0)), (240, 320, 3))
    img = matte_ball(bg, CX, CY, r, (float(base[0]), float(base[1]), float(base[2])), 0.35)
    return np.asarray(np.clip(img * gain, 0, 255), np.uint8)


@pytest.mark.parametrize("hue", [4, 176])  # red, a little towards orange and towards magenta
def test_an_over_exposed_ball_keeps_its_hue(hue: int, monkeypatch: pytest.MonkeyPatch) -> None:
    bright = lit_ball(20, hue, 1.8)
    score, off, _ = best(bright)
    assert score >= 0.6 and off <= 2.0
    monkeypatch.setattr(hsv_measure, "CLIPPED", 256)  # every pixel's hue read, clipped or not
    assert best(bright)[0] < 0.6
    well_exposed = lit_ball(20, hue, 1.0)
    every_pixel = best(well_exposed)
    monkeypatch.undo()
    assert best(well_exposed) == every_pixel and every_pixel[0] >= 0.6  # nothing clips: the same reading


def test_unclipped_hue_leaves_out_the_clipped_pixels_and_falls_back_on_the_whole() -> None:
    mask = np.zeros((40, 40), np.uint8)
    cv2.circle(mask, (20, 20), 9, 255, -1)
    hsv = np.zeros((40, 40, 3), np.uint8)
    hsv[..., 0], hsv[..., 1], hsv[..., 2] = 2, 220, 180
    hsv[:20, :, 0], hsv[:20, :, 2] = 12, 255  # the upper half clipped, its hue drifted
    box = cv2.boundingRect(mask)
    area = float(cv2.countNonZero(mask))
    hue, _ = blob_colour(hsv, mask, box)
    assert hue > 5.0
    assert unclipped_hue(hsv, mask, box, area, hue) == pytest.approx(2.0)
    hsv[..., 2] = 255  # all clipped: nothing to read instead
    assert unclipped_hue(hsv, mask, box, area, hue) == hue
