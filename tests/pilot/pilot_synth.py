"""Synthetic frames for the detector tests: a prepared background copied, shapes drawn on it."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.uint8]

RED = (30, 30, 210)  # BGR
DISTRACTORS = {
    "blue": (200, 80, 30),
    "green": (40, 180, 40),
    "orange": (0, 140, 255),
    "yellow": (0, 220, 230),
    "grey": (128, 128, 128),
}


def background(width: int, height: int) -> Image:
    bg = np.empty((height, width, 3), np.uint8)
    bg[: height // 2] = (150, 160, 170)  # wall
    bg[height // 2 :] = (90, 100, 110)  # floor
    return bg


def red_disc(bg: Image, cx: int, cy: int, radius: int, gain: float = 1.0, noise: float = 0.0, seed: int = 0) -> Image:
    img = bg.copy()
    cv2.circle(img, (cx, cy), radius, RED, -1, lineType=cv2.LINE_AA)
    return degrade(img, gain, noise, seed)


def degrade(img: Image, gain: float, noise: float, seed: int) -> Image:
    out = img
    if gain != 1.0:
        out = np.asarray(cv2.convertScaleAbs(out, alpha=gain, beta=0.0), dtype=np.uint8)
    if noise > 0:
        rng = np.random.default_rng(seed)
        n = rng.normal(0.0, noise, out.shape)
        out = np.clip(out.astype(np.float64) + n, 0, 255).astype(np.uint8)
    return np.asarray(out, dtype=np.uint8)


def marker_image(dictionary: int, marker_id: int, side: int) -> Image:
    d = cv2.aruco.getPredefinedDictionary(dictionary)
    m = cv2.aruco.generateImageMarker(d, marker_id, side)
    return np.asarray(cv2.cvtColor(m, cv2.COLOR_GRAY2BGR), dtype=np.uint8)


def paste_marker(bg: Image, marker: Image, cx: int, cy: int) -> Image:
    img = bg.copy()
    side = marker.shape[0]
    border = max(4, side // 6)
    x0, y0 = cx - side // 2, cy - side // 2
    img[y0 - border : y0 + side + border, x0 - border : x0 + side + border] = 255
    img[y0 : y0 + side, x0 : x0 + side] = marker
    return img
