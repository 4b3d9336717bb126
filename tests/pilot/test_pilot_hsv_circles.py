"""The colour-ball detector's circle look (pilot/hsv_circles.py): a shaded ball lying on a textured surface of its
own colour, which no mask separates, is found by the circle of brightness edges round it, and only in a frame
where nothing else is; a red square or an open arc on the same surface is not made a ball."""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt
import pytest

import pilot.hsv as hsv
import pilot.hsv_circles as hsv_circles
from pilot.hsv_circles import centres, circles, inside_share

Image = npt.NDArray[np.uint8]
CX, CY = 160, 120


def red_surface(seed: int, texture: float, value: float = 90.0) -> npt.NDArray[np.float64]:
    """A red surface whose brightness varies in blotches about 6 px across (BGR, float)."""
    blotches = cv2.GaussianBlur(np.random.default_rng(seed).normal(0.0, 1.0, (240, 320)), (0, 0), 3)
    v = np.clip(value + texture * blotches / blotches.std(), 0, 255)
    return np.stack([0.2 * v, 0.2 * v, v], axis=-1)


def on_surface(r: float, seed: int, texture: float) -> Image:
    """A matte red ball of radius ``r`` at (CX, CY), lit from the upper left, on ``red_surface``."""
    img = red_surface(seed, texture)
    yy, xx = np.mgrid[0:240, 0:320].astype(np.float64)
    dx, dy = (xx - CX) / r, (yy - CY) / r
    nz = np.sqrt(np.clip(1.0 - dx * dx - dy * dy, 0.0, 1.0))
    lit = np.clip(-0.5 * dx - 0.5 * dy + math.sqrt(0.5) * nz, 0.0, 1.0)
    shade = 220.0 * (0.3 + 0.7 * lit)
    alpha = np.clip(r + 0.5 - np.hypot(xx - CX, yy - CY), 0.0, 1.0)[..., None]
    ball = np.stack([0.15 * shade, 0.15 * shade, shade], axis=-1)
    return np.asarray(np.clip(img * (1.0 - alpha) + ball * alpha, 0, 255), np.uint8)


@pytest.mark.parametrize("r,seed,texture", [(9, 0, 20), (9, 1, 40), (12, 0, 40), (12, 1, 40)])
def test_a_ball_on_a_surface_of_its_colour_is_found_by_the_circle_look_only(
        r: float, seed: int, texture: float, monkeypatch: pytest.MonkeyPatch) -> None:
    img = on_surface(r, seed, texture)
    found = hsv.HsvBlobDetector().candidates(img)
    assert found and found[0].score >= 0.6  # the default acquisition threshold
    assert math.hypot(found[0].cx - CX, found[0].cy - CY) <= 3.0
    assert 2 * r - 5.0 <= found[0].size <= 2 * r + 2.0  # its shading's edges may pull the circle in a little
    monkeypatch.setattr(hsv, "CIRCLE_BLOBS", 0)
    without = hsv.HsvBlobDetector().candidates(img)
    assert not without or without[0].score < 0.6 or math.hypot(without[0].cx - CX, without[0].cy - CY) > r


def test_a_red_square_or_an_open_arc_on_the_surface_is_not_a_ball() -> None:
    for seed in range(3):
        square = red_surface(seed, 20).astype(np.uint8)
        cv2.rectangle(square, (CX - 12, CY - 12), (CX + 12, CY + 12), (30, 30, 200), -1)
        arc = red_surface(seed, 20).astype(np.uint8)  # three quarters of a circle drawn on it
        cv2.ellipse(arc, (CX, CY), (12, 12), 0, 0, 270, (10, 10, 50), 2, cv2.LINE_AA)
        for img in (square, arc):
            found = hsv.HsvBlobDetector().candidates(img)
            assert not found or found[0].score < 0.6


def test_the_votes_find_a_drawn_circle() -> None:
    grey = np.full((120, 160), 60, np.uint8)
    cv2.circle(grey, (70, 55), 20, 200, -1, cv2.LINE_AA)
    mask = np.full((120, 160), 255, np.uint8)
    (cx, cy, r), *_ = centres(grey, mask, 60.0)
    assert math.hypot(cx - 70, cy - 55) <= 2.0 and abs(r - 20) <= 0.15 * 20
    assert inside_share(mask, cx, cy, r) == 1.0
    assert inside_share(mask, 5.0, 5.0, 20.0) == 0.0  # reaching out of the window


def test_no_votes_no_circles() -> None:
    flat = np.full((40, 40), 120, np.uint8)
    assert centres(flat, np.full((40, 40), 255, np.uint8), 20.0) == []  # no edges
    tiny = np.zeros((9, 9), np.uint8)
    tiny[2:7, 2:7] = 200
    assert centres(tiny, np.full((9, 9), 255, np.uint8), 4.0) == []  # no radius fits the window
    bgr = cv2.cvtColor(flat, cv2.COLOR_GRAY2BGR)
    assert circles(bgr, np.zeros((40, 40), np.uint8), bgr, 0, 0) == []  # edges, but none near the mask


def test_a_plain_ball_never_pays_for_the_circle_look(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    looked = hsv_circles.circle_features

    def counted(*args: object) -> object:
        calls.append(1)
        return looked(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(hsv, "circle_features", counted)
    img = np.full((240, 320, 3), (200, 170, 60), np.uint8)
    cv2.circle(img, (CX, CY), 16, (40, 40, 200), -1, cv2.LINE_AA)
    found = hsv.HsvBlobDetector().candidates(img)
    assert found and found[0].score >= 0.9 and not calls
    hsv.HsvBlobDetector().candidates(on_surface(12, 0, 40))
    assert calls  # the same counter sees the circle look run
