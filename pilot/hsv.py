"""The colour-ball detector: every blob of the target's colour, scored on shape, colour purity and size.

Mask: one ``cvtColor`` and one ``inRange``, the floor any colour detector pays. Red wraps around hue 0,
which would need two ranges; converting the BGR frame as if it were RGB mirrors the hue circle
(h -> 120 - h, in OpenCV's 0..179 units) and puts red at 120, in one piece. A 3x3 opening removes speckle.

Candidates (the largest few external contours) are scored 0..1, each factor a ramp between a value that
no target shows and one that every target shows (bench/vision/RESULTS.md has the figures):

* shape: the share of the contour lying on its minimum enclosing circle ("arc support": a disk ~1, a
  disk with 30 % hidden behind an edge ~0.7, a square or a rectangle ~0.2), solidity (contour area over
  its convex hull), and fill of that circle. The circle, not the blob's centroid, gives the position:
  a ball's dark side or a covered part moves a centroid, not the circle through its lit rim.
* colour purity: mean saturation, and how far the mean hue sits from the middle of the range
  (orange and red-brown sit near its edge, the target's red in the middle).
* size: the range the apparent diameter implies (known diameter, field of view) must be plausible.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from cv2.typing import MatLike

from .config import HsvConfig, VisionConfig
from .detection import Candidate, Detection, frame_size, range_of
from .errors import ConfigError

MAX_CANDIDATES = 6  # the largest blobs scored in full; smaller ones cannot be the nearest target
# score ramps (zero, one), set on the tuning photos only (bench/vision/RESULTS.md)
ARC = (0.25, 0.5)
SOLIDITY = (0.7, 0.88)
FILL = (0.35, 0.6)
HUE_OFF = (0.5, 0.95)  # mean hue's distance from the range's middle, in half-widths
MAX_ASPECT = 2.2  # bounding box, longer side over shorter: a ball half covered is still under 2


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
        self._ranges = [(np.array(lo, np.uint8), np.array(hi, np.uint8)) for lo, hi in cfg.ranges]
        span = _contiguous(hues)
        if span is None and _contiguous(mirrored) is not None:
            span, self._code = _contiguous(mirrored), cv2.COLOR_RGB2HSV
        if span is not None and len(sv) == 1:
            ((s_lo, v_lo), (s_hi, v_hi)), = sv
            self._ranges = [(np.array((span[0], s_lo, v_lo), np.uint8), np.array((span[1], s_hi, v_hi), np.uint8))]
        # colour purity refers to the hue range's middle and half-width (in the space the mask uses)
        used = hues if self._code == cv2.COLOR_BGR2HSV else mirrored
        self._hue_mid = (min(used) + max(used)) / 2.0
        self._hue_half = max(1.0, (max(used) - min(used)) / 2.0)
        self._sat_lo = float(min(lo[1] for lo, _ in cfg.ranges))
        k = max(1, cfg.open_kernel)
        self._kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (k, k)) if k > 1 else None

    @property
    def single_range(self) -> bool:
        """True when the mask costs one cvtColor and one inRange (contiguous hues, shared S/V bounds)."""
        return len(self._ranges) == 1

    def _hsv(self, image: MatLike) -> MatLike:
        return cv2.cvtColor(image, self._code)

    def _mask_of(self, hsv: MatLike) -> MatLike:
        lo, hi = self._ranges[0]
        mask = cv2.inRange(hsv, lo, hi)
        for lo, hi in self._ranges[1:]:
            mask = cv2.bitwise_or(mask, cv2.inRange(hsv, lo, hi))
        if self._kernel is not None:
            # opening: speckle goes; closing: a noisy target's pinholes and ragged rim are mended
            mask = cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, self._kernel), cv2.MORPH_CLOSE, self._kernel)
        return mask

    def mask(self, image: MatLike) -> MatLike:
        return self._mask_of(self._hsv(image))

    def candidates(self, image: MatLike) -> list[Candidate]:
        hsv = self._hsv(image)
        mask = self._mask_of(hsv)
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        blobs = []
        for c in contours:
            if len(c) < 12:  # a blob of min_area >= 4 px whose outline is this short is speckle or a line
                continue
            area = cv2.contourArea(c)
            if area >= self.cfg.min_area:
                blobs.append((area, c))
        blobs.sort(key=lambda b: b[0], reverse=True)
        width = frame_size(image)[0]
        found = []
        for area, c in blobs[:MAX_CANDIDATES]:
            cand = self._score(hsv, mask, c, area, width)
            if cand is not None and cand.score >= self.cfg.min_score:
                found.append(cand)
        found.sort(key=lambda c: c.score, reverse=True)
        return found

    def _score(self, hsv: MatLike, mask: MatLike, c: MatLike, area: float, width: int) -> Candidate | None:
        x, y, w, h = cv2.boundingRect(c)
        if max(w, h) > MAX_ASPECT * min(w, h):
            return None
        (cx, cy), r = cv2.minEnclosingCircle(c)
        size = 2.0 * r + 1.0  # the circle passes through pixel centres; the ball covers the pixels
        distance = range_of(size, self.cfg.target_diameter_m, width, self.fov_deg)
        if not self.vision.range_min_m <= distance <= self.vision.range_max_m:
            return None
        pts = np.asarray(c, np.float32).reshape(-1, 2)
        gap = np.abs(np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) - r)
        arc = float(np.count_nonzero(gap <= max(1.5, 0.12 * r))) / len(pts)
        hull = float(cv2.contourArea(cv2.convexHull(c)))
        solidity = area / hull if hull > 0 else 0.0
        fill = area / (math.pi * r * r) if r > 0 else 0.0
        shape = _ramp(arc, ARC[0], ARC[1]) * _ramp(solidity, SOLIDITY[0], SOLIDITY[1]) * _ramp(fill, FILL[0], FILL[1])
        if shape <= 0.0:
            return None
        mean, _ = cv2.meanStdDev(hsv[y : y + h, x : x + w], mask=mask[y : y + h, x : x + w])
        hue_off = abs(float(mean[0][0]) - self._hue_mid) / self._hue_half
        colour = _ramp(float(mean[1][0]), self._sat_lo, self._sat_lo + 50.0) * (1.0 - _ramp(hue_off, *HUE_OFF))
        return Candidate(cx, cy, size, shape * colour)

    def detect(self, image: MatLike) -> Detection:
        """This frame alone, best candidate (no tracking, no frame checks: see ``pilot.detect.make_detector``)."""
        w, h = frame_size(image)
        cands = self.candidates(image)
        if not cands:
            return Detection(False, width=w, height=h)
        best = cands[0]
        distance = range_of(best.size, self.cfg.target_diameter_m, w, self.fov_deg)
        return Detection(True, best.cx, best.cy, best.size, best.score, w, h, range_m=distance)
