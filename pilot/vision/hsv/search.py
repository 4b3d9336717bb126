"""The colour-ball detector's (detector.py) search frame: the frame at half resolution from ``SEARCH_MIN_WIDTH`` px
wide (as it is below), its bounds for the frame's exposure, its HSV, and the first look's mask, each written into a
buffer kept from frame to frame. Written into, not allocated, they stay in the caches: 3-4 % of a frame at 320x240.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

from ..detection import frame_size
from .colour import Bounds, ColourMask

SEARCH_MIN_WIDTH = 320  # frames at least this wide are searched at half resolution
BUFFERS_KEPT = 6  # buffer pairs kept at most (three a frame size: two looks' frames and HSV, a mask and its opening)


class SearchFrames:
    def __init__(self, colour: ColourMask) -> None:
        self.colour = colour
        self._buffers: dict[tuple[int, int, int], tuple[MatLike, MatLike]] = {}  # by width, height and slot

    def search(self, image: MatLike, scale: int, look: int = 0) -> tuple[MatLike, Bounds, MatLike]:
        """The search's frame (``scale`` times smaller), its bounds for the frame's exposure, and its HSV; ``look``:
        0 for the frame, 1 for its smoothed copy, which must not overwrite the first look's (a rim look measures
        its blobs again)."""
        w, h = frame_size(image)
        size = (w // scale, h // scale)
        frame, hsv = self._pair(size, look, 3)
        small = cv2.resize(image, size, dst=frame, interpolation=cv2.INTER_AREA) if scale > 1 else image
        bounds = self.colour.bounds_for(small)  # the exposure read where the resize has just been: in cache
        return small, bounds, cv2.cvtColor(small, self.colour.code, dst=hsv)

    def mask_buffers(self, size: tuple[int, int]) -> tuple[MatLike, MatLike]:
        """The first look's mask before and after its opening, for a search of ``size``."""
        return self._pair(size, 2, 1)

    def _pair(self, size: tuple[int, int], slot: int, channels: int) -> tuple[MatLike, MatLike]:
        """Two buffers of ``size`` for ``slot`` (0 and 1: a look's frame and HSV; 2: the mask and its opening). A
        frame searched as it is leaves its slot's first buffer unused (57 kB at 160x120: not worth a second key)."""
        key = (*size, slot)
        pair = self._buffers.get(key)
        if pair is None:
            if len(self._buffers) >= BUFFERS_KEPT:  # frame sizes changing: keep the newest only
                self._buffers.clear()
            shape = (size[1], size[0], channels) if channels > 1 else (size[1], size[0])
            pair = self._buffers[key] = (np.empty(shape, np.uint8), np.empty(shape, np.uint8))
        return pair
