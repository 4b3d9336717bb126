"""Learning the room: ``pilot --calibrate BALL... --room EMPTY... --config pilot.yaml``.

BALL: a few frames (images, or a short video) of the user's ball held in the region of interest (by default the
central 20 %); EMPTY: a few frames of the same room without it, all at the camera's size. The HSV ranges come from
the first ball frame's region (calibrate.py); the colour model (colour_model.py) from the ball's inner disc, found
by the detector there, against the room's pixels. Its threshold keeps ``BALL_PIXELS`` of the ball's pixels (within
``THRESHOLD_MIN``..``THRESHOLD_MAX``). The calibration is refused with the figures, nothing written, when the model
takes more than ``ROOM_PIXELS`` of the room's pixels for the ball, or the detector with it confirms anything in the
room's frames or finds the ball in fewer than ``BALL_FOUND`` of its own. Otherwise the model is saved next to the
config (``<config>.colour.npz``) and the config's ``hsv.ranges`` and ``hsv.colour_model`` point at it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from ..common import config as config_mod
from ..common.config import DEFAULT_RED, HsvConfig, HsvRange, PilotConfig, VisionConfig
from ..common.errors import ConfigError
from . import colour_model as cm
from .budget import FrameBudget
from .calibrate import Roi, central_roi, hsv_ranges_from_sample
from .hsv.detector import HsvBlobDetector

VIDEO_FRAMES = 30  # frames read at most from a video (every other one)
VIDEO_SUFFIXES = (".avi", ".mp4", ".mkv", ".mov", ".webm", ".mjpg", ".mjpeg")
BALL_PIXELS = 0.95  # share of the ball's pixels the threshold keeps (light, blur and JPEG move its colours)...
THRESHOLD_MAX = 128  # ...but never above: a colour the room has as much as the ball is the ball's
THRESHOLD_MIN = 32  # nor below: a colour seven times the room's as the ball's is not the ball's
ROOM_PIXELS = 0.05  # the room's pixels the model may take for the ball: more, and the ball is not separable
SV_LOW = (DEFAULT_RED[0][0][1], DEFAULT_RED[0][0][2])  # the default ranges' lower S and V bounds
BALL_FOUND = 0.5  # share of the ball's frames where the calibrated detector must find it


@dataclass(frozen=True)
class RoomReport:
    ball_pixels: float  # share of the ball's pixels the model keeps
    room_pixels: float  # share of the room's pixels it takes for the ball
    room_detections: float  # share of the room's frames with a confirmed detection (the expected false rate)
    ball_found: float  # share of the ball's frames where it is found
    model_path: Path


def read_frames(path: str | Path, size: tuple[int, int]) -> list[MatLike]:
    """The frames of an image or a short video, each checked to be of the camera's ``size``."""
    p = Path(path)
    frames: list[MatLike] = []
    if p.suffix.lower() in VIDEO_SUFFIXES:
        cap = cv2.VideoCapture(str(p))
        k = 0
        while cap.isOpened() and len(frames) < VIDEO_FRAMES:
            ok, frame = cap.read()
            if not ok:
                break
            if k % 2 == 0:
                frames.append(frame)
            k += 1
        cap.release()
    else:
        image = cv2.imread(str(p), cv2.IMREAD_COLOR)
        if image is not None:
            frames.append(image)
    if not frames:
        raise ConfigError(f"calibration: {str(p)!r}: cannot read an image or video")
    h, w = frames[0].shape[:2]
    if (w, h) != size:
        raise ConfigError(f"calibration refused: {str(p)!r} is {w}x{h}, the camera's frames are {size[0]}x{size[1]} "
                          f"(--size): calibrate with the camera's own frames")
    return frames


def _in_ranges(hsv: MatLike, ranges: tuple[HsvRange, ...]) -> npt.NDArray[np.bool_]:
    mask = np.zeros(hsv.shape[:2], bool)
    for lo, hi in ranges:
        mask |= cv2.inRange(hsv, np.array(lo, np.uint8), np.array(hi, np.uint8)) > 0
    return mask


def ball_disc(frame: MatLike, roi: Roi | None, ranges: tuple[HsvRange, ...]) -> Roi | None:
    """The box of the ball's inner disc (0.7 of its radius: its rim blends with the room) in the region of interest:
    the best candidate there of the detector with ``ranges`` (None: none there). The region also holds some of the
    room, whose colours must not count as the ball's."""
    x, y, w, h = roi if roi is not None else central_roi(frame)
    det = HsvBlobDetector(HsvConfig(ranges=ranges))
    det.budget = FrameBudget(1000.0, lambda: 0.0)
    for c in det.candidates(frame):
        if x <= c.cx < x + w and y <= c.cy < y + h:
            r = max(1, int(0.35 * c.size))
            return int(c.cx) - r, int(c.cy) - r, 2 * r + 1, 2 * r + 1
    return None


