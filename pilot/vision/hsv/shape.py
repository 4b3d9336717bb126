"""Shape measures for the colour-ball detector (detector.py) that do not depend on colour: sampled rings, the
real edge of a piece an opening left, and the support of a robustly fitted ellipse."""

from __future__ import annotations

import math
from typing import Any, Union

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

Points = npt.NDArray[Union[np.integer[Any], np.floating[Any]]]  # a contour's points, N x 2
Flags = npt.NDArray[np.bool_]

ELLIPSE_TOL = 0.06  # a point within this share of the mean radius (at least 1 px) lies on the fitted ellipse
ELLIPSE_ASPECT = 1.5  # a longer fit is no ball seen at an angle (the elongation ramp's zero is 2.0)


def unit_circle(n: int) -> npt.NDArray[np.float64]:
    """``n`` points evenly spaced on the unit circle, N x 2 (x, y): offsets to sample a circle in a mask with."""
    angles = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.stack([np.cos(angles), np.sin(angles)], axis=1)


def pixels_at(image: MatLike, unit: npt.NDArray[np.float64], cx: float, cy: float,
              r: float) -> npt.NDArray[Any] | None:
    """The pixels of ``image`` at the points ``unit * r`` (offsets from cx, cy), in their order; None if any falls
    outside the image."""
    h, w = image.shape[:2]
    pts = (unit * r + (cx + 0.5, cy + 0.5)).astype(np.intp)  # + 0.5: truncation rounds
    if pts.min() < 0 or pts[:, 0].max() >= w or pts[:, 1].max() >= h:
        return None
    return np.asarray(image)[pts[:, 1], pts[:, 0]]


CIRCLE_48 = unit_circle(48)
# the ring from 1.25 to 1.75 radii, in radii: three circles of 48 points (sampling it costs a third of drawing it)
RING_POINTS = np.asfortranarray(np.concatenate([k * CIRCLE_48 for k in (1.33, 1.5, 1.67)]))  # x, y = .T contiguous


def share_set(mask: MatLike, cx: float, cy: float, unit: npt.NDArray[np.float64], r: float) -> float:
    """The share of the points ``unit * r`` (offsets from cx, cy; at most 1.7 r away) inside the mask's frame that
    are set in it."""
    h, w = mask.shape[:2]
    xs, ys = unit.T
    px, py = xs * r + (cx + 0.5), ys * r + (cy + 0.5)  # + 0.5: truncation rounds
    reach = 1.7 * r + 1.0
    if not (reach <= cx < w - reach and reach <= cy < h - reach):  # all inside is the usual case; here some may not be
        keep = (px >= 0.0) & (px < w) & (py >= 0.0) & (py < h)
        if not keep.any():
            return 1.0
        px, py = px[keep], py[keep]
    flat = py.astype(np.intp) * w + px.astype(np.intp)  # read by flat index: fewer numpy calls than by row and column
    return float(np.count_nonzero(np.asarray(mask).ravel().take(flat))) / len(flat)


def outer_rim(mask: MatLike, pts: Points, cx: float, cy: float, step: float) -> Flags:
    """For each contour point: is the mask unset ``step`` pixels further out from (cx, cy)? True where the point
    lies on the blob's real edge, False where a cut (an opening) made it."""
    h, w = mask.shape[:2]
    d = pts - (cx, cy)
    norm = np.sqrt(np.maximum(np.square(d).sum(axis=1), 1.0))
    out = pts + d * (step / norm)[:, None] + 0.5
    ox = np.clip(out[:, 0].astype(np.intp), 0, w - 1)
    oy = np.clip(out[:, 1].astype(np.intp), 0, h - 1)
    return np.asarray(np.asarray(mask)[oy, ox] == 0, np.bool_)


def ellipse_support(pts: Points, real: Flags | None) -> float:
    """The share of the contour lying on an ellipse fitted to it twice, the second time to the first fit's inliers
    only (a stub, a neck or a covered part does not pull it); with ``real``, only points on the blob's real edge
    count. A ball seen at an angle or through a perspective warp is an ellipse, which its enclosing circle misses."""
    fp = pts.astype(np.float32)
    keep, inliers = fp, np.zeros(len(fp), np.bool_)
    for _ in range(2):
        if len(keep) < 6:
            return 0.0
        (ex, ey), (d1, d2), angle = cv2.fitEllipse(keep)
        a, b = d1 / 2.0, d2 / 2.0
        if not (math.isfinite(a) and math.isfinite(b)) or min(a, b) <= 1.0 or max(a, b) > ELLIPSE_ASPECT * min(a, b):
            return 0.0
        t = math.radians(angle)
        dx, dy = fp[:, 0] - ex, fp[:, 1] - ey
        u = (dx * math.cos(t) + dy * math.sin(t)) / a
        v = (dy * math.cos(t) - dx * math.sin(t)) / b
        mean_r = (a + b) / 2.0
        inliers = np.abs(np.sqrt(u * u + v * v) - 1.0) <= max(1.0, ELLIPSE_TOL * mean_r) / mean_r
        keep = fp[inliers]
    if real is not None:
        inliers &= real
    return float(np.count_nonzero(inliers)) / len(fp)
