"""Rim support for the colour-ball detector (detector.py): how much of a circle near a blob's is an edge in the
image's brightness (or, short of that, in a colour channel), facing the circle's centre.

A ball's outline is an edge all the way round whatever its colour mask shows (JPEG blocks the colour, not the
brightness); a red shape's outline is not on a circle, and a texture is an edge here and there. The circle is looked
for near the one given, scaled and shifted a little. Figures: bench/vision/HISTORY.md."""

from __future__ import annotations

from typing import NamedTuple

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .inside import EDGES_MAX, inside_edges
from .shape import unit_circle

EDGE = 40.0  # Sobel (3x3) response across the rim, about a 10-level step in brightness: sensor noise is below it
RADIAL = 0.8  # the share of the gradient's square across the rim: within 27 degrees of the radius (0.5, 45
# degrees, let a polygon's sides through wherever a circle runs along them: 3 red shapes of 300 on the tuning
# photos, 1 at 0.8, 0 at 0.9 for 1-3 points of JPEG recall; dev seeds, not bench/vision's)
SCALES = (0.85, 0.92, 1.0, 1.08, 1.16)  # circles tried: radii, in radii of the blob's enclosing circle...
SHIFTS = (-0.15, 0.0, 0.15)  # ...and centres moved by this much in x and y (radii)
HALF_FROM = 16.0  # px (radius): a circle this wide is measured at half resolution. JPEG's blocks and blur make a
# wide ball's rim a ramp several pixels wide, too gentle for a 3x3 Sobel at full resolution; halved, it is a step
# again. Tuning photos' dev seeds: JPEG 84.8 -> 85.8 %, noise 91.4 -> 92.0 %, none lower, the same false detections
# in 4,800 empty and distractor views and in 2,400 of the validation photos' (from a radius of 12: JPEG 86.1 %, 2
# validation empty views more; from 20: 85.1 %)

WHOLE = 0.8  # a brightness rim this whole is a ball's (the circle look's bar; the score's RIM ramp reaches 1 above)
COLOUR_MIN = 0.88  # of the points (43 of 48), in one colour channel: more are edges there than in brightness
# (texture, print). Counted in any channel at each point, 0.8 and 0.84 gave 9 and 3 more detections in 4,500 empty
# and distractor views on the three dev seed sets, 0.88 none, nor 0.9 (with 7 balls fewer)
COLOUR_FROM = 18.0  # px across: a smaller circle is measured in brightness only. A red lamp 15-17 px across on the
# tuning photos' motorbike, a red ring round a yellow glow, has a colour rim all round

_U = unit_circle(48)
_FACTORS = np.array([k for k in SCALES for _ in SHIFTS for _ in SHIFTS])[:, None, None]
_OFFSETS = np.array([(dx, dy) for _ in SCALES for dx in SHIFTS for dy in SHIFTS])[:, None, :]
_UNIT = _FACTORS * _U[None, :, :] + _OFFSETS  # circles x points x (x, y), in radii from the blob's centre
_REACH = max(SCALES) + max(SHIFTS) * 1.5  # the farthest a point lies from the centre, in radii (with margin)


def rim_support(bgr: MatLike, cx: float, cy: float, r: float, colour: bool = False) -> float:
    """The best share, over the circles tried near (cx, cy, r) in ``bgr``'s pixels, of a circle's 48 points
    where the brightness's gradient is at least ``EDGE`` and points along the radius (either way: a ball's lit
    side may be brighter than what lies behind it, its shaded side darker); ``colour``: see ``best_rim``."""
    if colour:  # the colour rim's inside check needs the best circle itself
        return best_rim(bgr, cx, cy, r, True)[0]
    window = _window(bgr, cx, cy, r)
    return 0.0 if window is None else float(_counts(window, cx, cy, r, False).max()) / len(_U)


