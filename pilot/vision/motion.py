"""The whole scene's apparent motion between two frames: how far the camera seems to have turned and how much nearer
it seems to have come.

The pilot sees the airframe's drift through the target only while the target is in view and the heading held; a
far, flickering ball in a turning search shows neither. The scene shows it in every frame: a drone sliding right
makes the room slide left across the image (like a turn to the right), one moving forward makes it grow. A few
corners on a half-size grey image are followed with pyramidal Lucas-Kanade and a similarity (shift, scale,
rotation) is fitted to them with RANSAC (the target and anything moving are outliers); the control layer takes
away the turn it commanded and reads the rest as drift. About a millisecond a frame at 320x240
(bench/flight/HISTORY.md).
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .detection import SceneShift, colour_image, focal_px

SHRINK = 2  # corners are found and followed on an image this many times smaller
MAX_CORNERS = 40
QUALITY = 0.01
MIN_DISTANCE_PX = 6  # at the shrunk size
MIN_POINTS = 12  # fewer inliers than this: no estimate (a blank wall, a blurred turn)
RANSAC_PX = 1.0  # an inlier's reprojection error, at the shrunk size
WINDOW = (15, 15)
LEVELS = 2


class SceneMotion:
    """``update(image)``: the scene's shift from the previous frame given (None: no previous frame, too little
    texture, or a fit that failed)."""

    def __init__(self, fov_deg: float) -> None:
        self.fov_deg = fov_deg
        self._last: MatLike | None = None

    def reset(self) -> None:
        self._last = None

    def update(self, image: MatLike) -> SceneShift | None:
        if not colour_image(image):
            self._last = None
            return None
        h, w = image.shape[:2]
        grey = cv2.cvtColor(cv2.resize(image, (w // SHRINK, h // SHRINK), interpolation=cv2.INTER_AREA),
                            cv2.COLOR_BGR2GRAY)
        last, self._last = self._last, grey
        if last is None or last.shape != grey.shape:
            return None
        corners = cv2.goodFeaturesToTrack(last, MAX_CORNERS, QUALITY, MIN_DISTANCE_PX)
        if corners is None or len(corners) < MIN_POINTS:
            return None
        none = np.empty(0, np.float32)  # no initial guess (the stubs refuse None)
        moved, status, _ = cv2.calcOpticalFlowPyrLK(last, grey, corners, none, winSize=WINDOW, maxLevel=LEVELS)
        ok = status.reshape(-1) == 1
        if int(ok.sum()) < MIN_POINTS:
            return None
        f = focal_px(w, self.fov_deg) / SHRINK
        centre = (grey.shape[1] / 2.0, grey.shape[0] / 2.0)
        src, dst = _angles(corners.reshape(-1, 2)[ok], centre, f), _angles(moved.reshape(-1, 2)[ok], centre, f)
        fit, inliers = cv2.estimateAffinePartial2D(src, dst, method=cv2.RANSAC, ransacReprojThreshold=RANSAC_PX)
        if fit is None or inliers is None or int(inliers.sum()) < MIN_POINTS:
            return None
        scale = math.hypot(float(fit[0, 0]), float(fit[1, 0]))
        # the scene sliding right by this angle: the camera turned left
        return SceneShift(turn_deg=-math.degrees(float(fit[0, 2]) / f), scale=scale, points=int(inliers.sum()))


def _angles(points: npt.NDArray[np.float32], centre: tuple[float, float], f: float) -> npt.NDArray[np.float32]:
    """Image points as angles from the centre (azimuth, elevation; radians times ``f``): a turn about the vertical
    axis then shifts every point by the same amount, where in pixels the frame's edges move further than its centre
    (a 2.4° turn read as a 1-2 % growth at 60°)."""
    u = points[:, 0] - centre[0]
    v = points[:, 1] - centre[1]
    out = np.empty_like(points)
    out[:, 0] = f * np.arctan2(u, f)
    out[:, 1] = f * np.arctan2(v, np.hypot(u, f))
    return out
