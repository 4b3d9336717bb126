"""A ball is plain inside: the colour-ball detector's (pilot/hsv.py) check that a large blob is not a texture.

A ball is one colour, shaded: inside its rim, brightness changes slowly (the terminator, a soft highlight). The red
heart of a dahlia, a patterned cloth's print, a bunch of red berries are blobs of the target's colour that may keep
to a circle as well as a ball does, and are brightness edges all over inside. Heavy JPEG compression merges a
dahlia's red cups into one round blob 55-60 px across: on the validation photos' dev seeds (bench/vision), 3 of
1,000 empty views with a detection, and 3 target views where it outranked the ball.

Measured on the frame smoothed a little (``SIGMA``), so that sensor noise makes no edges: the edge share inside
0.7 radii of balls from ``FROM`` px across was at most 0.11 on the three dev seed sets (0.12 with Gaussian noise of
20 grey levels added, more than the simulator's dim room at full gain), the dahlia's hearts 0.31-0.34.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

FROM = 30.0  # px across: a smaller ball's rim and an occluder's edge fill too much of its inside to tell
EDGES_MAX = 0.2  # the share of the inside (to 0.7 radii) that may be a brightness edge
INSIDE = 0.7  # radii: the inside read (the rim's own edge blurs inwards)
SIGMA = 1.0  # px, the smoothing's Gaussian
CANNY = (60, 150)  # hysteresis thresholds on the grey image (pilot/hsv_circles.py's)


def busy_inside(image: MatLike, cx: float, cy: float, size: float) -> bool:
    """Whether the blob of diameter ``size`` at (cx, cy) is brightness edges inside (about 0.05 ms at 60 px)."""
    if size < FROM:
        return False
    r = size / 2.0
    h, w = image.shape[:2]
    pad = int(INSIDE * r) + 3  # the smoothing's and Canny's reach past the read disc
    x0, y0 = max(0, int(cx) - pad), max(0, int(cy) - pad)
    x1, y1 = min(w, int(cx) + pad + 1), min(h, int(cy) + pad + 1)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return False
    grey = cv2.GaussianBlur(cv2.cvtColor(image[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY), (0, 0), SIGMA)
    edges = np.asarray(cv2.Canny(grey, *CANNY))
    yy, xx = np.ogrid[y0:y1, x0:x1]
    disc = (xx - cx) ** 2 + (yy - cy) ** 2 < (INSIDE * r) ** 2
    n = int(np.count_nonzero(disc))
    return n > 0 and int(np.count_nonzero(edges[disc])) > EDGES_MAX * n
