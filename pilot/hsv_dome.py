"""Whether a circle of the target's colour is lit as a ball is: brighter in its middle than near its limb.

A matte ball's brightness is a plane (the light's side) plus a term that follows the surface's slope towards the
camera: a ring round the centre averages the plane out, so the middle stands above a ring at 0.8 radii by about 0.4
of that term, whichever side the light comes from, as long as some of it comes from the camera's side. A flat red
thing (a poster, a box's face, the saucer a ball lies on) reads level; a cup reads lower in its middle. A rounded red
knob (the end of a cup's handle, on bench/vision's fresh dev seeds) is domed as a ball is, and passes.

The circle look (pilot/hsv_circles.py) takes a circle with a rim short of ``hsv_rim.WHOLE`` when it is domed: JPEG's
blocks and a dark ground behind a ball's shaded side leave part of a ball's rim with no edge. A ball lit from behind
is not domed and stays unfound (the safe failure); this only admits circles, it never drops one.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

from .hsv_shape import unit_circle

RISE = 0.1  # the middle over the ring, as a share of their mean brightness
_MIDDLE = np.concatenate([0.2 * unit_circle(8), np.zeros((1, 2))])  # the middle, to 0.2 radii: 9 points
_LIMB = 0.8 * unit_circle(24)  # the ring at 0.8 radii (the rim's own edge blurs inwards beyond it)


def domed(bgr: MatLike, cx: float, cy: float, r: float) -> bool:
    """Whether the circle (cx, cy, r) of ``bgr`` is brighter in its middle than at 0.8 radii by ``RISE`` of their
    mean grey level; False when the ring leaves the image."""
    h, w = bgr.shape[:2]
    reach = int(r) + 2
    x0, y0 = max(0, int(cx) - reach), max(0, int(cy) - reach)
    x1, y1 = min(w, int(cx) + reach + 1), min(h, int(cy) + reach + 1)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return False
    grey = cv2.cvtColor(bgr[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY)  # a view: OpenCV reads its rows in place
    levels = []
    for unit in (_MIDDLE, _LIMB):
        pts = (unit * r + (cx - x0 + 0.5, cy - y0 + 0.5)).astype(np.intp)
        if pts.min() < 0 or pts[:, 0].max() >= x1 - x0 or pts[:, 1].max() >= y1 - y0:
            return False
        levels.append(float(grey[pts[:, 1], pts[:, 0]].mean()))
    middle, limb = levels
    return middle - limb >= RISE * max(1.0, (middle + limb) / 2.0)
