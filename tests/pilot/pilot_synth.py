"""Synthetic frames for the detector tests: a prepared background copied, shapes drawn on it."""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt

from pilot.vision.hsv.detector import HsvBlobDetector

Image = npt.NDArray[np.uint8]
FloatImage = npt.NDArray[np.float64]

RED = (30, 30, 210)  # BGR
CX, CY = 160, 120  # the centre of a 320x240 frame, where on_surface puts a ball
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


UPPER_LEFT = (-0.5, -0.5, math.sqrt(0.5))  # a light's unit direction: x right, y down, z towards the camera


def matte_ball(bg: FloatImage, cx: float, cy: float, r: float, colour: tuple[float, float, float],
               ambient: float, light: tuple[float, float, float] = UPPER_LEFT) -> FloatImage:
    """``bg`` (BGR, float) with a matte ball of radius ``r`` at (cx, cy), lit from ``light`` (a unit vector):
    ``colour`` (BGR) where the light falls square on it, ``ambient`` of it on its shaded side; its rim
    anti-aliased."""
    yy, xx = np.mgrid[0 : bg.shape[0], 0 : bg.shape[1]].astype(np.float64)
    dx, dy = (xx - cx) / r, (yy - cy) / r
    nz = np.sqrt(np.clip(1.0 - dx * dx - dy * dy, 0.0, 1.0))
    lit = np.clip(light[0] * dx + light[1] * dy + light[2] * nz, 0.0, 1.0)
    ball = (ambient + (1.0 - ambient) * lit)[..., None] * np.array(colour, np.float64)
    alpha = np.clip(r + 0.5 - np.hypot(xx - cx, yy - cy), 0.0, 1.0)[..., None]
    return np.asarray(bg * (1.0 - alpha) + ball * alpha, np.float64)


def best_hsv(img: Image) -> tuple[float, float, float] | None:
    """The colour-ball detector's best candidate in ``img`` (centre and score), None without one."""
    found = HsvBlobDetector().candidates(img)
    return (found[0].cx, found[0].cy, found[0].score) if found else None


def red_surface(seed: int, texture: float, value: float = 90.0) -> npt.NDArray[np.float64]:
    """A red surface whose brightness varies in blotches about 6 px across (BGR, float)."""
    blotches = cv2.GaussianBlur(np.random.default_rng(seed).normal(0.0, 1.0, (240, 320)), (0, 0), 3)
    v = np.clip(value + texture * blotches / blotches.std(), 0, 255)
    return np.stack([0.2 * v, 0.2 * v, v], axis=-1)


def on_surface(r: float, seed: int, texture: float,
               centres: tuple[tuple[float, float], ...] = ((CX, CY),)) -> Image:
    """Matte red balls of radius ``r`` at ``centres``, lit from the upper left, on ``red_surface``."""
    img = red_surface(seed, texture)
    for cx, cy in centres:
        img = matte_ball(img, cx, cy, r, (0.15 * 220.0, 0.15 * 220.0, 220.0), 0.3)
    return np.asarray(np.clip(img, 0, 255), np.uint8)
