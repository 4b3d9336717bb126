"""Calibration: the target's HSV ranges from a sample image, checked against the rest of the picture.

The target's pixels come from a region of interest (by default the central 20 % of the image, where the
user holds the target). The hue is the mode of a circular hue histogram of the ROI's coloured pixels,
and the range's half-width follows the measured spread (a median absolute deviation) around that mode
(not percentiles with fixed margins, which a patch of background in the ROI widens without limit).
A range that crosses hue 0 (red) is split into the two ranges OpenCV's ``inRange`` needs.

Before anything is saved the ranges are tried on the whole picture: a preview (matched pixels in
white, the ROI framed) is written next to the config, and if the ranges match more than ``max_share`` of
the frame outside the ROI the calibration is refused — those ranges would light up the room.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np
from cv2.typing import MatLike

from ..common import config as config_mod
from ..common.config import HsvConfig, HsvRange, PilotConfig
from ..common.errors import ConfigError
from .detection import colour_image
from .hsv.detector import HsvBlobDetector

Roi = tuple[int, int, int, int]  # x, y, w, h
MIN_SATURATION = 60  # greyish pixels say nothing about hue
MIN_VALUE = 40
MAX_SHARE = 0.05  # of the frame outside the ROI that the ranges may match


def central_roi(image: MatLike, fraction: float = 0.2) -> Roi:
    h, w = image.shape[:2]
    rw, rh = max(1, int(w * fraction)), max(1, int(h * fraction))
    return ((w - rw) // 2, (h - rh) // 2, rw, rh)


def _check_roi(image: MatLike, roi: Roi) -> None:
    x, y, w, h = roi
    if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > image.shape[1] or y + h > image.shape[0]:
        raise ConfigError(f"calibration roi {roi} is not inside the {image.shape[1]}x{image.shape[0]} image")


def hsv_ranges_from_sample(image: MatLike, roi: Roi | None = None) -> tuple[HsvRange, ...]:
    """Ranges around the ROI's hue mode, as wide as the hue spread around it (3 sigma + 2, 3..15 units)."""
    if not colour_image(image):
        got = f"{image.dtype} {image.shape}" if isinstance(image, np.ndarray) else type(image).__name__
        raise ConfigError(f"calibration: the sample must be an 8-bit, 3-channel (BGR) image, not {got}")
    x, y, w, h = roi if roi is not None else central_roi(image)
    _check_roi(image, (x, y, w, h))
    hsv = cv2.cvtColor(np.ascontiguousarray(image[y : y + h, x : x + w]), cv2.COLOR_BGR2HSV).reshape(-1, 3)
    coloured = hsv[(hsv[:, 1] >= MIN_SATURATION) & (hsv[:, 2] >= MIN_VALUE)]
    if len(coloured) < max(20, len(hsv) // 20):
        raise ConfigError(
            f"calibration: only {len(coloured)} of the {len(hsv)} pixels in the roi are coloured "
            f"(saturation >= {MIN_SATURATION}, value >= {MIN_VALUE}): hold the target in the roi, or give --roi"
        )
    hist = np.bincount(coloured[:, 0], minlength=180).astype(np.float64)
    smooth = sum(np.roll(hist, k) for k in range(-2, 3))  # circular box filter over 5 hue units
    mode = int(np.argmax(smooth))
    offsets = (coloured[:, 0].astype(np.int64) - mode + 90) % 180 - 90
    near = np.abs(offsets) <= 20
    # robust spread (median absolute deviation, as a sigma): a patch of another colour in the roi does not widen it
    spread = 1.4826 * float(np.median(np.abs(offsets[near])))
    half = int(min(15, max(3, round(3.0 * spread) + 2)))
    members = coloured[near]
    s_lo = int(max(MIN_SATURATION, np.percentile(members[:, 1], 10) - 25))
    v_lo = int(max(MIN_VALUE, np.percentile(members[:, 2], 5) - 25))
    lo_h, hi_h = (mode - half) % 180, (mode + half) % 180
    if lo_h <= hi_h:
        return (((lo_h, s_lo, v_lo), (hi_h, 255, 255)),)
    return (((0, s_lo, v_lo), (hi_h, 255, 255)), ((lo_h, s_lo, v_lo), (179, 255, 255)))


def preview_path(config_path: str | Path) -> Path:
    path = Path(config_path)
    return path.with_name(path.stem + ".calibration.png")


def match_outside_roi(image: MatLike, ranges: tuple[HsvRange, ...], roi: Roi) -> tuple[float, MatLike]:
    """The share of the frame outside the ROI that the ranges match, and the mask."""
    mask = HsvBlobDetector(HsvConfig(ranges=ranges)).mask(image)
    x, y, w, h = roi
    outside = mask.copy()
    outside[y : y + h, x : x + w] = 0
    total = mask.shape[0] * mask.shape[1] - w * h
    return (float(np.count_nonzero(outside)) / total if total > 0 else 0.0), mask


def calibrate_to_config(
    image_path: str | Path, config_path: str | Path, roi: Roi | None = None, max_share: float = MAX_SHARE
) -> PilotConfig:
    """Read the sample image, compute the ranges, write the preview, and save them into the config file
    (created if absent) unless they match too much outside the ROI."""
    image = cv2.imread(str(image_path), cv2.IMREAD_COLOR)
    if image is None:
        raise ConfigError(f"calibration image {str(image_path)!r}: cannot read")
    box = roi if roi is not None else central_roi(image)
    ranges = hsv_ranges_from_sample(image, box)
    share, mask = match_outside_roi(image, ranges, box)
    preview = image.copy()
    preview[mask > 0] = (255, 255, 255)
    x, y, w, h = box
    cv2.rectangle(preview, (x, y), (x + w - 1, y + h - 1), (0, 255, 0), 2)
    path = Path(config_path)
    cv2.imwrite(str(preview_path(path)), preview)
    if share > max_share:
        raise ConfigError(
            f"calibration refused: the ranges {ranges} match {share:.1%} of the picture outside the roi "
            f"(at most {max_share:.0%} allowed): the target's colour is all over this view. Calibrate "
            f"in front of a plainer background, or give --roi tighter around the target; "
            f"preview in {preview_path(path)}; {path} is unchanged"
        )
    base = config_mod.load(path) if path.exists() else PilotConfig()
    updated = dataclasses.replace(base, hsv=dataclasses.replace(base.hsv, ranges=ranges))
    config_mod.validate(updated, str(path))
    config_mod.save(updated, path)
    return updated
