"""A ball's middle is lit as a dome (hsv/dome.py): the circle look takes a circle whose rim is short of whole
when its middle stands above its limb, as a ball lit from the camera's side does; a flat disc, a cup, or a ball
lit from behind is not domed and gets nothing more than before."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from pilot_synth import CX, CY, matte_ball, on_surface, red_surface

import pilot.vision.hsv.circles as hsv_circles
import pilot.vision.hsv.detector as hsv
from pilot.vision.hsv.dome import domed
from pilot.vision.hsv.rim import WHOLE, best_rim

RED = (40.0, 40.0, 210.0)  # BGR where the light falls square on it


def ball(elevation: float, azimuth: float, back: float = 120.0) -> np.ndarray:
    """A matte red ball 24 px across at (60, 45), lit from ``elevation`` degrees towards the camera (negative: from
    behind) and ``azimuth`` round it, on a grey ground of ``back``."""
    e, a = math.radians(elevation), math.radians(azimuth)
    light = (math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e))
    img = matte_ball(np.full((90, 120, 3), back), 60.0, 45.0, 12.0, RED, 0.3, light)
    return np.asarray(np.clip(img, 0, 255), np.uint8)


@pytest.mark.parametrize("elevation", [35.0, 50.0, 70.0, 90.0])
def test_a_ball_lit_from_the_camera_s_side_is_domed(elevation: float) -> None:
    for azimuth in range(0, 360, 45):
        for back in (30.0, 230.0):
            assert domed(ball(elevation, azimuth, back), 60.0, 45.0, 12.0), (elevation, azimuth, back)


@pytest.mark.parametrize("elevation", [-45.0, 0.0, 15.0])
def test_a_ball_lit_from_behind_or_grazing_is_not_domed(elevation: float) -> None:
    """The safe failure: such a ball gets no more than it had before the dome."""
    assert not any(domed(ball(elevation, azimuth), 60.0, 45.0, 12.0) for azimuth in range(0, 360, 45))


def test_a_flat_disc_and_a_cup_are_not_domed() -> None:
    flat = np.full((90, 120, 3), 120, np.uint8)
    cv2.circle(flat, (60, 45), 12, (40, 40, 200), -1, cv2.LINE_AA)
    yy, xx = np.mgrid[0:90, 0:120].astype(np.float64)
    rho = np.hypot(xx - 60, yy - 45) / 12.0
    cup = np.where((rho < 1.0)[..., None], (0.35 + 0.65 * np.clip(rho, 0.0, 1.0))[..., None] * np.array(RED), 120.0)
    for img in (flat, np.asarray(cup, np.uint8)):
        assert not domed(img, 60.0, 45.0, 12.0)


def test_a_circle_reaching_out_of_the_frame_is_not_domed() -> None:
    img = ball(60.0, 0.0)
    assert not domed(img, 5.0, 45.0, 12.0) and not domed(img, 60.0, 45.0, 60.0)
    assert not domed(img[:2, :2], 1.0, 1.0, 4.0)


def short_rim(rim: float, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every circle the circle look measures reads ``rim`` (its centre and radius as measured): a ball whose rim
    JPEG's blocks or a dark ground broke in places."""
    monkeypatch.setattr(hsv_circles, "best_rim", lambda *a, **k: (rim, *best_rim(*a, **k)[1:]))


@pytest.mark.parametrize("seed", [0, 1])
def test_a_domed_ball_with_a_broken_rim_on_a_surface_of_its_colour_is_found(
        seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    img = on_surface(12, seed, 40)  # found by the circle look only (test_pilot_hsv_circles.py)
    short_rim(hsv_circles.DOMED_RIM, monkeypatch)
    found = hsv.HsvBlobDetector().candidates(img)
    assert found and found[0].score >= 0.6 and math.hypot(found[0].cx - CX, found[0].cy - CY) <= 3.0
    short_rim(hsv_circles.DOMED_RIM - 0.05, monkeypatch)  # under the bar: as before the dome, nothing
    found = hsv.HsvBlobDetector().candidates(img)
    assert not found or found[0].score < 0.6
    monkeypatch.setattr(hsv_circles, "domed", lambda *a: False)  # a rim at the bar, but not domed: nothing
    short_rim(hsv_circles.DOMED_RIM, monkeypatch)
    found = hsv.HsvBlobDetector().candidates(img)
    assert not found or found[0].score < 0.6


def test_a_flat_disc_with_a_broken_rim_on_the_surface_gives_no_circle(monkeypatch: pytest.MonkeyPatch) -> None:
    """A red sticker on a red surface, voted for where it is: a circle of edges with the mask inside, but level in
    its middle; a ball in its place gives a domed circle."""
    short_rim(WHOLE - 0.05, monkeypatch)
    monkeypatch.setattr(hsv_circles, "centres", lambda image, near, r_max: [(float(CX), float(CY), 12.0)])
    mask = np.full((240, 320), 255, np.uint8)
    for seed in range(3):
        sticker = red_surface(seed, 20).astype(np.uint8)
        cv2.circle(sticker, (CX, CY), 12, (40, 40, 170), -1, cv2.LINE_AA)
        assert hsv_circles.circles(sticker, mask, sticker, 0, 0) == []
        ball_on = on_surface(12, seed, 20)
        found = hsv_circles.circles(ball_on, mask, ball_on, 0, 0)
        assert found and all(c.domed and math.hypot(c.cx - CX, c.cy - CY) <= 3.0 for c in found)


def test_a_domed_circle_counts_only_where_no_circle_has_a_whole_rim(monkeypatch: pytest.MonkeyPatch) -> None:
    """A window's circles with a whole rim are what they were; its domed circles are only looked at without them
    (each domed circle beside a whole one would have made the window a texture of round things)."""
    whole = hsv_circles.Circle(30.0, 30.0, 12.0, 1.0, 0.9)
    dome = hsv_circles.Circle(70.0, 30.0, 12.0, 1.0, 0.75, domed=True)
    rims = {(30.0, 30.0): whole, (70.0, 30.0): dome}
    monkeypatch.setattr(hsv_circles, "centres", lambda image, near, r_max: [(30.0, 30.0, 12.0), (70.0, 30.0, 12.0)])
    monkeypatch.setattr(hsv_circles, "best_rim", lambda frame, cx, cy, r, colour: (rims[cx, cy].rim, cx, cy, r))
    monkeypatch.setattr(hsv_circles, "domed", lambda *a: True)
    img, mask = np.zeros((60, 100, 3), np.uint8), np.full((60, 100), 255, np.uint8)
    assert hsv_circles.circles(img, mask, img, 0, 0) == [whole, whole]  # voted in brightness and in colour
    rims[30.0, 30.0] = whole._replace(rim=0.5)
    assert hsv_circles.circles(img, mask, img, 0, 0) == [dome, dome]
