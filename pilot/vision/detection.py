"""What the detectors say: a typed frame status, scored candidates, and one Detection per frame."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from cv2.typing import MatLike


class FrameStatus(enum.Enum):
    """Why a frame was (not) looked at. Anything but OK means: no detection, hold or land."""

    OK = "ok"
    WRONG_TYPE = "wrong type"  # not an 8-bit image array
    WRONG_SHAPE = "wrong shape"  # not 3 channels, too small, or not the size the camera started with
    BLACK = "black"
    SATURATED = "saturated"
    FROZEN = "frozen"  # the same pixels frame after frame: the camera has stopped


MIN_WIDTH, MIN_HEIGHT = 32, 24  # a smaller frame has too few pixels to show any target's shape


def colour_image(image: object) -> bool:
    """Whether ``image`` is an 8-bit, 3-channel (BGR) image, of any size."""
    return isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3


def malformed(image: object) -> FrameStatus | None:
    """WRONG_TYPE or WRONG_SHAPE when ``image`` is no frame a detector can look at (an 8-bit, 3-channel image at
    least MIN_WIDTH x MIN_HEIGHT), else None."""
    if not isinstance(image, np.ndarray) or image.dtype != np.uint8:
        return FrameStatus.WRONG_TYPE
    if not colour_image(image) or image.shape[1] < MIN_WIDTH or image.shape[0] < MIN_HEIGHT:
        return FrameStatus.WRONG_SHAPE
    return None


@dataclass(frozen=True)
class Candidate:
    """One possible target in one frame, scored 0..1 on that frame alone."""

    cx: float
    cy: float
    size: float  # apparent diameter (a ball) or mean side (a marker), pixels
    score: float


@dataclass(frozen=True)
class Detection:
    found: bool
    cx: float = 0.0  # centre, pixels
    cy: float = 0.0
    size: float = 0.0  # apparent size, pixels (the ball's diameter, a marker's mean side)
    confidence: float = 0.0  # 0..1
    width: int = 0  # frame size the numbers refer to
    height: int = 0
    range_m: float = 0.0  # estimated from the apparent size and the target's known size (0: unknown)
    status: FrameStatus = FrameStatus.OK
    predicted: bool = False  # bridged by the tracker through a missed frame, not measured in this one
    aim_on_target: bool | None = None  # the laser's aim point shows the target itself (None: not measured)
    cut_short: bool = False  # the frame's time budget ran out: the best candidate found before it

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


class CandidateSource(Protocol):
    """A single-frame detector: every candidate in the frame, best first; none in a frame ``malformed`` names (not
    an OpenCV error)."""

    name: str

    @property
    def cut_short(self) -> bool:
        """Whether the last ``candidates`` stopped at the frame's time budget (``vision.budget_ms``)."""
        ...

    def candidates(self, image: MatLike) -> list[Candidate]: ...

    def aim_on_target(self, image: MatLike, size: float) -> bool | None:
        """Whether the frame's centre shows the target's own surface (None: this detector cannot tell)."""
        ...

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        """A closer look where a tracked target of ``size`` px is expected and the frame's look found nothing:
        the candidates there, best first (none: this detector has no closer look)."""
        ...


def focal_px(width: int, horizontal_fov_deg: float) -> float:
    return (width / 2.0) / math.tan(math.radians(horizontal_fov_deg) / 2.0)


def range_of(size_px: float, object_m: float, width: int, horizontal_fov_deg: float) -> float:
    """Pinhole range of an object of known size seen ``size_px`` wide."""
    return object_m * focal_px(width, horizontal_fov_deg) / size_px if size_px > 0 else math.inf


def frame_size(image: MatLike) -> tuple[int, int]:
    h, w = image.shape[:2]
    return int(w), int(h)


def reported_size(image: object) -> tuple[int, int]:
    """Width and height of whatever was passed as a frame (0, 0 without two dimensions): what a Detection
    reports, malformed frames included."""
    shape: tuple[int, ...] = tuple(getattr(image, "shape", ()))
    return (int(shape[1]), int(shape[0])) if len(shape) >= 2 else (0, 0)


def best_detection(source: CandidateSource, image: MatLike, object_m: float, horizontal_fov_deg: float) -> Detection:
    """This frame alone, the source's best candidate (no tracking, none of the black, saturated or frozen frame
    checks: see ``pilot.vision.detect.make_detector``), with its pinhole range for an object ``object_m``
    across. A frame that is not an 8-bit 3-channel image of a usable size gets its status, not an OpenCV error."""
    w, h = reported_size(image)
    if (status := malformed(image)) is not None:
        return Detection(False, width=w, height=h, status=status)
    cands = source.candidates(image)
    if not cands:
        return Detection(False, width=w, height=h)
    best = cands[0]
    distance = range_of(best.size, object_m, w, horizontal_fov_deg)
    return Detection(True, best.cx, best.cy, best.size, best.score, w, h, range_m=distance)
