"""How the colour-ball detector (detector.py) measures one blob and scores it: the features of ``Features``,
measured in the order that rejects soonest for least, and the score, a product of ramps (score.py).

A blob whose arcs or ring hold its score down, measured with the window's pixels at hand, is remembered for the
frame (``deferred``): if the frame's looks find nothing the pilot would act on, the detector measures those again
with their rim support (rim.py), which stands in for the arcs and for isolation. The rim costs more
than everything else measured (about 60 µs), and a frame with a plain ball never needs it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import cv2
import numpy as np
from cv2.typing import MatLike

from ...common.config import HsvConfig, VisionConfig
from ..budget import FrameBudget
from ..detection import range_of
from .colour import ColourMask
from .rim import rim_support
from .score import (
    ARC,
    ARC_TOL,
    ELONGATION_ROUND,
    FILL,
    HUE_OFF,
    RIM,
    RING,
    SATURATION,
    SIZE,
    SOLIDITY,
    Features,
    arc_score,
    box_score,
    ramp,
    stretch_score,
)
from .shape import ELLIPSE_ASPECT, RING_POINTS, ellipse_support, outer_rim, share_set
from .texture import SearchBlob, textured

HALF_DECIDES = 0.9  # the half-resolution score that keeps a blob from the refinement...
HALF_FILL = 0.8  # ...for a plain disc only: this fill of its circle (a square's is 0.64)...
HALF_ARC = 0.8  # ...and this share of its outline on it
RIM_STEP = 2.0  # px outwards from a contour point where the unopened mask must be unset for a real edge
RIM_MIN_R = 7.0  # px (radius, in the measured image): a smaller circle has too few distinct rim pixels
CORE_BELOW = 32.0  # px across: a smaller blob...
CORE_ROUND = 0.8  # ...this round (arc or rim support) has its saturation read on its core (core_saturation)...
CORE_MIN = 0.3  # ...when the core keeps this share of its area (a thin blob's may vanish)
CLIPPED = 250  # V from which a pixel's hue is not read where the hue holds a blob's score down (unclipped_hue)...
CLIP_MIN = 0.3  # ...when the rest keeps this share of its area
SCORES_KEPT = 64  # blob scores remembered at most (a frame scores a handful)


class Deferred(NamedTuple):
    """A blob to measure again with its rim: what ``measure`` was given, and the score it must reach then (the
    look's: a fallback look asks for more)."""

    hsv: MatLike
    mask: MatLike
    contour: MatLike
    area: float
    x0: int
    y0: int
    scale: int
    bgr: MatLike
    keep_from: float


class BlobMeasure:
    def __init__(self, cfg: HsvConfig, vision: VisionConfig, fov_deg: float) -> None:
        self.colour = ColourMask(cfg)  # raises ConfigError without a range
        self.cfg = cfg
        self.vision = vision
        self.fov_deg = fov_deg
        self.budget = FrameBudget(vision.budget_ms)  # refinement stops when the frame's time is spent
        self._width = 320  # of the frame being looked at (range estimates)
        self._scores: dict[int, tuple[Features, int, float]] = {}  # id -> the blob (kept alive), width, score
        self.deferred: list[Deferred] = []  # this frame's blobs held down by their arcs or ring
        self.keep_from = 0.0  # the score a deferred blob must reach (a fallback look asks for more)
        self.round_search: list[SearchBlob] = []  # the frame's round search blobs (the first look's, those filling
        # SEARCH_FILL of their box's disc, as a ball does), for the texture check...
        self.search_scale = 1  # ...and how much smaller than the frame the search is

    def new_frame(self, width: int) -> None:
        self._width = width
        self._scores.clear()
        self.deferred.clear()
        self.keep_from = 0.0

    def measure(self, hsv: MatLike, mask: MatLike, c: MatLike, area: float, x0: int, y0: int, scale: int = 1,
                cut: bool = False, decide: bool = False, bgr: MatLike | None = None,
                rim: bool = False) -> Features | None:
        """The blob's features; None as soon as the product of its factors so far is below ``min_score``.
        ``scale``: the mask is the search's, that many times smaller than the frame; ``cut``: the blob is a piece
        an opening left, and only its outline on the mask's real edge counts for its arcs; ``decide``: None too as
        soon as it cannot be a plain disc scoring ``HALF_DECIDES`` (``HALF_FILL``, ``HALF_ARC``); ``bgr``: the
        pixels of ``hsv``, to defer a blob held down by its arcs or ring; ``rim``: measure its rim now."""
        least = max(self.cfg.min_score, HALF_DECIDES) if decide else self.cfg.min_score
        (cx, cy), r = cv2.minEnclosingCircle(c)
        # the circle passes through pixel centres; the ball covers the pixels. At half resolution: 4 r, between a
        # flat disc's 4 r - 1.7 and a shaded ball's 4 r + 1 (tuning photos; the flights' approach rests on it)
        size = 2.0 * r * scale + 1.0 - (scale - 1)
        fill = area / (math.pi * r * r) if r > 0 else 0.0
        # the factors in the order that rejects soonest for least (bench/vision's frames): size and fill from the
        # circle alone, then the minimum-area rectangle's fill and aspect (at most what a round outline may have),
        # then the arcs (what most blobs that get that far fail) with the aspect's own score, then the ring
        geometry = self._size_score(size, self._width) * ramp(fill, *FILL)
        if geometry <= 0.0 or geometry < least or (decide and fill < HALF_FILL):
            return None
        (_, _), (rw, rh), _ = cv2.minAreaRect(c)
        elongation = max(rw, rh) / max(1e-6, min(rw, rh))
        box_fill = area / max(1e-6, rw * rh)
        geometry *= box_score(box_fill, size)
        most = geometry * ramp(elongation, *ELONGATION_ROUND)  # the aspect's score depends on the arcs, to come
        if most <= 0.0 or most < least:
            return None
        # what a rim look would need to measure it again, should its arcs or ring hold it down (a piece an opening
        # left is not deferred: its caller puts the widest disc's centre and size on it, a rim look would not)
        later = (hsv, mask, c, area, x0, y0, scale, bgr) \
            if bgr is not None and not (rim or decide or cut or r < RIM_MIN_R) else None
        edge = rim_support(bgr, cx, cy, r, colour=True) if rim and bgr is not None else 0.0
        pts = c.reshape(-1, 2)
        dx, dy = pts[:, 0] - cx, pts[:, 1] - cy  # two coordinate arrays: fewer numpy calls than an N x 2 sum
        d2 = dx * dx + dy * dy
        tol = max(1.5, ARC_TOL * r)
        on_arc = (d2 >= (r - tol) ** 2) & (d2 <= (r + tol) ** 2)
        real = outer_rim(mask, pts, cx, cy, RIM_STEP) if cut else None
        if real is not None:
            on_arc &= real
        arc = float(np.count_nonzero(on_arc)) / len(pts)
        if decide and arc < HALF_ARC:
            return None
        geometry *= stretch_score(elongation, arc)
        if geometry <= 0.0 or geometry < least:  # neither its rim nor its ring would lift it (no rim look)
            return None
        # an ellipse no longer than ELLIPSE_ASPECT fills 1 / ELLIPSE_ASPECT of its enclosing circle or more: a blob
        # filling less has something sticking out (a red lamp on the tuning photos' motorbike passed as an ellipse)
        may_be_ellipse = arc < ARC[1] and fill >= 1.0 / ELLIPSE_ASPECT
        round_part = max(ramp(arc, *ARC), ramp(edge, *RIM)) if edge else ramp(arc, *ARC)
        if not may_be_ellipse and geometry * round_part < least:
            self._defer(later, least)
            return None
        # the ring from 1.25 to 1.75 radii, sampled: outside the blob's circle, so the mask there is something else;
        # a rim all round walls the blob off from what is there (a ball on a surface of its colour)
        ring = share_set(mask, cx, cy, RING_POINTS, max(r, 2.0))
        if edge:
            ring = min(ring, 1.0 - edge)
        geometry *= ramp(ring, *RING)
        if geometry <= 0.0 or geometry < least:
            self._defer(later, least)
            return None
        ellipse_arc = ellipse_support(pts, real) if may_be_ellipse else 0.0
        hull = float(cv2.contourArea(cv2.convexHull(c)))
        solidity = area / hull if hull > 0 else 0.0
        shape = max(arc_score(arc, ellipse_arc), ramp(edge, *RIM)) if edge else arc_score(arc, ellipse_arc)
        if later is not None and (shape < 1.0 or ring > RING[1]):
            self._defer(later, least)  # held down by its arcs or ring, whether or not it passes
        geometry *= shape * ramp(solidity, *SOLIDITY)
        if geometry <= 0.0 or geometry < least:
            return None
        box = cv2.boundingRect(c)
        hue, sat = blob_colour(hsv, mask, box)
        if sat < self.colour.sat_lo + SATURATION[1] and size < CORE_BELOW and max(arc, edge) >= CORE_ROUND:
            sat = core_saturation(hsv, mask, box, area, sat)  # only where the saturation holds the score down
        hue_off = self.colour.hue_off(hue)
        if hue_off > HUE_OFF[0]:  # only where the hue holds the score down
            hue_off = self.colour.hue_off(unclipped_hue(hsv, mask, box, area, hue))
        half = (scale - 1) / 2.0  # a pixel's centre at half resolution lies between two at full resolution
        return Features(
            (cx + x0) * scale + half, (cy + y0) * scale + half, size, arc, solidity, fill, elongation, box_fill, sat,
            hue_off, ring, ellipse_arc, edge,
        )

    def _defer(self, later: tuple[MatLike, MatLike, MatLike, float, int, int, int, MatLike] | None,
               least: float) -> None:
        if later is not None:
            self.deferred.append(Deferred(*later, max(least, self.keep_from)))

    def _size_score(self, size: float, width: int) -> float:
        distance = range_of(size, self.cfg.target_diameter_m, width, self.fov_deg)
        if not self.vision.range_min_m <= distance <= self.vision.range_max_m:
            return 0.0
        return ramp(size, *SIZE)

    def score(self, f: Features, width: int) -> float:
        """0..1 (a frame asks it three or four times of one blob: remembered until the next frame's look)."""
        known = self._scores.get(id(f))
        if known is not None and known[0] is f and known[1] == width:
            return known[2]
        s = self._score(f, width)
        if len(self._scores) >= SCORES_KEPT:
            self._scores.clear()
        self._scores[id(f)] = (f, width, s)
        return s

    def _score(self, f: Features, width: int) -> float:
        shape = arc_score(f.arc, f.ellipse_arc)
        if f.rim:  # read only when measured (a domed circle's, short of whole, counts as whole)
            shape = max(shape, 1.0 if f.domed else ramp(f.rim, *RIM))
        shape *= ramp(f.solidity, *SOLIDITY) * ramp(f.fill, *FILL)
        shape *= stretch_score(f.elongation, f.arc) * box_score(f.box_fill, f.size) * self._size_score(f.size, width)
        colour = ramp(f.saturation, self.colour.sat_lo + SATURATION[0], self.colour.sat_lo + SATURATION[1])
        colour *= 1.0 - ramp(f.hue_off, *HUE_OFF)
        s = shape * colour * ramp(f.ring, *RING)
        return 0.0 if s > 0.0 and textured(f.cx, f.cy, f.size, self.round_search, self.search_scale) else s


_CORE = np.ones((3, 3), np.uint8)


def _slices(box: Sequence[int], pad: int, shape: tuple[int, ...]) -> tuple[slice, slice]:
    """The rows and columns of a blob's bounding box, ``pad`` px wider on each side within the image."""
    bx, by, bw, bh = box
    h, w = shape[:2]
    return slice(max(0, by - pad), min(h, by + bh + pad)), slice(max(0, bx - pad), min(w, bx + bw + pad))


def _mean_where(window: MatLike, keep: MatLike, channel: int, area: float, least: float, whole: float) -> float:
    """The mean of one HSV channel over the pixels ``keep`` sets (``whole`` where they are fewer than ``least`` of
    the blob's area)."""
    if cv2.countNonZero(keep) < least * area:
        return whole
    return float(cv2.mean(window, mask=keep)[channel])


def blob_colour(hsv: MatLike, mask: MatLike, box: Sequence[int]) -> tuple[float, float]:
    """The mean hue and saturation over the blob's box (the mask's pixels there are the blob's, or nearly)."""
    tight = _slices(box, 0, mask.shape)
    mean = cv2.mean(hsv[tight], mask=mask[tight])
    return float(mean[0]), float(mean[1])


def core_saturation(hsv: MatLike, mask: MatLike, box: Sequence[int], area: float, whole: float) -> float:
    """The mean saturation over the blob's mask eroded by a pixel (``whole``, the blob's, if that leaves less than
    ``CORE_MIN`` of its area). Blur, motion and JPEG blend a ball's rim with what lies behind it: a small ball's rim
    is much of its area, and its mean saturation then reads like a pink ball's.

    On the tuning photos' dev seeds (not bench/vision's), read on small round blobs, 12 balls of about 3,400 more
    reached 0.6 and none fewer, with the same detections in 14,400 empty and distractor views. Read on every blob's
    core (and the hue too), 3 more of 4,800 empty and distractor views passed; on large round blobs too, 5 pink
    balls at the threshold; the hue on the core, a shaded ball's sat further off the range's middle than the whole
    ball's."""
    wide = _slices(box, 1, mask.shape)
    inner = cv2.erode(np.asarray(mask)[wide], _CORE, borderType=cv2.BORDER_CONSTANT, borderValue=0)
    return _mean_where(hsv[wide], inner, 1, area, CORE_MIN, whole)


def unclipped_hue(hsv: MatLike, mask: MatLike, box: Sequence[int], area: float, whole: float) -> float:
    """The mean hue over the blob's pixels under ``CLIPPED`` in V (``whole``, the blob's, if that leaves less than
    ``CLIP_MIN`` of its area). Where a channel clips, the others keep growing with the light and the hue drifts
    off: an over-exposed red ball's lit side reads orange. On the dev seeds, 4 balls of about 3,400 more reached
    0.6 on the tuning photos (3 in the bright condition) and 2 of 1,700 on the validation photos (both bright),
    none fewer; 1 empty view more of 9,600 on the validation photos, the same in 14,400 empty and distractor views
    on the tuning photos."""
    tight = _slices(box, 0, mask.shape)
    window = np.asarray(hsv)[tight]
    lit = cv2.inRange(window, (0, 0, 0), (255, 255, CLIPPED - 1))
    return _mean_where(window, cv2.bitwise_and(np.asarray(mask)[tight], lit), 0, area, CLIP_MIN, whole)
