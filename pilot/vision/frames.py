"""Frame checks before any detection: a malformed, black, saturated or frozen frame is named, never searched.

The checks look at a sparse grid of about 32x24 pixels, so they cost a few microseconds at any frame size.
A real sensor's noise never repeats a frame exactly: identical grids ``frozen_frames`` times in a row mean
the camera (or its driver) has stopped and is handing out its last frame.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .detection import FrameStatus, malformed

BLACK_LEVEL = 12  # brightest channel at or below this: black
SATURATED_LEVEL = 250  # darkest channel at or above this: blown out
DEAD_SHARE = 0.98  # share of the grid that must be black (or saturated) for the frame to be


class FrameCheck:
    def __init__(self, frozen_frames: int = 5) -> None:
        self.frozen_frames = frozen_frames
        self.size: tuple[int, int] | None = None  # locked by the first good frame
        self._last: npt.NDArray[np.uint8] | None = None
        self._repeats = 0

    def check(self, image: object) -> FrameStatus:
        if (bad := malformed(image)) is not None:
            return bad
        assert isinstance(image, np.ndarray)  # malformed() made sure; for the type checker
        h, w = image.shape[:2]
        if self.size is not None and self.size != (w, h):
            return FrameStatus.WRONG_SHAPE
        step = max(2, w // 32)
        grid: npt.NDArray[np.uint8] = image[::step, ::step].copy()
        alive = (1.0 - DEAD_SHARE) * grid.size  # channel values, not pixels: cheaper, and as telling
        if np.count_nonzero(grid > BLACK_LEVEL) <= alive:
            return FrameStatus.BLACK
        if np.count_nonzero(grid < SATURATED_LEVEL) <= alive:
            return FrameStatus.SATURATED
        if self._last is not None and np.array_equal(grid, self._last):
            self._repeats += 1
        else:
            self._repeats = 0
            self._last = grid
        if self._repeats + 1 >= self.frozen_frames:
            return FrameStatus.FROZEN
        self.size = (w, h)
        return FrameStatus.OK
