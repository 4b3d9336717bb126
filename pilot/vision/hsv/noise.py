"""Sensor noise: how much a frame carries, and the smoothing that keeps a ball's outline whole through it.

In dim light a camera raises its gain, and its sensor noise with it. A dark red ball then frays in the colour mask:
noise pushes its pixels across the hue and saturation bounds, its outline no longer keeps to its circle, and the
shape's arcs fail (a ball 4 m away in the simulator's `dim` room, at the camera's full gain: no frame of 71 scored
0.6; smoothed as here, 48). Smoothing every frame would blur small balls into their surroundings, so the detector
smooths only a frame whose noise is measured high, in its fallback looks (detector.py).

The noise is J. Immerkær's fast estimate ("Fast noise variance estimation", 1996), made robust to texture and
edges by taking the median of the mask's absolute response, not its mean.
"""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

NOISY = 4.0  # grey levels, the noise's standard deviation: photographs read 0-2.5 (90 % of bench/vision's), the bench's
# noise condition (8-12 per channel, about 0.67 of that in grey) 5-8, the simulator's dim room at full gain 13-15
SMOOTH_SIGMA = 1.5  # px, the Gaussian's: on the dim room's frames 1.0 left 27 of 71 at 0.6, 1.5 48, 2.0 43

# the difference of two Laplacians: zero on any plane, so only noise (and fine texture) responds; its coefficients'
# squares sum to 36, so the response's standard deviation is 6 times the noise's. The mask, [[1, -2, 1], [-2, 4,
# -2], [1, -2, 1]], is the outer product of [1, -2, 1] with itself: two passes of that give the same integers in a
# third of the time (0.035 against 0.09 ms at 320x240)
_PASS = np.array([1, -2, 1], np.float32)
_MAD_TO_SIGMA = 1.4826  # a Gaussian's standard deviation over its median absolute deviation


def noise_level(image: MatLike) -> float:
    """The standard deviation of the frame's sensor noise in grey levels (about 0.16 ms at 320x240)."""
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    # saturates at 255: beyond any median
    response = cv2.convertScaleAbs(cv2.sepFilter2D(grey, cv2.CV_16S, _PASS, _PASS))
    hist = cv2.calcHist([response], [0], None, [256], [0, 256]).ravel()
    median = int(np.searchsorted(np.cumsum(hist), response.size / 2.0))
    return _MAD_TO_SIGMA * median / 6.0


def noisy(image: MatLike) -> bool:
    """Whether the frame's noise is ``NOISY`` or more."""
    return noise_level(image) >= NOISY


def smoothed(image: MatLike) -> MatLike | None:
    """The frame smoothed if it is noisy, else None."""
    return cv2.GaussianBlur(image, (0, 0), SMOOTH_SIGMA) if noisy(image) else None
