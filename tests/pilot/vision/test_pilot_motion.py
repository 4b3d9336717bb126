"""The whole scene's apparent motion between frames (``pilot.vision.motion``): a shifted view reads as a turn of
the camera, a magnified one as a growth, a blank one as nothing."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from cv2.typing import MatLike

from pilot.vision.detection import focal_px
from pilot.vision.motion import SceneMotion

FOV = 60.0
ROOM = cv2.GaussianBlur((np.random.default_rng(1).random((600, 800, 3)) * 255).astype(np.uint8), (7, 7), 0)


def view(yaw_deg: float = 0.0, scale: float = 1.0) -> MatLike:
    """320x240 of a textured plane ahead, the camera turned ``yaw_deg`` right and ``scale`` times nearer."""
    f = focal_px(320, FOV)
    k = np.array([[f, 0, 160], [0, f, 120], [0, 0, 1]])
    a = math.radians(yaw_deg)
    turn = np.array([[math.cos(a), 0, -math.sin(a)], [0, 1, 0], [math.sin(a), 0, math.cos(a)]])
    # the room's pixels (centre 400, 300) seen through the turned camera
    room = np.array([[1 / scale, 0, 400 - 160 / scale], [0, 1 / scale, 300 - 120 / scale], [0, 0, 1]])
    h = room @ k @ turn.T @ np.linalg.inv(k)
    return cv2.warpPerspective(ROOM, h, (320, 240), flags=cv2.WARP_INVERSE_MAP | cv2.INTER_LINEAR)


@pytest.mark.parametrize("yaw", [0.8, -2.4])
def test_a_turned_view_reads_as_the_turn_and_no_growth(yaw: float) -> None:
    """In pixels the frame's edges move further than its centre through a turn: read as angles, a turn of 2.4°
    in a frame (a search's spin) is no growth (it read as 1-2 %)."""
    motion = SceneMotion(FOV)
    assert motion.update(view()) is None  # no frame before
    shift = motion.update(view(yaw))
    assert shift is not None and shift.points >= 12
    assert shift.turn_deg == pytest.approx(yaw, abs=0.05)
    assert shift.scale == pytest.approx(1.0, abs=0.002)


def test_a_magnified_view_reads_as_a_growth_and_no_turn() -> None:
    motion = SceneMotion(FOV)
    motion.update(view())
    shift = motion.update(view(scale=1.02))
    assert shift is not None
    assert shift.scale == pytest.approx(1.02, abs=0.003) and abs(shift.turn_deg) < 0.05


def test_a_blank_wall_or_a_reset_gives_no_reading() -> None:
    motion = SceneMotion(FOV)
    blank = np.full((240, 320, 3), 128, np.uint8)
    motion.update(blank)
    assert motion.update(blank) is None
    motion.update(view())
    motion.reset()
    assert motion.update(view(0.5)) is None
