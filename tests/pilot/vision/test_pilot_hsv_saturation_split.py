"""The colour-ball detector's split by saturation (hsv/split.py, hsv/refine.py): a ball lying on a
glossy surface of its own hue is one blob with it in the mask and in hue, and stands apart by its purity (the
surface's colour is purer) and its rim. A pattern of round things of that kind is not a ball."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from pilot_synth import best_hsv, matte_ball

import pilot.vision.hsv.split as hsv_split
from pilot.vision.hsv.detector import HsvBlobDetector

SURFACE = (10.0, 40.0, 190.0)  # BGR: hue 5 (OpenCV units), saturation 241; shaded from 0.8 to 1.05 of it
BALL = (45.0, 60.0, 215.0)  # hue 3 (under HUE_GAP from the surface's), saturation 201
CX, CY, R = 150.0, 110.0, 14.0


def saucer() -> np.ndarray:
    """Where the saucer lies in the frame: an ellipse."""
    mask = np.zeros((240, 320), np.uint8)
    cv2.ellipse(mask, (160, 120), (140, 75), 0.0, 0.0, 360.0, 255, -1)
    return mask


def surface() -> np.ndarray:
    """A grey table with a saucer on it: the surface, its brightness falling off from left to right (its hue and
    saturation the same everywhere)."""
    img = np.full((240, 320, 3), 120.0)
    on = saucer() > 0
    shade = np.linspace(1.05, 0.8, 320)[None, :, None]
    img[on] = (np.ones((240, 320, 1)) * shade * np.array(SURFACE))[on]
    return img


def frame(balls: list[tuple[float, float]], r: float = R) -> np.ndarray:
    img = surface()
    for cx, cy in balls:
        img = matte_ball(img, cx, cy, r, BALL, 0.35)
    return np.asarray(np.clip(img + 0.5, 0, 255), np.uint8)


def test_the_frame_is_one_blob_in_hue() -> None:
    """The premise: the ball and the surface are both in the target's range, in one hue class."""
    img = frame([(CX, CY)])
    hsv = cv2.cvtColor(img, cv2.COLOR_RGB2HSV)  # the detector's mirrored hue (red at 120)
    mask = saucer()
    assert hsv_split.two_classes(np.ascontiguousarray(hsv[..., 0]), mask, 100, hsv_split.HUE_GAP) is None
    assert hsv_split.two_classes(np.ascontiguousarray(hsv[..., 1]), mask, 100, hsv_split.SAT_GAP) is not None


def test_a_ball_on_a_surface_of_its_hue_is_split_off_by_saturation(monkeypatch: pytest.MonkeyPatch) -> None:
    img = frame([(CX, CY)])
    found = best_hsv(img)
    assert found is not None
    x, y, score = found
    assert score >= 0.6 and abs(x - CX) <= 2.0 and abs(y - CY) <= 2.0
    monkeypatch.setattr(hsv_split, "SAT_GAP", 256.0)  # no split by saturation: nothing at the ball
    without = best_hsv(img)
    assert without is None or without[2] < 0.6 or abs(without[0] - CX) > R


def pieces(img: np.ndarray) -> list[tuple[tuple[int, int, int, int], int]]:
    """What the split by colour yields for the frame's saucer: each piece's box and the channel split."""
    det = HsvBlobDetector()
    hsv = cv2.cvtColor(img, det.colour.code)
    mask = det.colour.clean(det.colour.in_range(hsv, det.colour.ranges))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    c = max(contours, key=cv2.contourArea)
    x, y, w, h = cv2.boundingRect(c)
    joined = [(float(cv2.contourArea(c)), c, (x, y, w, h))]
    return [(box, ch) for _, box, ch in hsv_split.colour_pieces(hsv, mask, joined, det.colour.ranges, 30.0, 0.45,
                                                                 det.colour.clean)]


def test_a_ball_is_a_piece_of_its_saturation_class() -> None:
    found = pieces(frame([(CX, CY)]))
    assert found and all(ch == hsv_split.SATURATION for _, ch in found)
    (x, y, w, h), _ = found[0]
    assert abs(x + w / 2.0 - CX) <= 2.0 and abs(y + h / 2.0 - CY) <= 2.0


def test_round_pieces_of_a_size_in_one_saturation_class_are_a_texture(monkeypatch: pytest.MonkeyPatch) -> None:
    """Five such discs in a row, 3 diameters apart, are a print of round things (a dahlia's cups), not a ball on a
    surface: their class gives no piece. Without the pattern rule, its two largest would be refined."""
    img = frame([(60.0 + 60.0 * k, CY) for k in range(5)], r=12.0)
    assert not [p for p in pieces(img) if abs(p[0][1] + p[0][3] / 2.0 - CY) <= 2.0]
    monkeypatch.setattr(hsv_split, "_patterned", lambda _: False)
    assert len([p for p in pieces(img) if abs(p[0][1] + p[0][3] / 2.0 - CY) <= 2.0]) == hsv_split.CLASS_PIECES
