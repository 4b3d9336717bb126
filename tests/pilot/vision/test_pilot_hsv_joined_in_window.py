"""A ball round in the colour-ball detector's half-resolution search, joined in its full-resolution window to a strip
of its colour that the search's opening took off (a rail, a beam): the window measures nothing, and the ball is split
off by shape (hsv/detector.py, step 3). A square joined the same way stays out."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from pilot_synth import best_hsv, matte_ball

import pilot.vision.hsv.detector as hsv

GREY = (150.0, 160.0, 170.0)  # BGR
RED = (40.0, 40.0, 200.0)
CX, CY = 100.0, 120.0


def frame(r: float, strip: int, square: bool = False) -> np.ndarray:
    """A red ball (or an axis-aligned square) of radius ``r`` on grey, a red strip ``strip`` px wide and 40 long
    running from its right edge: too thin for the search's opening at half resolution, not for the window's."""
    img = np.full((240, 320, 3), GREY)
    x0, y0 = int(CX + r - 2), int(CY) - strip // 2
    cv2.rectangle(img, (x0, y0), (x0 + 40, y0 + strip - 1), RED, -1)
    if square:
        cv2.rectangle(img, (int(CX - r), int(CY - r)), (int(CX + r), int(CY + r)), RED, -1)
    else:
        img = matte_ball(img, CX, CY, r, RED, 0.35)
    return np.asarray(np.clip(img + 0.5, 0, 255), np.uint8)


@pytest.mark.parametrize("strip", [3, 4])
def test_a_ball_joined_in_its_window_is_split_off(strip: int, monkeypatch: pytest.MonkeyPatch) -> None:
    img = frame(8.5, strip)
    found = best_hsv(img)
    assert found is not None and found[2] >= 0.6
    assert abs(found[0] - CX) <= 2.0 and abs(found[1] - CY) <= 2.0
    monkeypatch.setattr(hsv, "UNREFINED_SHAPE", 2.0)  # no piece of such a blob counts: the detector before
    before = best_hsv(img)
    assert before is None or before[2] < 0.6


@pytest.mark.parametrize(("r", "strip"), [(8.5, 2), (8.5, 3), (8.5, 4), (11.0, 3), (11.0, 4)])
def test_a_square_joined_in_its_window_is_not_a_ball(r: float, strip: int) -> None:
    """Opened, a square's corners round off; the search blob measured at half resolution is no ball, so it is not
    split (the ball above, with the same strip, is). Split without that check, each of these scored 0.79-0.97."""
    found = best_hsv(frame(r, strip, square=True))
    assert found is None or found[2] < 0.6
