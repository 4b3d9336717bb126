"""The fixed-size features a learned verifier reads from one ball candidate (pilot/vision/verify.py).

The window around the candidate's circle (two radii each side) is resized to ``SIDE`` x ``SIDE`` pixels, so a
16 px ball and a 120 px one give the same numbers: redness, saturation and brightness by radial band (a ball is red
inside, not red just outside, all round), per angular sector (a red letter inside a round outline is not), an
orientation histogram of the brightness gradient per cell (what OpenCV's HOG reads; OpenCV 5 has no
``HOGDescriptor``), small images of redness and brightness, and the detector's own score and the size.
``VERSION`` changes whenever these numbers do: a model trained on other features is refused at load.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .detection import Candidate

VERSION = 1
SIDE = 24  # the window's side once resized: a circle of radius SIDE / 4
RED_HUE = 20.0  # OpenCV hue units from red at which redness reaches 0
BANDS = (0.0, 0.5, 0.8, 1.0, 1.2, 1.5, 2.0)  # radial bands, in radii
SECTORS = 8
CELLS, BINS = 4, 8  # orientation histogram: CELLS x CELLS cells of BINS directions
SMALL = 8  # the small redness and brightness images
FloatArray = npt.NDArray[np.float32]

_IY, _IX = np.mgrid[0:SIDE, 0:SIDE]
_yy, _xx = _IY.astype(np.float32) + 0.5 - SIDE / 2, _IX.astype(np.float32) + 0.5 - SIDE / 2
_RADIUS = np.hypot(_xx, _yy) / (SIDE / 4)  # in radii of the candidate's circle
_SECTOR = ((np.arctan2(_yy, _xx) + math.pi) / (2 * math.pi) * SECTORS).astype(np.int32) % SECTORS
_BAND = np.digitize(_RADIUS, BANDS[1:-1]).astype(np.int32)  # 0 .. len(BANDS) - 2 (the corners join the last)
_INNER = (_RADIUS >= 0.5) & (_RADIUS < 0.95)
_OUTER = (_RADIUS >= 1.1) & (_RADIUS < 1.6)
_RIM = ((_RADIUS >= 0.8) & (_RADIUS < 1.2)).ravel()
_MIDDLE = (_RADIUS < 0.8).ravel()
_UX, _UY = _xx / np.maximum(np.hypot(_xx, _yy), 1e-3), _yy / np.maximum(np.hypot(_xx, _yy), 1e-3)
_CELL = (np.arange(SIDE) * CELLS // SIDE).astype(np.int32)
_CELL_BIN = ((_CELL[:, None] * CELLS + _CELL[None, :]) * BINS).astype(np.int32).ravel()


def _means(regions: list[npt.NDArray[np.bool_]]) -> FloatArray:
    """Each region's averaging weights over the window's pixels, one row per region."""
    rows = np.stack([r.ravel().astype(np.float32) for r in regions])
    return np.asarray(rows / np.maximum(rows.sum(axis=1, keepdims=True), 1.0), np.float32)


_N_BANDS = len(BANDS) - 1
_BLOCK = SIDE // SMALL
_SMALL_CELL = _IY // _BLOCK * SMALL + _IX // _BLOCK
_REGIONS = _means([k == _BAND for k in range(_N_BANDS)] + [_INNER & (k == _SECTOR) for k in range(SECTORS)]
                  + [_OUTER & (k == _SECTOR) for k in range(SECTORS)]
                  + [k == _SMALL_CELL for k in range(SMALL * SMALL)])
LENGTH = 4 * (len(BANDS) - 1) + 6 + 3 + CELLS * CELLS * BINS + 2 * SMALL * SMALL + 2


def window(image: MatLike, c: Candidate) -> MatLike:
    """The candidate's window (two radii each side of the centre, the frame's edge repeated), SIDE x SIDE."""
    side = max(4, round(2.0 * max(c.size, 2.0)))
    patch = cv2.getRectSubPix(image, (side, side), (float(c.cx), float(c.cy)))
    return cv2.resize(patch, (SIDE, SIDE), interpolation=cv2.INTER_AREA if side > SIDE else cv2.INTER_LINEAR)


def features(image: MatLike, c: Candidate) -> FloatArray:
    """The candidate's feature vector, LENGTH numbers."""
    patch = window(image, c)
    hsv = cv2.cvtColor(patch, cv2.COLOR_BGR2HSV).reshape(-1, 3).astype(np.float32)
    hue, sat, val = hsv[:, 0], hsv[:, 1] / 255.0, hsv[:, 2] / 255.0
    red = sat * np.clip(1.0 - np.minimum(hue, 180.0 - hue) / RED_HUE, 0.0, 1.0)
    m = _REGIONS @ np.stack([red, val, sat, val * val], axis=1)  # regions x (red, val, sat, val^2)
    bands = m[:_N_BANDS]
    spread = np.sqrt(np.maximum(bands[:, 3] - bands[:, 1] ** 2, 0.0))
    inner, outer = m[_N_BANDS : _N_BANDS + SECTORS, 0], m[_N_BANDS + SECTORS : _N_BANDS + 2 * SECTORS, 0]
    contrast = inner - outer
    sectors = np.array([contrast.min(), contrast.mean(), contrast.max(), contrast.std(), inner.min(), inner.max()],
                       np.float32)
    grey = cv2.cvtColor(patch, cv2.COLOR_BGR2GRAY).astype(np.float32) / 255.0
    gx, gy = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3), cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    mag = np.hypot(gx, gy).ravel()
    radial = np.abs(gx * _UX + gy * _UY).ravel()
    edges = np.array([radial[_RIM].sum() / (mag[_RIM].sum() + 1e-3), mag[_MIDDLE].mean(),
                      mag[_OUTER.ravel()].mean()], np.float32)
    angle = ((np.arctan2(gy, gx).ravel() % math.pi) * (BINS / math.pi)).astype(np.int32) % BINS  # unsigned
    hog = np.bincount(_CELL_BIN + angle, mag, minlength=CELLS * CELLS * BINS).astype(np.float32)
    hog /= float(np.linalg.norm(hog)) + 1e-3
    small = m[_N_BANDS + 2 * SECTORS :, :2].T.ravel()  # the small redness image, then the brightness one
    scalars = np.array([c.score, math.log(max(c.size, 1.0))], np.float32)
    return np.concatenate([bands[:, :3].T.ravel(), spread, sectors, edges, hog, small, scalars]).astype(np.float32)
