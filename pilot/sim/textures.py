"""The simulator's images, as PNG bytes for MuJoCo's asset table: photographs shipped inside scikit-image's
wheel (nothing is downloaded at run time), the ArUco marker, and plain colours.

``SURFACES`` are the photographs that cover walls and floors, each with the width it shows in metres, so that
the room draws them at their real scale (a brick course 75 mm high, gravel of 1-2 cm)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from .scenario import MarkerPlate

Image = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class Surface:
    photo: str  # scikit-image's name
    metres: float  # the real width the photograph shows
    turn: bool = False  # a quarter turn (the brick photograph's courses run up the image)


# brick.png: 512 px across 9.5 courses of 65 mm bricks and 10 mm joints (0.72 m); gravel.png: 512 px across about
# 35 stones of 10-20 mm (0.5 m)
SURFACES = {"brick": Surface("brick", 0.72, turn=True), "gravel": Surface("gravel", 0.5)}


@functools.cache
def surface(name: str) -> bytes:
    """A wall or floor photograph at its full resolution (512 px), turned so that it lies as it stood."""
    import skimage.data

    s = SURFACES[name]
    img = np.asarray(getattr(skimage.data, s.photo)(), dtype=np.uint8)
    if s.turn:
        img = np.ascontiguousarray(np.rot90(img))
    if img.ndim == 2:
        img = np.stack([img] * 3, axis=-1)
    return _png(np.asarray(img[..., :3], dtype=np.uint8))


@functools.cache
def photo(name: str, size: int = 256) -> bytes:
    """A scikit-image photograph (colour or grey) as a square-ish PNG no larger than ``size``."""
    import skimage.data

    img = np.asarray(getattr(skimage.data, name)())
    if img.ndim == 2:
        img = np.stack([img] * 3, axis=-1)
    rgb: Image = np.asarray(img[..., :3], dtype=np.uint8)
    h, w = rgb.shape[:2]
    scale = size / max(h, w)
    small = cv2.resize(rgb, (max(8, round(w * scale)), max(8, round(h * scale))), interpolation=cv2.INTER_AREA)
    return _png(np.asarray(small, dtype=np.uint8))


def marker(plate: MarkerPlate, cell_px: int = 16) -> bytes:
    """The marker with a white border of one quarter of its side on each side (RGB)."""
    dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, plate.dictionary))
    cells = dictionary.markerSize + 2
    img = np.asarray(cv2.aruco.generateImageMarker(dictionary, plate.marker_id, cells * cell_px))
    border = cells * cell_px // 4
    img = cv2.copyMakeBorder(img, border, border, border, border, cv2.BORDER_CONSTANT, value=235)
    img = np.where(img < 128, 20, img).astype(np.uint8)
    return _png(np.stack([img] * 3, axis=-1))


def _png(rgb: Image) -> bytes:
    ok, data = cv2.imencode(".png", np.ascontiguousarray(rgb[..., ::-1]))
    assert ok
    return bytes(data.tobytes())