def best_rim(bgr: MatLike, cx: float, cy: float, r: float,
             colour: bool = False) -> tuple[float, float, float, float]:
    """``rim_support`` and the circle that has it (centre, radius). ``colour``: a rim short of ``WHOLE`` in
    brightness, from ``COLOUR_FROM`` px across, is measured in each colour channel too; that one counts if it
    reaches ``COLOUR_MIN`` and the circle is plain inside."""
    window = _window(bgr, cx, cy, r)
    if window is None:
        return 0.0, cx, cy, r
    rim = _best(window, cx, cy, r, False)
    if colour and rim[0] < WHOLE and 2.0 * r >= COLOUR_FROM:
        in_colour = _best(window, cx, cy, r, True)
        _, bx, by, br = in_colour
        if in_colour[0] >= COLOUR_MIN and inside_edges(bgr, bx, by, 2.0 * br) <= EDGES_MAX:
            return in_colour
    return rim


def _best(window: Window, cx: float, cy: float, r: float, colour: bool) -> tuple[float, float, float, float]:
    counts = _counts(window, cx, cy, r, colour)
    top = counts == counts.max()
    # of the circles tied best, the widest (a ball's shading is an edge inside its rim, never outside it), their
    # centres averaged (a clean rim ties several around the true one)
    widest = float(_FACTORS[top, 0, 0].max())
    top &= _FACTORS[:, 0, 0] == widest
    dx, dy = _OFFSETS[top, 0].mean(axis=0)
    return float(counts.max()) / len(_U), float(cx + dx * r), float(cy + dy * r), widest * r


class Window(NamedTuple):
    """The pixels every circle tried near one reaches (a view of the image), where they start, and how much the
    rim is read smaller (2 from ``HALF_FROM``)."""

    roi: MatLike
    x0: int
    y0: int
    k: int


def _window(bgr: MatLike, cx: float, cy: float, r: float) -> Window | None:
    """The window of the circles tried near (cx, cy, r), cut once for the rim in brightness and in colour; None where
    it is too small."""
    h, w = bgr.shape[:2]
    k = 2 if r >= HALF_FROM else 1
    reach = _REACH * r + 2.0 * k
    x0, y0 = max(0, int(cx - reach)), max(0, int(cy - reach))
    x1, y1 = min(w, int(cx + reach) + 2), min(h, int(cy + reach) + 2)
    x1, y1 = x0 + (x1 - x0) // k * k, y0 + (y1 - y0) // k * k
    if x1 - x0 < 3 * k or y1 - y0 < 3 * k:
        return None
    return Window(bgr[y0:y1, x0:x1], x0, y0, k)  # a view: OpenCV reads its rows in place


def _counts(window: Window, cx: float, cy: float, r: float, colour: bool) -> npt.NDArray[np.intp]:
    """For each circle tried, how many of its points are on the rim (``colour``: in the channel where most
    are)."""
    roi, x0, y0, k = window
    img = roi if colour else cv2.cvtColor(roi, cv2.COLOR_BGR2GRAY)
    if k > 1:
        img = cv2.resize(img, (roi.shape[1] // k, roi.shape[0] // k), interpolation=cv2.INTER_AREA)
    gh, gw = img.shape[:2]
    gx = cv2.Sobel(img, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(img, cv2.CV_32F, 0, 1, ksize=3)
    if not colour:  # one channel: the same arithmetic as three (a trailing axis of one)
        gx, gy = gx[..., None], gy[..., None]
    # a pixel's centre at i lies at (i + 0.5) / k - 0.5 in the window; + 0.5 again: truncation rounds
    pos = _UNIT * (r / k) + ((cx - x0 + 0.5) / k, (cy - y0 + 0.5) / k)
    ix, iy = pos[..., 0].astype(np.intp), pos[..., 1].astype(np.intp)
    # the Sobel's outer row and column see the border, not the image: points there count as no edge
    inside = (ix >= 1) & (ix < gw - 1) & (iy >= 1) & (iy < gh - 1)
    ix, iy = np.where(inside, ix, 1), np.where(inside, iy, 1)
    vx, vy = gx[iy, ix], gy[iy, ix]  # circles x points x channels
    across: npt.NDArray[np.float64] = vx * _U[:, :1] + vy * _U[:, 1:]  # the circle's normal is its unit point
    sq = across * across
    edge = (sq >= EDGE * EDGE) & (sq >= RADIAL * (vx * vx + vy * vy)) & inside[..., None]
    return np.asarray(np.count_nonzero(edge, axis=1).max(axis=1), np.intp)  # the best channel's
