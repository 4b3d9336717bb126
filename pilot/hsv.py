"""The colour-ball detector: every blob of the target's colour, scored on shape, colour purity, isolation and size.

Search, then refine (the cost stays near the floor any colour detector pays, one ``cvtColor`` and one
``inRange`` on the frame):

1. Search: the frame at half resolution (from 320 px wide up; a 16 px target is still 8 px there),
   one ``cvtColor``, one ``inRange``, a 3x3 opening, external contours. Red wraps around hue 0, which would
   need two ranges; converting the BGR frame as if it were RGB mirrors the hue circle (h -> 120 - h, in
   OpenCV's 0..179 units) and puts red at 120, in one piece. The value (V) bound follows the frame's exposure:
   in a frame whose brightest pixels are dim, it drops in proportion (never below ``V_FLOOR``), so that a
   ball's shaded side stays in the mask and the fitted circle stays on the ball.
2. Refine: the few largest blobs filling at least ``SEARCH_FILL`` of their box's disc are looked at again at
   full resolution, in a window around each: a 3x3 median (sensor noise in a ball's shaded side would fray
   its outline), mask, 3x3 opening and closing, the blob's contours, and a score 0..1 each, a product of
   ramps each between a value no target shows and one every target shows (chosen on the tuning photos of
   bench/vision); measuring stops as soon as the product so far is below ``hsv.min_score``:

   * shape: the share of the contour lying on its minimum enclosing circle ("arc support": a disk ~1, a
     disk with 30 % hidden behind an edge ~0.7, a square ~0.3), solidity, fill of that circle, and the
     aspect of its minimum-area rectangle (a rotated bar has a square bounding box).
   * colour purity: mean saturation, and how far the mean hue sits from the middle of the range (orange
     and red-brown sit near its edge, the target's red in the middle).
   * isolation: the share of the ring around the circle (1.25 to 1.75 radii, sampled) that is of the
     target's colour: a ball stands apart; a hole in a red poster's print, a piece of a red box or of a brick
     wall does not.
   * size: the range the apparent diameter implies (known diameter, field of view) must be plausible, and
     a blob under 16 px is scored down (too few pixels to show its shape).

   The circle, not the blob's centroid, gives the position: a ball's dark side or a covered part moves
   a centroid, not the circle through its rim.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .config import HsvConfig, VisionConfig
from .detection import Candidate, Detection, best_detection, frame_size, range_of
from .errors import ConfigError

MAX_CANDIDATES = 4  # the largest search blobs refined; smaller ones cannot be the nearest target
SEARCH_FILL = 0.45  # below FILL's zero: the search's coarser outline never rejects what the refinement keeps
BLOBS_PER_BOX = 2  # blobs measured in one search blob's window (noise can join two at half resolution)
SEARCH_MIN_WIDTH = 320  # frames at least this wide are searched at half resolution
V_REFERENCE = 200.0  # brightness (see _exposure) of a well-exposed frame; the V bound scales below it
V_FLOOR = 24  # the V bound never drops below this: under it hue and saturation are noise
# score ramps (zero, one), set on the tuning photos only (bench/vision/RESULTS.md)
ARC = (0.3, 0.6)
ARC_TOL = 0.12  # a contour point within this share of the radius (at least 1.5 px) lies on the circle
SOLIDITY = (0.7, 0.88)
FILL = (0.35, 0.6)
ELONGATION = (2.0, 1.4)  # minimum-area rectangle, longer side over shorter (falling ramp)
SATURATION = (10.0, 60.0)  # mean saturation above the S bound (pink and pale red sit just over it)
HUE_OFF = (0.6, 1.0)  # mean hue's distance from the range's middle, in half-widths
RING = (0.35, 0.1)  # share of the ring of the target's colour (falling ramp)
SIZE = (8.0, 16.0)  # diameter, pixels: a smaller blob has too few pixels to show its shape


Bounds = list[tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]]  # inRange's lower and upper HSV triples
# the ring from 1.25 to 1.75 radii, in radii: three circles of 48 points (sampling it costs a third of drawing it)
_ANGLES = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
_RING_POINTS = np.concatenate([k * np.stack([np.cos(_ANGLES), np.sin(_ANGLES)], axis=1) for k in (1.33, 1.5, 1.67)])


def _share_set(mask: MatLike, cx: float, cy: float, unit: npt.NDArray[np.float64], r: float) -> float:
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


class Features(NamedTuple):
    """What the score of one blob is made of (bench/vision tunes the ramps on these)."""

    cx: float
    cy: float
    size: float  # diameter of the fitted circle, pixels
    arc: float
    solidity: float
    fill: float
    elongation: float
    saturation: float  # mean, 0..255
    hue_off: float  # mean hue's distance from the range's middle, in half-widths
    ring: float


def _ramp(value: float, zero: float, one: float) -> float:
    return min(1.0, max(0.0, (value - zero) / (one - zero)))


def _contiguous(hues: set[int]) -> tuple[int, int] | None:
    lo, hi = min(hues), max(hues)
    return (lo, hi) if hi - lo + 1 == len(hues) else None


class HsvBlobDetector:
    name = "hsv"

    def __init__(
        self, config: HsvConfig | None = None, vision: VisionConfig | None = None, fov_deg: float = 60.0
    ) -> None:
        cfg = config or HsvConfig()
        if not cfg.ranges:
            raise ConfigError("hsv.ranges: at least one range is needed")
        self.cfg = cfg
        self.vision = vision or VisionConfig()
        self.fov_deg = fov_deg
        hues = {h for lo, hi in cfg.ranges for h in range(lo[0], hi[0] + 1)}
        sv = {(lo[1:], hi[1:]) for lo, hi in cfg.ranges}
        mirrored = {(120 - h) % 180 for h in hues}
        self._code = cv2.COLOR_BGR2HSV
        ranges = [(np.array(lo, np.uint8), np.array(hi, np.uint8)) for lo, hi in cfg.ranges]
        span = _contiguous(hues)
        if span is None and _contiguous(mirrored) is not None:
            span, self._code = _contiguous(mirrored), cv2.COLOR_RGB2HSV
        if span is not None and len(sv) == 1:
            ((s_lo, v_lo), (s_hi, v_hi)), = sv
            ranges = [(np.array((span[0], s_lo, v_lo), np.uint8), np.array((span[1], s_hi, v_hi), np.uint8))]
        self._ranges = ranges
        # colour purity refers to the hue range's middle and half-width (in the space the mask uses)
        used = hues if self._code == cv2.COLOR_BGR2HSV else mirrored
        self._hue_mid = (min(used) + max(used)) / 2.0
        self._hue_half = max(1.0, (max(used) - min(used)) / 2.0)
        self._width = 320  # of the frame being looked at (range estimates)
        self._sat_lo = float(min(lo[1] for lo, _ in cfg.ranges))
        k = max(1, cfg.open_kernel)
        self._kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (k, k)) if k > 1 else None

    @property
    def single_range(self) -> bool:
        """True when the mask costs one cvtColor and one inRange (contiguous hues, shared S/V bounds)."""
        return len(self._ranges) == 1

    # -- masks --------------------------------------------------------------------------------------
    def _exposure(self, image: MatLike) -> float:
        """The frame's brightness: a high order statistic of every channel on a sparse grid (a few µs)."""
        step = max(4, image.shape[1] // 24)  # about 24x18 samples at any frame size
        grid = np.asarray(image[::step, ::step]).reshape(-1)
        k = max(1, grid.size // 50)  # the 98th percentile, without a sort
        return float(np.partition(grid, grid.size - k)[grid.size - k])

    def _bounds(self, exposure: float) -> Bounds:
        gain = min(1.0, exposure / V_REFERENCE)
        if gain >= 1.0:
            return self._ranges
        out = []
        for lo, hi in self._ranges:
            adapted = lo.copy()
            adapted[2] = max(min(int(lo[2]), V_FLOOR), round(int(lo[2]) * gain))
            out.append((adapted, hi))
        return out

    def _raw_mask(self, image: MatLike, bounds: Bounds) -> MatLike:
        return self._in_range(cv2.cvtColor(image, self._code), bounds)

    @staticmethod
    def _in_range(hsv: MatLike, bounds: Bounds) -> MatLike:
        mask = cv2.inRange(hsv, bounds[0][0], bounds[0][1])
        for lo, hi in bounds[1:]:
            mask = cv2.bitwise_or(mask, cv2.inRange(hsv, lo, hi))
        return mask

    def _clean(self, mask: MatLike) -> MatLike:
        if self._kernel is None:
            return mask
        # opening: speckle goes; closing: a noisy target's pinholes and ragged rim are mended
        return cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, self._kernel), cv2.MORPH_CLOSE, self._kernel)

    def mask(self, image: MatLike) -> MatLike:
        """The full-resolution mask (with the exposure-adapted V bound), as the refinement sees it."""
        return self._clean(self._raw_mask(image, self._bounds(self._exposure(image))))

    # -- candidates ---------------------------------------------------------------------------------
    def features(self, image: MatLike) -> list[Features]:
        """Every refined blob's features (unscored)."""
        w, h = frame_size(image)
        self._width = w
        bounds = self._bounds(self._exposure(image))
        scale = 2 if w >= SEARCH_MIN_WIDTH else 1
        small = cv2.resize(image, (w // scale, h // scale), interpolation=cv2.INTER_AREA) if scale > 1 else image
        mask = self._raw_mask(small, bounds)
        if self._kernel is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, self._kernel)
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        min_area = self.cfg.min_area / (scale * scale)
        boxes = []
        for c in contours:
            if len(c) < 3 or (area := cv2.contourArea(c)) < min_area:
                continue
            x, y, bw, bh = cv2.boundingRect(c)
            # a blob filling less than SEARCH_FILL of its box's disc cannot hold a ball the refinement would take
            if area >= SEARCH_FILL * math.pi * (max(bw, bh) / 2.0) ** 2:
                boxes.append((area, (x * scale, y * scale, bw * scale, bh * scale)))
        boxes.sort(key=lambda b: b[0], reverse=True)
        found: list[Features] = []
        for _, box in boxes[:MAX_CANDIDATES]:
            for f in self._refine(image, bounds, box):
                if all(abs(f.cx - g.cx) > 1.0 or abs(f.cy - g.cy) > 1.0 for g in found):
                    found.append(f)
        return found

    def _refine(self, image: MatLike, bounds: Bounds, box: tuple[int, int, int, int]) -> list[Features]:
        """The blobs of a search box at full resolution (a search blob may be several joined by noise), in a
        window that also holds their rings."""
        w, h = frame_size(image)
        bx, by, bw, bh = box
        pad = max(bw, bh) // 2 + 4  # a ring reaches 1.75 radii; the search rounds by a pixel or two
        x0, y0, x1, y1 = max(0, bx - pad), max(0, by - pad), min(w, bx + bw + pad), min(h, by + bh + pad)
        # smoothed: sensor noise in a ball's shaded side would fray its outline and the shape with it
        roi = cv2.medianBlur(np.ascontiguousarray(image[y0:y1, x0:x1]), 3)
        hsv = cv2.cvtColor(roi, self._code)
        mask = self._clean(self._in_range(hsv, bounds))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        blobs = [(a, c) for c in contours if len(c) >= 8 and (a := float(cv2.contourArea(c))) >= self.cfg.min_area]
        blobs.sort(key=lambda b: b[0], reverse=True)
        found = (self._measure(hsv, mask, c, area, x0, y0) for area, c in blobs[:BLOBS_PER_BOX])
        return [f for f in found if f is not None]

    def _measure(self, hsv: MatLike, mask: MatLike, c: MatLike, area: float, x0: int, y0: int) -> Features | None:
        """The blob's features; None as soon as the product of its factors so far is below ``min_score``."""
        (cx, cy), r = cv2.minEnclosingCircle(c)
        size = 2.0 * r + 1.0  # the circle passes through pixel centres; the ball covers the pixels
        (_, _), (rw, rh), _ = cv2.minAreaRect(c)
        elongation = max(rw, rh) / max(1e-6, min(rw, rh))
        fill = area / (math.pi * r * r) if r > 0 else 0.0
        geometry = self._size_score(size, self._width) * _ramp(fill, *FILL)
        geometry *= _ramp(elongation, *ELONGATION)
        if geometry <= 0.0 or geometry < self.cfg.min_score:
            return None
        # the ring from 1.25 to 1.75 radii, sampled: outside the blob's circle, so the mask there is something else
        ring = _share_set(mask, cx, cy, _RING_POINTS, max(r, 2.0))
        geometry *= _ramp(ring, *RING)
        if geometry <= 0.0 or geometry < self.cfg.min_score:
            return None
        pts = c.reshape(-1, 2)
        d2 = np.square(pts - (cx, cy)).sum(axis=1)
        tol = max(1.5, ARC_TOL * r)
        on_arc = (d2 >= (r - tol) ** 2) & (d2 <= (r + tol) ** 2)
        arc = float(np.count_nonzero(on_arc)) / len(pts)
        hull = float(cv2.contourArea(cv2.convexHull(c)))
        solidity = area / hull if hull > 0 else 0.0
        geometry *= _ramp(arc, *ARC) * _ramp(solidity, *SOLIDITY)
        if geometry <= 0.0 or geometry < self.cfg.min_score:
            return None
        # colour: the mean over the blob's box (the mask's pixels there are the blob's, or nearly)
        bx, by, bw, bh = cv2.boundingRect(c)
        box = (slice(by, by + bh), slice(bx, bx + bw))
        mean = cv2.mean(hsv[box], mask=mask[box])
        return Features(
            cx + x0, cy + y0, size, arc, solidity, fill, elongation, float(mean[1]),
            abs(float(mean[0]) - self._hue_mid) / self._hue_half, ring,
        )

    def _size_score(self, size: float, width: int) -> float:
        distance = range_of(size, self.cfg.target_diameter_m, width, self.fov_deg)
        if not self.vision.range_min_m <= distance <= self.vision.range_max_m:
            return 0.0
        return _ramp(size, *SIZE)

    def score(self, f: Features, width: int) -> float:
        shape = _ramp(f.arc, *ARC) * _ramp(f.solidity, *SOLIDITY) * _ramp(f.fill, *FILL)
        shape *= _ramp(f.elongation, *ELONGATION) * self._size_score(f.size, width)
        colour = _ramp(f.saturation, self._sat_lo + SATURATION[0], self._sat_lo + SATURATION[1])
        colour *= 1.0 - _ramp(f.hue_off, *HUE_OFF)
        return shape * colour * _ramp(f.ring, *RING)

    def candidates(self, image: MatLike) -> list[Candidate]:
        width = frame_size(image)[0]
        found = []
        for f in self.features(image):
            s = self.score(f, width)
            if s > 0.0 and s >= self.cfg.min_score:
                found.append(Candidate(f.cx, f.cy, f.size, s))
        found.sort(key=lambda c: c.score, reverse=True)
        return found

    def detect(self, image: MatLike) -> Detection:
        """This frame alone, the best candidate (no tracking, no frame checks)."""
        return best_detection(self, image, self.cfg.target_diameter_m, self.fov_deg)
