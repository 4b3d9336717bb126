"""Whether a circle of the target's colour is lit as a ball is: brighter in its middle than near its limb.

A matte ball's brightness is a plane (the light's side) plus a term that follows the surface's slope towards the
camera: a ring round the centre averages the plane out, so the middle stands above a ring at 0.8 radii by about 0.4
of that term, whichever side the light comes from, as long as some of it comes from the camera's side. A flat red
thing (a poster, a box's face, the saucer a ball lies on) reads level; a cup reads lower in its middle. A rounded red
knob (the end of a cup's handle, on bench/vision's fresh dev seeds) is domed as a ball is, and passes.

The circle look (circles.py) takes a circle with a rim short of ``hsv_rim.WHOLE`` when it is domed: JPEG's
blocks and a dark ground behind a ball's shaded side leave part of a ball's rim with no edge. A ball lit from behind
is not domed and stays unfound (the safe failure); this only admits circles, it never drops one.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

from .shape import pixels_at, unit_circle

RISE = 0.1  # the middle over the ring, as a share of their mean brightness
_MIDDLE = np.concatenate([0.2 * unit_circle(8), np.zeros((1, 2))])  # the middle, to 0.2 radii: 9 points
_LIMB = 0.8 * unit_circle(24)  # the ring at 0.8 radii (the rim's own edge blurs inwards beyond it)
_POINTS = np.concatenate([_MIDDLE, _LIMB])


def domed(bgr: MatLike, cx: float, cy: float, r: float) -> bool:
    """Whether the circle (cx, cy, r) of ``bgr`` is brighter in its middle than at 0.8 radii by ``RISE`` of their
    mean grey level; False when the ring leaves the image. Only the 33 points read are made grey (as
    hollow.py reads its sectors)."""
    pixels = pixels_at(bgr, _POINTS, cx, cy, r)
    if pixels is None:
        return False
    grey = cv2.cvtColor(pixels.reshape(1, -1, 3), cv2.COLOR_BGR2GRAY).ravel().astype(np.float64)
    middle, limb = float(grey[: len(_MIDDLE)].mean()), float(grey[len(_MIDDLE):].mean())
    return middle - limb >= RISE * max(1.0, (middle + limb) / 2.0)
