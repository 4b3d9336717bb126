"""The target's colour for the colour-ball detector (detector.py): the configured HSV ranges as the fewest
``inRange`` calls, a V bound that follows the frame's exposure, and the masks made with them.

Red wraps around hue 0, which would need two ranges; converting the BGR frame as if it were RGB mirrors the hue
circle (h -> 120 - h, in OpenCV's 0..179 units) and puts red at 120, in one piece. The value (V) bound follows the
frame's exposure: in a frame whose brightest pixels are dim, it drops in proportion (never below ``V_FLOOR``), so
that a ball's shaded side stays in the mask. ``Grown`` bounds (the detector's second look) also take the pixels of
the target's hue and saturation down to ``V_FLOOR`` that touch the mask.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from ...common.config import HsvConfig
from ...common.errors import ConfigError
from ..colour_model import ColourModel, load
from .noise import SMOOTH_SIGMA, noisy

V_REFERENCE = 200  # brightness (see exposure) of a well-exposed frame; the V bound scales below it
V_FLOOR = 24  # the V bound never drops below this: under it hue and saturation are noise
GRIDS_KEPT = 8  # exposure grids' indices kept (a frame, its half-size search, a window or two)

Bounds = list[tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]]  # inRange's lower and upper HSV triples


def _contiguous(hues: set[int]) -> tuple[int, int] | None:
    lo, hi = min(hues), max(hues)
    return (lo, hi) if hi - lo + 1 == len(hues) else None


def darker(bounds: Bounds, gain: float) -> Bounds:
    """The bounds with their V bound scaled by ``gain`` (never below ``V_FLOOR``, nor raised by it)."""
    out = []
    for lo, hi in bounds:
        adapted = lo.copy()
        adapted[2] = max(min(int(lo[2]), V_FLOOR), round(int(lo[2]) * gain))
        out.append((adapted, hi))
    return out


def _in_range(hsv: MatLike, bounds: Bounds, dst: MatLike | None = None) -> MatLike:
    mask = cv2.inRange(hsv, bounds[0][0], bounds[0][1], dst=dst)
    for lo, hi in bounds[1:]:
        mask = cv2.bitwise_or(mask, cv2.inRange(hsv, lo, hi))
    return mask


class Grown(list[tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]]):
    """Bounds whose mask grows, as Canny's two thresholds do: the pixels of the target's hue and saturation with V
    down to ``V_FLOOR`` join it where they touch it. A ball's shaded side joins its lit side; a dark surface of
    its colour stays out unless something over the bound lies on it. One lower V bound for every pixel, as a look
    once had, joined dark red-brown surfaces to the balls on the tuning photos of bench/vision."""

    def mask(self, hsv: MatLike) -> MatLike:
        core = _in_range(hsv, self)
        if not cv2.countNonZero(core):  # nothing for a dark piece to join (an empty view's usual case)
            return core
        n, labels = cv2.connectedComponents(_in_range(hsv, darker(self, 0.0)), connectivity=8)
        keep = np.zeros(n, np.uint8)
        keep[labels[np.asarray(core) > 0]] = 255  # the dark pieces holding a pixel of the core
        keep[0] = 0
        return np.take(keep, np.asarray(labels))


def grown(bounds: Bounds, gain: float) -> Grown | None:
    """``bounds`` ``gain`` times as dark (see ``darker``), grown; None if they are at ``V_FLOOR`` already (the mask
    would be theirs)."""
    if all(int(lo[2]) <= V_FLOOR for lo, _ in bounds):
        return None
    return Grown(darker(bounds, gain))


class ColourMask:
    def __init__(self, cfg: HsvConfig) -> None:
        if not cfg.ranges:
            raise ConfigError("hsv.ranges: at least one range is needed")
        hues = {h for lo, hi in cfg.ranges for h in range(lo[0], hi[0] + 1)}
        sv = {(lo[1:], hi[1:]) for lo, hi in cfg.ranges}
        mirrored = {(120 - h) % 180 for h in hues}
        self.code = cv2.COLOR_BGR2HSV  # the conversion every mask uses
        ranges = [(np.array(lo, np.uint8), np.array(hi, np.uint8)) for lo, hi in cfg.ranges]
        span = _contiguous(hues)
        if span is None and _contiguous(mirrored) is not None:
            span, self.code = _contiguous(mirrored), cv2.COLOR_RGB2HSV
            # each range mirrored too (a range holding hue 120 is not in one piece mirrored: the union then is not)
            ranges = [(np.array(((120 - hi[0]) % 180, *lo[1:]), np.uint8),
                       np.array(((120 - lo[0]) % 180, *hi[1:]), np.uint8)) for lo, hi in cfg.ranges]
        if span is not None and len(sv) == 1:
            ((s_lo, v_lo), (s_hi, v_hi)), = sv
            ranges = [(np.array((span[0], s_lo, v_lo), np.uint8), np.array((span[1], s_hi, v_hi), np.uint8))]
        self.ranges = ranges
        # the room's colour model (checked here, at start): of the ranges' mask, only the colours it gives the ball
        self.model: ColourModel | None = None
        if cfg.colour_model:
            model = load(cfg.colour_model)
            self.model = model.mirrored() if self.code == cv2.COLOR_RGB2HSV else model
        # colour purity refers to the hue range's middle and half-width (in the space the mask uses)
        used = hues if self.code == cv2.COLOR_BGR2HSV else mirrored
        self.hue_mid = (min(used) + max(used)) / 2.0
        self.hue_half = max(1.0, (max(used) - min(used)) / 2.0)
        self.sat_lo = float(min(lo[1] for lo, _ in cfg.ranges))
        k = max(1, cfg.open_kernel)
        self.kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (k, k)) if k > 1 else None
        self._grid_index: dict[tuple[int, ...], npt.NDArray[np.intp]] = {}  # the exposure grid's, by frame shape

    def hue_off(self, hue: float) -> float:
        """How far a mean hue sits from the range's middle, in half-widths (the score's colour purity)."""
        return abs(hue - self.hue_mid) / self.hue_half

    @property
    def single_range(self) -> bool:
        """True when the mask costs one cvtColor and one inRange (contiguous hues, shared S/V bounds)."""
        return len(self.ranges) == 1

    def bounds_for(self, image: MatLike) -> Bounds:
        """The ranges with the V bound for this frame's exposure: a high order statistic of every channel on a
        sparse grid (a few µs)."""
        grid = self._grid(image)
        k = max(1, grid.size // 50)  # the 98th percentile, without a sort
        if np.count_nonzero(grid >= V_REFERENCE) >= k:  # at least the reference: the configured bound (most frames)
            return self.ranges
        grid.partition(grid.size - k)  # in place: the grid is a copy
        return darker(self.ranges, float(grid[grid.size - k]) / V_REFERENCE)

    def _grid(self, image: MatLike) -> npt.NDArray[np.uint8]:
        """Every channel of the pixels on a grid of about 24x18 at any frame size, one flat array. Taken by flat
        index (made once a frame size): comparing a strided view, three bytes at a time, cost 16 µs in a frame."""
        shape = tuple(image.shape)
        index = self._grid_index.get(shape)
        if index is None:
            if len(self._grid_index) >= GRIDS_KEPT:  # frame sizes changing: keep the newest only
                self._grid_index.clear()
            h, w = shape[:2]
            c = shape[2] if len(shape) > 2 else 1
            step = max(4, w // 24)
            rows, cols = np.arange(0, h, step), np.arange(0, w, step)
            index = ((rows[:, None, None] * w + cols[None, :, None]) * c + np.arange(c)[None, None, :]).reshape(-1)
            self._grid_index[shape] = index
        return np.asarray(image, np.uint8).reshape(-1).take(index)

    def raw(self, image: MatLike, bounds: Bounds) -> MatLike:
        return self.in_range(cv2.cvtColor(image, self.code), bounds)

    def in_range(self, hsv: MatLike, bounds: Bounds, dst: MatLike | None = None) -> MatLike:
        """The mask of ``bounds`` (written into ``dst`` where it can be: not a grown one), and of the room's
        colour model if there is one."""
        mask = bounds.mask(hsv) if isinstance(bounds, Grown) else _in_range(hsv, bounds, dst)
        return mask if self.model is None else cv2.bitwise_and(mask, self.model.mask(hsv), dst=mask)

    def clean(self, mask: MatLike) -> MatLike:
        if self.kernel is None:
            return mask
        # opening: speckle goes; closing: a noisy target's pinholes and ragged rim are mended
        return cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, self.kernel), cv2.MORPH_CLOSE, self.kernel)

    def mask(self, image: MatLike) -> MatLike:
        """The full-resolution mask (with the exposure-adapted V bound), as the refinement sees it."""
        return self.clean(self.raw(image, self.bounds_for(image)))

    def centre_holds(self, image: MatLike, r: int, gain: float, share: float) -> bool:
        """Whether at least ``share`` of the (2 r + 1)-pixel square at the frame's centre is of the target's colour
        (with the frame's V bound ``gain`` times as high). Noise pushes a dark ball's pixels out of its colour: a
        noisy frame's square (noise.py) that falls short is read smoothed too."""
        if self._centre_share(image, r, gain, 0.0) >= share:
            return True
        return noisy(image) and self._centre_share(image, r, gain, SMOOTH_SIGMA) >= share

    def _centre_share(self, image: MatLike, r: int, gain: float, smooth: float) -> float:
        """The share of that square of the target's colour, read after a Gaussian of ``smooth`` px if not 0."""
        h, w = image.shape[:2]
        m = min(math.ceil(3.0 * smooth), h // 2 - r, w // 2 - r)  # the Gaussian's reach, within the frame
        roi = image[h // 2 - r - m: h // 2 + r + m + 1, w // 2 - r - m: w // 2 + r + m + 1]
        if smooth > 0.0:
            roi = cv2.GaussianBlur(roi, (0, 0), smooth)
        roi = roi[m: roi.shape[0] - m, m: roi.shape[1] - m]
        mask = self.raw(roi, darker(self.bounds_for(image), gain))  # a view: OpenCV reads its rows in place
        return cv2.countNonZero(mask) / mask.size
