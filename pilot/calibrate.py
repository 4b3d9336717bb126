"""Calibration helper: HSV ranges from a sample image of the target, saved to the config file.

The target's pixels are taken from a region of interest (by default the central 20 % of the
image, where the user holds the target). Hue is treated as circular: a range that crosses hue 0
(red) is split into the two ranges OpenCV's ``inRange`` needs.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np
from cv2.typing import MatLike

from . import config as config_mod
from .config import HsvRange, PilotConfig
from .errors import ConfigError

Roi = tuple[int, int, int, int]  # x, y, w, h


def central_roi(image: MatLike, fraction: float = 0.2) -> Roi:
    h, w = image.shape[:2]
    rw, rh = max(1, int(w * fraction)), max(1, int(h * fraction))
    return ((w - rw) // 2, (h - rh) // 2, rw, rh)


def hsv_ranges_from_sample(
    image: MatLike,
    roi: Roi | None = None,
    hue_margin: int = 4,
    sat_margin: int = 40,
    val_margin: int = 50,
    percentile: float = 3.0,
) -> tuple[HsvRange, ...]:
    """HSV ranges covering the ROI's pixels (between the given percentiles), widened by margins."""
    x, y, w, h = roi if roi is not None else central_roi(image)
    if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > image.shape[1] or y + h > image.shape[0]:
        raise ConfigError(f"calibration roi {(x, y, w, h)} is not inside the {image.shape[1]}x{image.shape[0]} image")
    hsv = cv2.cvtColor(np.ascontiguousarray(image[y : y + h, x : x + w]), cv2.COLOR_BGR2HSV).reshape(-1, 3)
    hue = hsv[:, 0].astype(np.float64)
    # circular mean of the hue (OpenCV hue is 0..179, i.e. degrees / 2)
    angles = hue * (2.0 * np.pi / 180.0)
    mean = float(np.arctan2(np.sin(angles).mean(), np.cos(angles).mean())) * 180.0 / (2.0 * np.pi)
    offsets = (hue - mean + 90.0) % 180.0 - 90.0  # signed distance from the mean, -90..90
    lo_off = float(np.percentile(offsets, percentile)) - hue_margin
    hi_off = float(np.percentile(offsets, 100.0 - percentile)) + hue_margin
    s_lo = int(max(0, np.percentile(hsv[:, 1], percentile) - sat_margin))
    v_lo = int(max(0, np.percentile(hsv[:, 2], percentile) - val_margin))
    lo_h = int(np.floor(mean + lo_off))
    hi_h = int(np.ceil(mean + hi_off))
    if hi_h - lo_h >= 179:
        return (((0, s_lo, v_lo), (179, 255, 255)),)
    lo_h %= 180
    hi_h %= 180
    if lo_h <= hi_h:
        return (((lo_h, s_lo, v_lo), (hi_h, 255, 255)),)
    return (((0, s_lo, v_lo), (hi_h, 255, 255)), ((lo_h, s_lo, v_lo), (179, 255, 255)))


def calibrate_to_config(image_path: str | Path, config_path: str | Path, roi: Roi | None = None) -> PilotConfig:
    """Read the sample image, compute the ranges, and write them into the config file (created if absent)."""
    image = cv2.imread(str(image_path), cv2.IMREAD_COLOR)
    if image is None:
        raise ConfigError(f"calibration image {str(image_path)!r}: cannot read")
    ranges = hsv_ranges_from_sample(image, roi)
    path = Path(config_path)
    base = config_mod.load(path) if path.exists() else PilotConfig()
    updated = dataclasses.replace(base, hsv=dataclasses.replace(base.hsv, ranges=ranges))
    config_mod.validate(updated, str(path))
    config_mod.save(updated, path)
    return updated
