"""Balls joined in the mask to something of their colour (detector.py, step 3): the array work of splitting
them off, by shape (a disc bulging out of a blob, cut free by an opening), by hue (a ball a few hue units off the
red-brown surface it lies on) and, where the hue is one, by saturation (a crimson ball on a glossy orange-red
saucer of the same hue: the saucer's colour is purer)."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from typing import NamedTuple

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .colour import Bounds
from .shape import unit_circle
from .texture import SIZE_RATIO

PEAK_MIN = 3.0  # pixels: a disc centre nearer than this to the blob's edge is too small to be a ball
PEAKS_PER_BLOB = 6  # disc centres looked at per blob, widest first
RIM_MIN = 0.35  # of a circle just outside a disc that leaves the blob: less is no bulge (a disc that merely
# fits inside a wide region has its nearest edge on one side); it halves the discs refined, not the recall
SPLIT_OPEN = 0.5  # the opening's disc, in radii of the disc found (0.6 let opened squares through: red_shape)
SPLIT_CUT = 0.1  # the opening must cut off this much (of the piece's area): else the blob was joined to nothing
CLASS_PIECES = 2  # the largest round pieces of each colour class (of hue or saturation) refined
HUE_GAP = 4.0  # hue units between the means of a blob's two hue classes (Otsu) for a split by hue (3: more
# false detections on the tuning photos' empty views, 2: more still)
SAT_GAP = 16.0  # saturation units between the means of a blob's two saturation classes for a split by saturation
# (24 found nearly the same: a ball and the surface it is joined to differ by 20-50)
HUE, SATURATION = 0, 1  # the HSV channels a joined blob is split by

_CIRCLE = unit_circle(24)
_PEAK_KERNEL = np.ones((3, 3), np.uint8)
Box = tuple[int, int, int, int]  # x, y, width, height


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


class Piece(NamedTuple):
    """A ball split off by an opening, in its window: the piece's contour and area, the mask's holes filled
    (``solid``), and the widest disc near where it was looked for."""

    contour: MatLike
    area: float
    solid: MatLike
    cx: float
    cy: float
    radius: float


def split_off(mask: MatLike, cx: int, cy: int, r: float, min_area: float) -> Piece | None:
    """The piece of ``mask`` around (cx, cy) that an opening by a disc SPLIT_OPEN times ``r`` leaves, or None
    when too small or when the opening cut off next to nothing (the blob was joined to nothing)."""
    # holes filled: a ball's highlight would pull the widest disc off its centre
    solid = np.zeros_like(np.asarray(mask))
    cv2.drawContours(solid, cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)[0], -1, 255, -1)
    dist = cv2.distanceTransform(solid, cv2.DIST_L2, 5)  # within 2 % of the precise one, at a third of its cost
    opened = open_by_disc(solid, SPLIT_OPEN * (r + 1.0), dist)
    # the widest disc near (cx, cy): the ball, where the opening may leave shoulders of what it is joined to
    # (a neck wider than the opening's disc), which would pull an enclosing circle
    k = max(2, int(r / 3.0))
    kx, ky = max(0, cx - k), max(0, cy - k)
    _, r_in, _, (mx, my) = cv2.minMaxLoc(dist[ky : cy + k + 1, kx : cx + k + 1])
    centre = (float(mx + kx), float(my + ky))
    for c in cv2.findContours(opened, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0]:
        if cv2.pointPolygonTest(c, centre, False) >= 0:
            area = float(cv2.contourArea(c))
            cut_off = cv2.countNonZero(solid) - cv2.countNonZero(opened)
            if len(c) < 8 or area < min_area or cut_off < SPLIT_CUT * area:
                return None
            return Piece(c, area, solid, centre[0], centre[1], float(r_in))
    return None


def two_classes(values: npt.NDArray[np.uint8], blob: npt.NDArray[np.uint8], min_count: float, gap: float) -> int | None:
    """The value (inclusive upper bound of the lower class) that splits a blob's pixels of one channel into two
    classes (Otsu) whose means lie at least ``gap`` apart, or None (one class, or too few pixels)."""
    inside = values[blob > 0]
    if len(inside) < min_count:
        return None
    t, _ = cv2.threshold(inside.reshape(-1, 1), 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    low, high = inside[inside <= t], inside[inside > t]
    if not len(low) or not len(high) or float(high.mean()) - float(low.mean()) < gap:
        return None
    return int(t)


def colour_pieces(hsv: MatLike, mask: MatLike, joined: Sequence[tuple[float, MatLike, Box]], bounds: Bounds,
                  min_area: float, min_fill: float,
                  clean: Callable[[MatLike], MatLike]) -> Iterator[tuple[Bounds, Box, int]]:
    """For each joined blob (area, contour, box in the search ``hsv`` and its ``mask``) whose pixels fall in two hue
    classes, or else in two saturation classes: each class's range (``bounds``, one range, narrowed in that
    channel), the ``CLASS_PIECES`` largest round pieces of the blob in it (their boxes in the search; ``clean``: the
    detector's mask cleaning) and the channel split. A saturation class holding round pieces of a size is a texture
    of round things (a dahlia's cups), not a ball on a surface: none of its pieces."""
    ((lo, hi),) = bounds
    for _, c, (x, y, bw, bh) in joined:
        blob = np.zeros((bh, bw), np.uint8)
        cv2.drawContours(blob, [c], -1, 255, -1, offset=(-x, -y))
        window = np.asarray(hsv, np.uint8)[y : y + bh, x : x + bw]
        blob &= np.asarray(mask, np.uint8)[y : y + bh, x : x + bw]
        channel, t = HUE, two_classes(np.ascontiguousarray(window[..., HUE]), blob, 4 * min_area, HUE_GAP)
        if t is None:
            channel, t = SATURATION, two_classes(np.ascontiguousarray(window[..., SATURATION]), blob,
                                                 4 * min_area, SAT_GAP)
        if t is None:
            continue
        for v0, v1 in ((int(lo[channel]), t), (t + 1, int(hi[channel]))):
            sub_lo, sub_hi = lo.copy(), hi.copy()
            sub_lo[channel], sub_hi[channel] = v0, v1
            sub = clean(cv2.bitwise_and(cv2.inRange(window, sub_lo, sub_hi), blob))
            pieces = round_pieces(sub, min_area, min_fill)
            if channel == SATURATION and _patterned(pieces):
                continue
            for _, (px, py, pw, ph) in pieces[:CLASS_PIECES]:
                yield [(sub_lo, sub_hi)], (px + x, py + y, pw, ph), channel


def _patterned(pieces: list[tuple[float, Box]]) -> bool:
    """Whether the largest of ``pieces`` (largest first) has another of a similar size: within the texture check's
    ``SIZE_RATIO`` (texture.py)."""
    if len(pieces) < 2:
        return False
    sizes = [max(bw, bh) for _, (_, _, bw, bh) in pieces]
    return any(sizes[0] / SIZE_RATIO <= s <= sizes[0] * SIZE_RATIO for s in sizes[1:])


def round_pieces(mask: MatLike, min_area: float, min_fill: float) -> list[tuple[float, Box]]:
    """The external blobs of ``mask`` filling at least ``min_fill`` of their box's disc, as (area, box), largest
    first."""
    out = []
    for c in cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)[0]:
        if len(c) < 3 or (area := float(cv2.contourArea(c))) < min_area:
            continue
        x, y, bw, bh = cv2.boundingRect(c)
        if area >= min_fill * math.pi * (max(bw, bh) / 2.0) ** 2:
            out.append((area, (x, y, bw, bh)))
    return sorted(out, key=lambda p: p[0], reverse=True)
