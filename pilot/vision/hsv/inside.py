"""A ball is plain inside: the colour-ball detector's (detector.py) check that a large blob is not a texture.

A ball is one colour, shaded: inside its rim, brightness changes slowly (the terminator, a soft highlight). The red
heart of a dahlia, a patterned cloth's print, a bunch of red berries are blobs of the target's colour that may keep
to a circle as well as a ball does, and are brightness edges all over inside. Heavy JPEG compression merges a
dahlia's red cups into one round blob 54-60 px across: on the validation photos' dev seeds (bench/vision), it was
the detection of 3 of 1,000 empty views and the best candidate of 3 target views (their balls are missed either way).

Measured on the frame smoothed a little (``SIGMA``), so that sensor noise makes few edges: the edge share inside
0.7 radii of the balls from ``FROM`` px across found on the three dev seed sets (2,583 of them) was at most 0.07, 0.10
with Gaussian noise of 20 grey levels added (more than the simulator's dim room at full gain), and the hearts'
0.31-0.34. Balls of 30-40 px read up to 0.11 (0.14 noisy): their rim's blur and an occluder's edge fill more of it.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

CANNY = (60, 150)  # hysteresis thresholds on the grey image (the circle look's too; edges.py's, on each
# channel there)
FROM = 40.0  # px across: the hearts that fired were 54-60 px; only blobs this large pay for the check (0.02-0.1 ms)
EDGES_MAX = 0.2  # the share of the inside (to 0.7 radii) that may be a brightness edge
INSIDE = 0.7  # radii: the inside read (the rim's own edge blurs inwards)
SIGMA = 1.0  # px, the smoothing's Gaussian


def busy_inside(image: MatLike, cx: float, cy: float, size: float) -> bool:
    """Whether the blob of diameter ``size`` at (cx, cy), from ``FROM`` px across, is brightness edges inside."""
    return size >= FROM and inside_edges(image, cx, cy, size) > EDGES_MAX


def inside_edges(image: MatLike, cx: float, cy: float, size: float) -> float:
    """The share of the disc of diameter ``size`` at (cx, cy), to ``INSIDE`` radii, that is a brightness edge."""
    r = size / 2.0
    h, w = image.shape[:2]
    pad = int(INSIDE * r) + 3  # the smoothing's and Canny's reach past the read disc
    x0, y0 = max(0, int(cx) - pad), max(0, int(cy) - pad)
    x1, y1 = min(w, int(cx) + pad + 1), min(h, int(cy) + pad + 1)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return 0.0
    # a 5x5 kernel (to 2 sigma): OpenCV's own size for the sigma (7x7) costs twice as much
    grey = cv2.GaussianBlur(cv2.cvtColor(image[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY), (5, 5), SIGMA)
    disc = np.zeros((y1 - y0, x1 - x0), np.uint8)
    cv2.circle(disc, (round(cx - x0), round(cy - y0)), max(1, round(INSIDE * r)), 255, -1)
    n = cv2.countNonZero(disc)
    return cv2.countNonZero(cv2.bitwise_and(cv2.Canny(grey, *CANNY), disc)) / n if n else 0.0
