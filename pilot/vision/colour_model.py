"""The room's colour model: which hue-saturation pairs are the user's ball rather than the room around it.

A ratio histogram (Swain and Ballard's back-projection): for each of 180 hues x 32 saturations, the share of the
ball's pixels over the ball's and the room's (each normalised), so a colour the room is full of scores low even when
the ball has it too. The detector keeps, of its colour mask, the pixels whose back-projection reaches the model's
threshold. The file (``.npz``) holds its format version, the histogram, the threshold and the camera's frame size;
any other version, a truncated or corrupt file is refused when the pilot starts, naming the file.
"""

from __future__ import annotations

import math
import zipfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from ..common.errors import ConfigError

VERSION = 1
H_BINS, S_BINS = 180, 32  # one bin per hue unit: a red model mirrors exactly into the RGB-converted hue circle
RANGES = [0, 180, 0, 256]
FloatArray = npt.NDArray[np.float32]


@dataclass(frozen=True)
class ColourModel:
    ratio: FloatArray  # H_BINS x S_BINS, 0..255: the ball's share of each colour
    threshold: float  # back-projection at or above: the ball's colour
    width: int  # the camera's frame size the model was learnt at
    height: int

    def mirrored(self) -> ColourModel:
        """The model for a hue circle mirrored as ``h -> 120 - h`` (a frame converted as RGB: red in one piece)."""
        idx = (120 - np.arange(H_BINS)) % 180
        return ColourModel(np.ascontiguousarray(self.ratio[idx]), self.threshold, self.width, self.height)

    def back_project(self, hsv: MatLike) -> MatLike:
        """Each pixel's ball-ness, 0..255."""
        return cv2.calcBackProject([hsv], [0, 1], self.ratio, RANGES, 1)

    def mask(self, hsv: MatLike) -> MatLike:
        """255 where the pixel's colour is the ball's."""
        return cv2.inRange(self.back_project(hsv), math.ceil(self.threshold), 255)


def histogram(hsv_pixels: npt.NDArray[np.uint8]) -> FloatArray:
    """The normalised hue-saturation histogram of N x 3 HSV pixels (BGR2HSV's hue)."""
    pts = np.ascontiguousarray(hsv_pixels.reshape(-1, 1, 3))
    hist = cv2.calcHist([pts], [0, 1], None, [H_BINS, S_BINS], RANGES)
    return np.asarray(hist / max(1.0, float(hist.sum())), np.float32)


def ratio_histogram(ball: FloatArray, room: FloatArray) -> FloatArray:
    """The ball's share of each colour (0..255), smoothed over neighbouring bins (hue wrapping round)."""
    smooth_ball = cv2.GaussianBlur(np.vstack([ball[-4:], ball, ball[:4]]), (5, 5), 0)[4:-4]
    smooth_room = cv2.GaussianBlur(np.vstack([room[-4:], room, room[:4]]), (5, 5), 0)[4:-4]
    return np.asarray(255.0 * smooth_ball / (smooth_ball + smooth_room + 1e-6), np.float32)


def save(model: ColourModel, path: str | Path) -> None:
    with open(path, "wb") as f:
        np.savez(f, version=np.int32(VERSION), ratio=model.ratio, threshold=np.float32(model.threshold),
                 size=np.array([model.width, model.height], np.int32))


def load(path: str | Path) -> ColourModel:
    """The model in ``path``; a ConfigError naming the file if it is missing, truncated, corrupt or of another
    version."""
    where = f"colour model {str(path)!r}"
    try:
        with np.load(path, allow_pickle=False) as data:
            version = int(data["version"])
            if version != VERSION:
                raise ConfigError(f"{where}: version {version}, this pilot reads version {VERSION}: calibrate again")
            ratio = np.asarray(data["ratio"], np.float32)
            threshold = float(data["threshold"])
            width, height = (int(v) for v in data["size"])
    except ConfigError:
        raise
    except FileNotFoundError:
        raise ConfigError(f"{where}: no such file (run pilot --calibrate, or remove hsv.colour_model)") from None
    except (OSError, ValueError, KeyError, EOFError, TypeError, zipfile.BadZipFile) as exc:
        raise ConfigError(f"{where}: corrupt or truncated ({type(exc).__name__}): calibrate again") from None
    if ratio.shape != (H_BINS, S_BINS) or not np.isfinite(ratio).all() or not 0.0 < threshold <= 255.0:
        raise ConfigError(f"{where}: corrupt (histogram {ratio.shape}, threshold {threshold}): calibrate again")
    if width < 1 or height < 1:
        raise ConfigError(f"{where}: corrupt (frame size {width}x{height}): calibrate again")
    return ColourModel(ratio, threshold, width, height)