def learn(ball: list[MatLike], room: list[MatLike], discs: list[Roi],
          ranges: tuple[HsvRange, ...]) -> tuple[cm.ColourModel, float, float]:
    """The colour model of the ball's pixels (in each frame's ``discs`` and ``ranges``) against the room's; the
    shares of the ball's and of the room's pixels it passes."""
    ball_px, room_px = [], []
    for frame, (x, y, w, h) in zip(ball, discs):
        x0, y0 = max(0, x), max(0, y)
        hsv = cv2.cvtColor(np.ascontiguousarray(frame[y0 : y + h, x0 : x + w]), cv2.COLOR_BGR2HSV)
        ball_px.append(hsv[_in_ranges(hsv, ranges)])
    for frame in room:
        room_px.append(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV).reshape(-1, 3))
    b, r = np.asarray(np.concatenate(ball_px), np.uint8), np.asarray(np.concatenate(room_px), np.uint8)
    height, width = ball[0].shape[:2]
    ratio = cm.ratio_histogram(cm.histogram(b), cm.histogram(r))
    model = cm.ColourModel(ratio, float(THRESHOLD_MIN), width, height)
    b_score = model.back_project(b.reshape(-1, 1, 3)).reshape(-1)
    r_score = model.back_project(r.reshape(-1, 1, 3)).reshape(-1)[_in_ranges(r.reshape(-1, 1, 3), ranges).reshape(-1)]
    # the threshold keeping BALL_PIXELS of the ball's pixels, within THRESHOLD_MIN..THRESHOLD_MAX
    keep = float(np.quantile(b_score, 1.0 - BALL_PIXELS)) if len(b_score) else float(THRESHOLD_MAX)
    threshold = min(float(THRESHOLD_MAX), max(float(THRESHOLD_MIN), keep))
    model = dataclasses.replace(model, threshold=threshold)
    ball_share = float(np.count_nonzero(b_score >= threshold)) / max(1, len(b_score))
    room_share = float(np.count_nonzero(r_score >= threshold)) / max(1, len(r))
    return model, ball_share, room_share


def model_path(config_path: str | Path) -> Path:
    p = Path(config_path)
    return p.with_name(p.stem + ".colour.npz")


def learn_room(ball_paths: list[str], room_paths: list[str], config_path: str | Path, roi: Roi | None,
               size: tuple[int, int], acquire: float = 0.6) -> RoomReport:
    """Learn, check and save the room's colour model; a ConfigError with the figures when it is refused."""
    named = [(f, p) for p in ball_paths for f in read_frames(p, size)]
    ball = [f for f, _ in named]
    room = [f for p in room_paths for f in read_frames(p, size)]
    # the hues of the first frame's region of interest (the room there too: the model tells the ball apart), its
    # saturation and value bounds no stricter than the defaults' (one frame's lighting is not the flight's)
    ranges = tuple(((lo[0], min(lo[1], SV_LOW[0]), min(lo[2], SV_LOW[1])), hi)
                   for lo, hi in hsv_ranges_from_sample(ball[0], roi))
    discs = [ball_disc(f, roi, ranges) for f in ball]
    if sum(d is not None for d in discs) < BALL_FOUND * len(ball):
        missed = [p for (_, p), d in zip(named, discs) if d is None]
        raise ConfigError(f"calibration refused: no ball of the colour {ranges} in the region of interest of "
                          f"{len(missed)} of the {len(ball)} ball frames ({', '.join(missed[:3])}): hold it in the "
                          f"middle of the view, or give --roi; nothing written")
    kept = [(f, d) for f, d in zip(ball, discs) if d is not None]
    model, ball_share, room_share = learn([f for f, _ in kept], room, [d for _, d in kept], ranges)
    out = model_path(config_path)
    if room_share > ROOM_PIXELS:
        raise ConfigError(f"calibration refused: the ball is not separable from this room: a model keeping "
                          f"{ball_share:.0%} of the ball's pixels takes {room_share:.2%} of the room's for it (at most "
                          f"{ROOM_PIXELS:.0%} allowed); nothing written")
    cm.save(model, out)
    try:
        hsv = HsvConfig(ranges=ranges, colour_model=str(out.resolve()))
        det = HsvBlobDetector(hsv, VisionConfig(budget_ms=1000.0))
        det.budget = FrameBudget(1000.0, lambda: 0.0)  # judged on what it sees, not on this machine's load
        false = sum(any(c.score >= acquire for c in det.candidates(f)) for f in room) / len(room)
        found = sum(any(c.score >= acquire for c in det.candidates(f)) for f in ball) / len(ball)
        if false > 0.0 or found < BALL_FOUND:
            raise ConfigError(f"calibration refused: with the model the detector confirms something in {false:.0%} "
                              f"of the room's {len(room)} frames without the ball (0 allowed) and finds the ball in "
                              f"{found:.0%} of its {len(ball)} frames (at least {BALL_FOUND:.0%} needed); "
                              f"nothing written")
        path = Path(config_path)
        base = config_mod.load(path) if path.exists() else PilotConfig()
        updated = dataclasses.replace(base, hsv=dataclasses.replace(base.hsv, ranges=ranges,
                                                                    colour_model=str(out.resolve())))
        config_mod.validate(updated, str(path))
        config_mod.save(updated, path)
    except BaseException:
        out.unlink(missing_ok=True)
        raise
    return RoomReport(ball_share, room_share, false, found, out)


def room_summary(report: RoomReport) -> str:
    """The one line ``pilot --calibrate --room`` prints."""
    return (f"pilot: saved the room's colour model to {report.model_path}: it keeps {report.ball_pixels:.0%} of the "
            f"ball's pixels and takes {report.room_pixels:.2%} of the room's; expected false detections "
            f"{report.room_detections:.1%} of the room's frames; the ball found in {report.ball_found:.0%} of its own")
