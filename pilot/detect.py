"""Target detectors behind one interface: ``detect(image) -> Detection``.

* ``HsvBlobDetector`` (default): BGR->HSV, one ``inRange`` per hue range (red needs two, it wraps
  around hue 0), a morphological opening, the largest external contour, its moments.
* ``ArucoMarkerDetector``: ``cv2.aruco.ArucoDetector`` on the grey image, one marker id (or any).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .config import ArucoConfig, HsvConfig, PilotConfig
from .errors import ConfigError


@dataclass(frozen=True)
class Detection:
    found: bool
    cx: float = 0.0  # centre, pixels
    cy: float = 0.0
    size: float = 0.0  # apparent size, pixels (equivalent diameter of a blob, mean side of a marker)
    confidence: float = 0.0  # 0..1
    width: int = 0  # frame size the numbers refer to
    height: int = 0

    @property
    def error_x(self) -> float:
        """Horizontal offset from the image centre, -1 (left edge) .. +1 (right edge)."""
        return (self.cx - self.width / 2.0) / (self.width / 2.0) if self.width else 0.0

    @property
    def error_y(self) -> float:
        """Vertical offset from the image centre, -1 (top) .. +1 (bottom)."""
        return (self.cy - self.height / 2.0) / (self.height / 2.0) if self.height else 0.0

    @property
    def relative_size(self) -> float:
        """Apparent size as a fraction of the frame width."""
        return self.size / self.width if self.width else 0.0


class Detector(Protocol):
    name: str

    def detect(self, image: MatLike) -> Detection: ...


def _not_found(image: MatLike) -> Detection:
    h, w = image.shape[:2]
    return Detection(found=False, width=int(w), height=int(h))


class HsvBlobDetector:
    name = "hsv"

    def __init__(self, config: HsvConfig | None = None) -> None:
        cfg = config or HsvConfig()
        if not cfg.ranges:
            raise ConfigError("hsv.ranges: at least one range is needed")
        self._ranges = [
            (np.array(lo, dtype=np.uint8), np.array(hi, dtype=np.uint8)) for lo, hi in cfg.ranges
        ]
        # Fast path when every range shares its saturation/value bounds (red's two ranges do): one
        # inRange on S and V, and the hue ranges as a 256-entry lookup table on the hue channel,
        # instead of one 3-channel inRange per hue range.
        sv = {(lo[1:], hi[1:]) for lo, hi in cfg.ranges}
        self._sv: tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]] | None = None
        self._hue_lut: npt.NDArray[np.uint8] | None = None
        if len(cfg.ranges) > 1 and len(sv) == 1:
            (s_lo, s_hi), = sv
            self._sv = (np.array((0, *s_lo), np.uint8), np.array((255, *s_hi), np.uint8))
            lut = np.zeros(256, np.uint8)
            for lo, hi in cfg.ranges:
                lut[lo[0] : hi[0] + 1] = 255
            self._hue_lut = lut
        self.min_area = cfg.min_area
        k = max(1, cfg.open_kernel)
        self._kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (k, k)) if k > 1 else None

    def mask(self, image: MatLike) -> MatLike:
        hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)
        if self._sv is not None and self._hue_lut is not None:
            mask = cv2.bitwise_and(
                cv2.inRange(hsv, self._sv[0], self._sv[1]),
                cv2.LUT(cv2.extractChannel(hsv, 0), self._hue_lut),
            )
        else:
            lo, hi = self._ranges[0]
            mask = cv2.inRange(hsv, lo, hi)
            for lo, hi in self._ranges[1:]:
                mask = cv2.bitwise_or(mask, cv2.inRange(hsv, lo, hi))
        if self._kernel is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, self._kernel)
        return mask

    def detect(self, image: MatLike) -> Detection:
        mask = self.mask(image)
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        if not contours:
            return _not_found(image)
        best = max(contours, key=cv2.contourArea)
        area = float(cv2.contourArea(best))
        if area < self.min_area:
            return _not_found(image)
        m = cv2.moments(best)
        if m["m00"] <= 0:
            return _not_found(image)
        (_, _), radius = cv2.minEnclosingCircle(best)
        circle = math.pi * radius * radius
        confidence = min(1.0, area / circle) if circle > 0 else 0.0
        h, w = image.shape[:2]
        return Detection(
            found=True,
            cx=m["m10"] / m["m00"],
            cy=m["m01"] / m["m00"],
            size=2.0 * math.sqrt(area / math.pi),
            confidence=confidence,
            width=int(w),
            height=int(h),
        )


def aruco_dictionary(name: str) -> cv2.aruco.Dictionary:
    code = getattr(cv2.aruco, name, None)
    if not name.startswith("DICT_") or not isinstance(code, int):
        raise ConfigError(f"aruco.dictionary: unknown ArUco dictionary {name!r} (e.g. DICT_4X4_50)")
    return cv2.aruco.getPredefinedDictionary(code)


class ArucoMarkerDetector:
    name = "aruco"

    def __init__(self, config: ArucoConfig | None = None) -> None:
        cfg = config or ArucoConfig()
        self.marker_id = cfg.marker_id
        params = cv2.aruco.DetectorParameters()
        params.adaptiveThreshConstant = cfg.adaptive_thresh_constant
        self._detector = cv2.aruco.ArucoDetector(aruco_dictionary(cfg.dictionary), params)

    def detect(self, image: MatLike) -> Detection:
        grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
        corners, ids, _ = self._detector.detectMarkers(grey)
        if ids is None or len(corners) == 0:
            return _not_found(image)
        best: tuple[float, float, float] | None = None
        for quad, marker in zip(corners, np.asarray(ids).reshape(-1), strict=True):
            if self.marker_id >= 0 and int(marker) != self.marker_id:
                continue
            pts = np.asarray(quad, dtype=np.float64).reshape(4, 2)
            sides = np.linalg.norm(pts - np.roll(pts, 1, axis=0), axis=1)
            side = float(sides.mean())
            if best is None or side > best[2]:
                centre = pts.mean(axis=0)
                best = (float(centre[0]), float(centre[1]), side)
        if best is None:
            return _not_found(image)
        h, w = image.shape[:2]
        return Detection(True, best[0], best[1], best[2], 1.0, int(w), int(h))


def make_detector(config: PilotConfig) -> Detector:
    if config.detector == "hsv":
        return HsvBlobDetector(config.hsv)
    if config.detector == "aruco":
        return ArucoMarkerDetector(config.aruco)
    raise ConfigError(f"option 'detector' must be 'hsv' or 'aruco', got {config.detector!r}")
