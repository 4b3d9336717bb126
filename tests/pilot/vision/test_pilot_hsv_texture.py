"""The colour-ball detector's texture check (hsv/texture.py): a pattern of round things of the target's colour
(a polka-dot print, a flower's cups) is not a ball, however round each dot; a ball among things of its colour that
are not round, or not its size, still is."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from pilot_synth import RED, background

import pilot.vision.hsv.measure as hsv_measure
from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.hsv.score import SIZE
from pilot.vision.hsv.texture import PEERS, PEERS_SMALL, textured

CX, CY, R = 160, 120, 10


def dots(spacing: int, r: int = R) -> np.ndarray:
    """A frame tiled with red discs of radius ``r``, one of them at the centre."""
    img = background(320, 240)
    for y in range(CY % spacing, 240, spacing):
        for x in range(CX % spacing, 320, spacing):
            cv2.circle(img, (x, y), r, RED, -1, lineType=cv2.LINE_AA)
    return img


def fires(img: np.ndarray) -> bool:
    found = HsvBlobDetector().candidates(img)
    return bool(found) and found[0].score >= 0.6  # the default acquisition threshold


@pytest.mark.parametrize("spacing", [30, 45])  # every dot has PEERS within REACH diameters
def test_a_polka_dot_print_is_not_a_ball(spacing: int, monkeypatch: pytest.MonkeyPatch) -> None:
    img = dots(spacing)
    assert not fires(img)
    monkeypatch.setattr(hsv_measure, "textured", lambda *_: False)
    assert fires(img)  # each dot alone would be one


def small_dots(n: int) -> np.ndarray:
    """``n`` red discs 15 px across (under SIZE's one) on a circle of 23 px radius round the frame's centre (three
    are 40 px apart)."""
    img = background(320, 240)
    for a in np.linspace(0.0, 2.0 * math.pi, n, endpoint=False):
        cv2.circle(img, (round(CX + 23 * math.cos(a)), round(CY + 23 * math.sin(a))), 7, RED, -1, lineType=cv2.LINE_AA)
    return img


def test_three_small_dots_are_a_pattern(monkeypatch: pytest.MonkeyPatch) -> None:
    # each has PEERS_SMALL of its size within REACH diameters: a flower's cups, not three balls side by side
    img = small_dots(PEERS_SMALL + 1)
    assert not fires(img)
    monkeypatch.setattr(hsv_measure, "textured", lambda *_: False)
    assert fires(img)  # each dot alone would be one


def test_two_small_balls_are_balls() -> None:
    assert fires(small_dots(PEERS_SMALL))  # one peer each


def test_sparse_dots_are_balls() -> None:
    # peers further than REACH diameters: a few balls on a floor, not a print
    assert fires(dots(100))


def test_a_ball_among_red_bars_and_specks_is_found() -> None:
    img = background(320, 240)
    cv2.circle(img, (CX, CY), R, RED, -1, lineType=cv2.LINE_AA)
    for k in range(6):  # bars its length, not round; specks a third its size
        a = 2.0 * math.pi * k / 6
        x, y = int(CX + 45 * math.cos(a)), int(CY + 45 * math.sin(a))
        cv2.rectangle(img, (x - 10, y - 2), (x + 10, y + 2), RED, -1)
        cv2.circle(img, (int(CX + 25 * math.cos(a + 0.5)), int(CY + 25 * math.sin(a + 0.5))), 3, RED, -1)
    det = HsvBlobDetector()
    found = det.candidates(img)
    assert found and found[0].score >= 0.6
    assert math.hypot(found[0].cx - CX, found[0].cy - CY) <= 2.0
    # the bars are search blobs its size all round it, but not round ones: only those are a texture's peers
    assert textured(CX, CY, 2 * R + 1, det._blobs, det.search_scale)
    assert not textured(CX, CY, 2 * R + 1, det.round_search, det.search_scale)


def test_peers_are_counted_by_size_and_distance() -> None:
    def blob(cx: float, cy: float, d: int) -> tuple[float, np.ndarray, tuple[int, int, int, int]]:
        return (0.78 * d * d, np.zeros((0, 1, 2), np.int32), (int(cx - d / 2), int(cy - d / 2), d, d))

    own = blob(100, 100, 20)
    ring = [blob(100 + 50 * math.cos(a), 100 + 50 * math.sin(a), 20) for a in np.linspace(0, 6, PEERS)]
    assert textured(100, 100, 20, [own, *ring], 1)
    assert not textured(100, 100, 20, [own, *ring[:-1]], 1)  # one short
    far = [blob(100 + 120 * math.cos(a), 100 + 120 * math.sin(a), 20) for a in np.linspace(0, 6, PEERS)]
    assert not textured(100, 100, 20, [own, *far], 1)  # beyond REACH diameters
    small = [blob(x + 5, y + 5, 8) for _, _, (x, y, _, _) in ring]
    assert not textured(100, 100, 20, [own, *small], 1)  # not its size
    # under SIZE's one, PEERS_SMALL peers make a pattern; at it, they do not
    small_own, at_one = blob(100, 100, 16), blob(100, 100, int(SIZE[1]))
    pair = [blob(100 + 40 * math.cos(a), 100 + 40 * math.sin(a), 16) for a in np.linspace(0, 3, PEERS_SMALL)]
    assert textured(100, 100, 16, [small_own, *pair], 1)
    assert not textured(100, 100, 16, [small_own, *pair[:-1]], 1)  # one short
    assert not textured(100, 100, SIZE[1], [at_one, *pair], 1)
    half = [blob(50 + 25 * math.cos(a), 50 + 25 * math.sin(a), 10) for a in np.linspace(0, 6, PEERS)]
    assert textured(100, 100, 20, [blob(50, 50, 10), *half], 2)  # the search at half resolution
