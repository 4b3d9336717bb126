"""A simpler colour-ball detector (``hsv.simple: true``): the colour mask (the room's model or the default ranges),
then one shape, colour, isolation and size score per blob, within the frame's budget. Beside the rule-grown
detector of ``hsv/`` until it measures at least as well on the held-out sources (bench/vision/RESULTS.md has both).

Each blob of the half-resolution mask, largest first, is measured again at full resolution in a window around it:
its circle (the minimum enclosing one) and the share of its outline on that circle (a ball 30 % hidden keeps 0.7 of
it, a square 0.3), its solidity and fill of the circle, its mean saturation over the mask's bound, and how much of
the ring around it (1.25-1.75 radii) is of its colour (a ball stands apart from a red wall it is not part of). The
score is the product of ramps of the hsv detector's measures (hsv/score.py); the circle gives the position.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import cv2
import numpy as np
from cv2.typing import MatLike

from ..common.config import HsvConfig, VisionConfig
from .budget import FrameBudget
from .detection import Candidate, Detection, best_detection, focal_px, frame_size, malformed
from .hsv.colour import Bounds, ColourMask
from .hsv.score import ARC, ARC_TOL, FILL, RING, SATURATION, SIZE, SOLIDITY, ramp

MAX_BLOBS = 6  # the largest blobs measured: smaller ones cannot be the nearest target
RING_SPAN = (1.25, 1.75)  # radii
RING_POINTS = 48


class SimpleBallDetector:
    name = "hsv"

    def __init__(self, config: HsvConfig | None = None, vision: VisionConfig | None = None, fov_deg: float = 60.0,
                 clock: Callable[[], float] | None = None) -> None:
        self.cfg = config or HsvConfig()
        self.vision = vision or VisionConfig()
        self.fov_deg = fov_deg
        self.colour = ColourMask(self.cfg)
        self.budget = FrameBudget(self.vision.budget_ms, clock)
        angles = np.linspace(0.0, 2.0 * math.pi, RING_POINTS, endpoint=False)
        radii = np.repeat(np.linspace(*RING_SPAN, 3), RING_POINTS)
        self._ring = np.stack([np.tile(np.cos(angles), 3) * radii, np.tile(np.sin(angles), 3) * radii], axis=1)

    @property
    def cut_short(self) -> bool:
        return self.budget.exhausted

    def candidates(self, image: MatLike) -> list[Candidate]:
        if malformed(image) is not None:
            return []
        self.budget.start()
        w, h = frame_size(image)
        scale = 2 if w >= 320 else 1
        small = cv2.resize(image, (w // scale, h // scale), interpolation=cv2.INTER_AREA) if scale > 1 else image
        bounds = self.colour.bounds_for(small)
        mask = self.colour.clean(self.colour.in_range(cv2.cvtColor(small, self.colour.code), bounds))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        blobs = sorted((c for c in contours if cv2.contourArea(c) >= self.cfg.min_area / scale**2),
                       key=cv2.contourArea, reverse=True)
        out: list[Candidate] = []
        for i, c in enumerate(blobs[:MAX_BLOBS]):
            if i and self.budget.out():
                break
            x, y, bw, bh = (v * scale for v in cv2.boundingRect(c))
            cand = self._measure(image, bounds, x, y, bw, bh, w)
            if cand is not None and cand.score >= self.cfg.min_score:
                out.append(cand)
        return sorted(out, key=lambda k: k.score, reverse=True)

    def _measure(self, image: MatLike, bounds: Bounds, x: int, y: int, bw: int, bh: int,
                 width: int) -> Candidate | None:
        """The blob in the box (x, y, bw, bh) measured in a window that holds its ring, as a scored candidate."""
        h_img, w_img = image.shape[:2]
        pad = max(bw, bh) + 4  # the ring reaches 1.75 radii
        x0, y0 = max(0, x - pad), max(0, y - pad)
        x1, y1 = min(w_img, x + bw + pad), min(h_img, y + bh + pad)
        roi = cv2.medianBlur(np.ascontiguousarray(image[y0:y1, x0:x1]), 3)
        hsv = cv2.cvtColor(roi, self.colour.code)
        mask = self.colour.clean(self.colour.in_range(hsv, bounds))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        if not contours:
            return None
        # the window's blob at the search blob's middle (a larger one of its colour may share the window)
        mid = (x + bw / 2.0 - x0, y + bh / 2.0 - y0)
        inside = [k for k in contours if cv2.pointPolygonTest(k, mid, False) >= 0]
        c = max(inside or contours, key=cv2.contourArea)
        area = float(cv2.contourArea(c))
        if area < self.cfg.min_area or len(c) < 8:
            return None
        (cx, cy), r = cv2.minEnclosingCircle(c)
        pts = c.reshape(-1, 2).astype(np.float64)
        on_circle = np.abs(np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) - r) <= max(1.5, ARC_TOL * r)
        arc = float(np.count_nonzero(on_circle)) / len(pts)
        solidity = area / max(1.0, float(cv2.contourArea(cv2.convexHull(c))))
        fill = area / (math.pi * r * r)
        blob = np.zeros_like(mask)
        cv2.drawContours(blob, [c], -1, 255, -1)
        saturation = float(cv2.mean(hsv, mask=blob)[1]) - self.colour.sat_lo
        ring = self._ring_share(mask, cx, cy, r)
        size = 2.0 * r
        distance = self.cfg.target_diameter_m * focal_px(width, self.fov_deg) / size
        if not self.vision.range_min_m <= distance <= self.vision.range_max_m:
            return None
        score = (ramp(arc, *ARC) * ramp(solidity, *SOLIDITY) * ramp(fill, *FILL) * ramp(saturation, *SATURATION)
                 * ramp(ring, *RING) * ramp(size, *SIZE))
        return Candidate(cx + x0, cy + y0, size, score)

    def _ring_share(self, mask: MatLike, cx: float, cy: float, r: float) -> float:
        """The share of the ring's points (inside the window) set in the mask."""
        pts = np.round(self._ring * r + (cx, cy)).astype(np.int32)
        h, w = mask.shape[:2]
        inside = (pts[:, 0] >= 0) & (pts[:, 0] < w) & (pts[:, 1] >= 0) & (pts[:, 1] < h)
        if not inside.any():
            return 0.0
        p = pts[inside]
        return float(np.count_nonzero(np.asarray(mask)[p[:, 1], p[:, 0]])) / len(p)

    def detect(self, image: MatLike) -> Detection:
        return best_detection(self, image, self.cfg.target_diameter_m, self.fov_deg)

    def aim_on_target(self, image: MatLike, size: float) -> bool:
        """Whether the frame's centre (a third of the ball across) shows the target's colour: half its pixels."""
        if malformed(image) is not None:
            return False
        r = max(2, min(round(size / 6.0), image.shape[0] // 4))
        return self.colour.centre_holds(image, r, 1.0, 0.5)

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        """None: the frame's look measured every blob already."""
        return []
