"""The simulator's images, as PNG bytes for MuJoCo's asset table: photographs shipped inside scikit-image's
wheel (nothing is downloaded at run time), the ArUco marker, and plain colours."""

from __future__ import annotations

import functools

import cv2
import numpy as np
import numpy.typing as npt

from .scenario import MarkerPlate

Image = npt.NDArray[np.uint8]


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
