"""A ball is not hollow: the colour-ball detector's (detector.py) check that a round blob is not a cup.

A convex matte ball lit from one side is brighter than its middle on less than half of any circle around it; a
cup's lit wall is brighter than its shaded inside all round. Read on sectors at a few radii, each counted lit when
brighter than the middle and of the target's colour. Figures: bench/vision/HISTORY.md."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .colour import Bounds, ColourMask
from .shape import unit_circle

SECTORS = 12
RADII = (0.45, 0.575, 0.7)  # of the radius, three (added one by one): inside the rim's blur, clear of the middle
CENTRE = 0.2  # of the radius (1 px at least): the middle's four neighbours, and the middle itself
MARGIN = 8.0  # grey levels a sector must be brighter by (sensor noise at full gain: 10-20 a channel, averaged)
HOLLOW_SECTORS = 7  # of SECTORS: brighter and of the target's colour, more than a lit ball can be...
HOLLOW_SPREAD = 9  # ...and spread over this many in a row at least, the gaps between them included
IN_COLOUR = 2  # of the sector's len(RADII) samples: the sector is of the target's colour

OFFSETS_KEPT = 256  # sample offsets kept (by frame width and diameter in whole pixels)

_MIDDLE_POINTS = ((0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))  # in CENTRE radii
# the ring's samples (row by radius, column by sector), then the middle's
_UNIT_X, _UNIT_Y = np.concatenate([k * unit_circle(SECTORS) for k in RADII] + [np.array(_MIDDLE_POINTS)]).T
_RING = len(RADII) * SECTORS
_MIDDLE = len(_UNIT_X) - _RING
_offsets: dict[tuple[int, int], tuple[npt.NDArray[np.intp], npt.NDArray[np.intp], npt.NDArray[np.intp], int]] = {}


def _samples(width: int, size: float) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp], npt.NDArray[np.intp], int]:
    """The samples' column and row offsets for a blob ``size`` across (in whole pixels), their offsets in a
    frame ``width`` wide, and how far they reach."""
    key = (width, round(size))
    known = _offsets.get(key)
    if known is None:
        r = key[1] / 2.0
        scale = np.concatenate((np.full(_RING, r), np.full(_MIDDLE, max(1.0, CENTRE * r))))
        dx = np.rint(_UNIT_X * scale).astype(np.intp)
        dy = np.rint(_UNIT_Y * scale).astype(np.intp)
        if len(_offsets) >= OFFSETS_KEPT:
            _offsets.clear()
        known = _offsets[key] = (dx, dy, dy * width + dx, int(max(np.abs(dx).max(), np.abs(dy).max())))
    return known


def hollow(image: MatLike, colour: ColourMask, bounds: Bounds, cx: float, cy: float, size: float) -> bool:
    """Whether the blob of diameter ``size`` at (cx, cy) is brighter than its middle, in the target's colour
    (``bounds``), lit and spread as no ball lit from one side is."""
    h, w = image.shape[:2]
    dx, dy, flat, reach = _samples(w, size)
    x, y = round(cx), round(cy)
    pixels = image.reshape(-1, 3)
    if reach <= x < w - reach and reach <= y < h - reach:
        pixels = pixels.take(y * w + x + flat, axis=0)
    else:  # at the frame's edge: the nearest pixel in it
        pixels = pixels.take(np.clip(y + dy, 0, h - 1) * w + np.clip(x + dx, 0, w - 1), axis=0)
    grey = cv2.cvtColor(pixels.reshape(1, -1, 3), cv2.COLOR_BGR2GRAY).ravel().tolist()
    # each sector's samples' sum against as many of the middle's mean (in Python: 41 numbers cost less than numpy's
    # calls on them, 3-10 µs each in a frame)
    bar = (sum(grey[_RING:]) / _MIDDLE + MARGIN) * len(RADII)
    near, mid, far = grey[:SECTORS], grey[SECTORS:2 * SECTORS], grey[2 * SECTORS:_RING]
    brighter = [a + b + c > bar for a, b, c in zip(near, mid, far)]
    if sum(brighter) < HOLLOW_SECTORS:
        return False
    hsv = cv2.cvtColor(pixels[:_RING].reshape(1, _RING, 3), colour.code)
    in_colour = (np.asarray(colour.in_range(hsv, bounds)).reshape(len(RADII), SECTORS) > 0).sum(axis=0).tolist()
    lit = [b and n >= IN_COLOUR for b, n in zip(brighter, in_colour)]
    return sum(lit) >= HOLLOW_SECTORS and SECTORS - _longest_gap(lit) >= HOLLOW_SPREAD


def _longest_gap(lit: list[bool]) -> int:
    """The most sectors in a row, round the circle, that are not ``lit`` (some are)."""
    longest = run = 0
    for on in lit + lit:
        run = 0 if on else run + 1
        longest = max(longest, run)
    return min(longest, len(lit))
