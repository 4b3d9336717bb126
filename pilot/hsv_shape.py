"""Shape measures for the colour-ball detector (pilot/hsv.py) that do not depend on colour: sampled rings, the
support of a robustly fitted ellipse, disc centres in a blob, and an opening by a disc of any size."""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

Points = npt.NDArray[np.integer[Any] | np.floating[Any]]  # a contour's points, N x 2
Flags = npt.NDArray[np.bool_]

ELLIPSE_TOL = 0.06  # a point within this share of the mean radius (at least 1 px) lies on the fitted ellipse
ELLIPSE_ASPECT = 1.5  # a longer fit is no ball seen at an angle (the elongation ramp's zero is 2.0)
PEAK_MIN = 3.0  # pixels: a disc centre nearer than this to the blob's edge is too small to be a ball
PEAKS_PER_BLOB = 6  # disc centres looked at per blob, widest first
RIM_MIN = 0.35  # of a circle just outside a disc that leaves the blob: less is no bulge (a disc that merely
# fits inside a wide region has its nearest edge on one side); it halves the discs refined, not the recall

# the ring from 1.25 to 1.75 radii, in radii: three circles of 48 points (sampling it costs a third of drawing it)
_ANGLES = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
RING_POINTS = np.concatenate([k * np.stack([np.cos(_ANGLES), np.sin(_ANGLES)], axis=1) for k in (1.33, 1.5, 1.67)])
_PEAK_KERNEL = np.ones((3, 3), np.uint8)
_CIRCLE = np.stack([np.cos(_ANGLES[::2]), np.sin(_ANGLES[::2])], axis=1)  # 24 points


def share_set(mask: MatLike, cx: float, cy: float, unit: npt.NDArray[np.float64], r: float) -> float:
    """The share of the points ``unit * r`` (offsets from cx, cy; at most 1.7 r away) inside the mask's frame that
    are set in it."""
    h, w = mask.shape[:2]
    pos = unit * r + (cx + 0.5, cy + 0.5)  # + 0.5: truncation rounds
    reach = 1.7 * r + 1.0
    if reach <= cx < w - reach and reach <= cy < h - reach:  # all inside: the usual case
        idx = pos.astype(np.intp)
    else:
        idx = pos[(pos[:, 0] >= 0.0) & (pos[:, 0] < w) & (pos[:, 1] >= 0.0) & (pos[:, 1] < h)].astype(np.intp)
        if not len(idx):
            return 1.0
    return float(np.count_nonzero(np.asarray(mask)[idx[:, 1], idx[:, 0]])) / len(idx)


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


def disc_centres(contour: MatLike, box: tuple[int, int, int, int]) -> list[tuple[float, float, float]]:
    """The centres of the widest discs inside one blob (maxima of its distance transform, each at least its
    radius from a wider one) that bulge out of it (``RIM_MIN``), as (radius, x, y), widest first: where a ball
    joined to something else sits."""
    x, y, bw, bh = box
    # filled: a ball's highlight is a hole in the mask, which would pull the disc off the ball's centre
    blob = np.zeros((bh + 2, bw + 2), np.uint8)  # a 1 px border: the distance reaches zero at the box's edge
    cv2.drawContours(blob, [contour], -1, 255, -1, offset=(1 - x, 1 - y))
    dist = cv2.distanceTransform(blob, cv2.DIST_L2, 3)
    ys, xs = np.nonzero((dist >= cv2.dilate(dist, _PEAK_KERNEL)) & (dist >= PEAK_MIN))
    values = dist[ys, xs]
    out: list[tuple[float, float, float]] = []
    for k in np.argsort(-values):
        r, px, py = float(values[k]), float(xs[k]), float(ys[k])
        if all((px - qx) ** 2 + (py - qy) ** 2 > max(r, qr) ** 2 for qr, qx, qy in out):
            out.append((r, px, py))
            if len(out) >= PEAKS_PER_BLOB:
                break
    vetted = []
    for r, px, py in out:
        pos = (_CIRCLE * (r + 1.5) + (px + 0.5, py + 0.5)).astype(np.intp)  # + 0.5: truncation rounds
        pos = pos[(pos[:, 0] >= 0) & (pos[:, 0] < bw + 2) & (pos[:, 1] >= 0) & (pos[:, 1] < bh + 2)]
        rim = 1.0 - float(np.count_nonzero(blob[pos[:, 1], pos[:, 0]])) / len(_CIRCLE)  # beyond the box: outside
        if rim >= RIM_MIN:
            vetted.append((r, px + x - 1, py + y - 1))
    return vetted


def open_by_disc(mask: MatLike, radius: float, dist: MatLike) -> MatLike:
    """The mask opened by a disc of ``radius``, given the mask's distance transform: necks and strips narrower
    than the disc go, any wider disc stays whole. Two distance transforms, whatever the radius (a structuring
    element that size would cost far more)."""
    _, core = cv2.threshold(np.asarray(dist, np.float32), radius, 255, cv2.THRESH_BINARY_INV)
    _, opened = cv2.threshold(cv2.distanceTransform(core.astype(np.uint8), cv2.DIST_L2, 3), radius, 255,
                              cv2.THRESH_BINARY_INV)
    return opened.astype(np.uint8)
