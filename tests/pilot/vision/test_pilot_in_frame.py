"""No detection is ever reported outside the frame: a target bridged by the tracker past the frame's edge is lost."""

from __future__ import annotations

import numpy as np

from pilot.common.config import VisionConfig
from pilot.vision.detect import TrackedDetector
from pilot.vision.detection import Candidate


class Scripted:
    """A candidate source that returns the next frame's scripted candidates."""

    name = "scripted"
    cut_short = False

    def __init__(self, frames: list[list[Candidate]]) -> None:
        self.frames = frames

    def candidates(self, image: object) -> list[Candidate]:
        return self.frames.pop(0)

    def aim_on_target(self, image: object, size: float) -> bool | None:
        return None

    def candidates_near(self, image: object, cx: float, cy: float, size: float) -> list[Candidate]:
        return []


def test_a_target_bridged_past_the_left_edge_is_lost_not_reported_outside() -> None:
    # a marker moving left 20 px a frame, then no longer seen: the prediction runs on past x = 0
    seen = [[Candidate(x, 120.0, 30.0, 1.0)] for x in (100.0, 80.0, 60.0, 40.0, 20.0, 5.0)]
    det = TrackedDetector(Scripted([*seen, [], [], []]), 0.3, 60.0, VisionConfig(bridge_frames=3))
    rng = np.random.default_rng(0)
    out = [det.detect(rng.integers(30, 220, (240, 320, 3), np.uint8)) for _ in range(9)]
    assert all(d.found for d in out[:6])
    assert all(0.0 <= d.cx < d.width and 0.0 <= d.cy < d.height for d in out if d.found)
    assert not out[-1].found and not det.tracker.active  # gone past the edge: the track is dropped


def test_a_target_bridged_inside_the_frame_is_still_reported() -> None:
    seen = [[Candidate(160.0, 120.0, 30.0, 1.0)] for _ in range(4)]
    det = TrackedDetector(Scripted([*seen, []]), 0.3, 60.0, VisionConfig(bridge_frames=3))
    rng = np.random.default_rng(1)
    out = [det.detect(rng.integers(30, 220, (240, 320, 3), np.uint8)) for _ in range(5)]
    assert out[-1].found and out[-1].predicted
