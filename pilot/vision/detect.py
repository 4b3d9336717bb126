"""The pilot's vision: ``make_detector(config).detect(image) -> Detection``, one call per frame.

The pipeline (each part in its own module):

1. ``pilot.vision.frames``: a malformed, black, saturated or frozen frame is named in ``Detection.status`` and
   goes no further.
2. A single-frame detector lists scored candidates: ``pilot.vision.hsv.detector`` (a coloured ball; its first few
   candidates then pass ``pilot.vision.verify``'s learned veto) or ``pilot.vision.aruco`` (a marker).
3. ``pilot.vision.tracking``: one track picks the candidate consistent with the last frames, rejects jumps and
   bridges a few missed frames. A target the pilot acts on that the frame's look misses first gets a closer
   look where the track expects it (``candidates_near``).
4. The controller's ``pilot.vision.gating.Gate`` turns confidences into "act on it" and "the laser may fire".
"""

from __future__ import annotations

from collections.abc import Callable

from cv2.typing import MatLike

from ..common.config import PilotConfig, VisionConfig
from ..common.errors import ConfigError
from .aruco import ArucoMarkerDetector, aruco_dictionary
from .ball import SimpleBallDetector
from .detection import CandidateSource, Detection, Detector, FrameStatus, range_of, reported_size
from .frames import FrameCheck
from .hsv.detector import HsvBlobDetector
from .tracking import Tracker
from .verify import VerifiedSource, shipped

__all__ = [
    "ArucoMarkerDetector", "Detection", "Detector", "FrameStatus", "HsvBlobDetector", "TrackedDetector",
    "aruco_dictionary", "make_detector",
]


class TrackedDetector:
    """Frame checks, a single-frame detector and the tracker, behind ``detect(image) -> Detection``."""

    def __init__(
        self, source: CandidateSource, object_m: float, fov_deg: float, vision: VisionConfig | None = None,
        look_again_from: float = 0.6,
    ) -> None:
        """``look_again_from``: the tracked score from which a lost target gets a closer look (the controller's
        ``acquire_confidence``)."""
        self.source = source
        self.name = source.name
        self.object_m = object_m
        self.fov_deg = fov_deg
        cfg = vision or VisionConfig()
        self.frames = FrameCheck(cfg.frozen_frames)
        self.tracker = Tracker(cfg)
        self.look_again_from = look_again_from

    def detect(self, image: MatLike) -> Detection:
        status = self.frames.check(image)
        w, h = reported_size(image)
        if status is not FrameStatus.OK:
            self.tracker.reset()  # nothing seen through a bad frame carries over
            return Detection(False, width=w, height=h, status=status)
        candidates = self.source.candidates(image)
        # a target the pilot acts on, not in this frame's look: a closer look where it should be (a ball darkening
        # as a bright window fills more of the frame drops under the frame's V bound); ``takes`` is False without
        # a track, so the prediction is asked again only when the look is needed
        if self.tracker.score >= self.look_again_from and not self.tracker.takes(candidates, w) and (
                expected := self.tracker.expected()) is not None:
            candidates = candidates + self.source.candidates_near(image, *expected)
        out = self.tracker.update(candidates, w)
        cut = self.source.cut_short
        if out is None:
            return Detection(False, width=w, height=h, cut_short=cut)
        c = out.candidate
        if not (0.0 <= c.cx < w and 0.0 <= c.cy < h):  # a bridged target gone past the frame's edge: lost, not
            self.tracker.reset()  # reported where no pixel shows it (a marker was logged at cx -61)
            return Detection(False, width=w, height=h, cut_short=cut)
        distance = range_of(c.size, self.object_m, w, self.fov_deg)
        aim = None if out.predicted else self.source.aim_on_target(image, c.size)
        return Detection(True, c.cx, c.cy, c.size, c.score, w, h, range_m=distance, predicted=out.predicted,
                         aim_on_target=aim, cut_short=cut)


def make_detector(config: PilotConfig, clock: Callable[[], float] | None = None, verified: bool = True
                  ) -> TrackedDetector:
    """``clock``: seconds, for the frame's budget (default ``pilot.vision.budget.CLOCK``, the thread's CPU time);
    ``verified``: the colour-ball detector's candidates pass the learned verifier (``pilot.vision.verify``; False:
    the rules alone, as the bench compares)."""
    fov = config.controller.horizontal_fov_deg
    source: CandidateSource
    if config.detector == "hsv":
        ball = SimpleBallDetector if config.hsv.simple else HsvBlobDetector
        source, size = ball(config.hsv, config.vision, fov, clock), config.hsv.target_diameter_m
        if verified and not config.hsv.simple:
            source = VerifiedSource(source, shipped())
    elif config.detector == "aruco":
        source, size = ArucoMarkerDetector(config.aruco, config.vision, fov, clock), config.aruco.marker_size_m
    else:
        raise ConfigError(f"option 'detector' must be 'hsv' or 'aruco', got {config.detector!r}")
    return TrackedDetector(source, size, fov, config.vision, config.controller.acquire_confidence)
