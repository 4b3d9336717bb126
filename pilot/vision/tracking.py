"""One target track: a constant-velocity Kalman filter on the image position, a smoothed apparent size.

Each frame the track predicts where the target will be; among the frame's candidates it takes the best
one that lies within ``max_jump`` (a share of the frame width, plus the target's own size) of the
prediction and has a size within a factor of ``SIZE_RATIO`` of the tracked one. A candidate elsewhere is a
jump: while the track lives it is ignored, whatever its score (a second red thing does not steal the
lock). With no candidate in reach the track reports its prediction, marked ``predicted``, with a
confidence that decays per missed frame, for up to ``bridge_frames`` frames; then it is dropped and the
best candidate of a later frame starts a new one.

OpenCV's own trackers (KCF, CSRT) are not in opencv-python-headless; this filter is 4 states and costs
microseconds. The reported position is the measurement itself: the filter serves association and the
bridging of lost frames, and a filtered position would lag a turning drone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..common.config import VisionConfig
from .detection import Candidate

SIZE_RATIO = 1.6  # per frame; a target 1.6x nearer in 50 ms would be closing at tens of m/s
BRIDGE_DECAY = 0.8  # confidence kept per bridged frame
MEASUREMENT_PX = 1.5  # position noise of a measurement, pixels (one sigma)
ACCELERATION = 0.02  # process noise: velocity change per frame, as a share of the frame width

F = np.array([[1.0, 0, 1, 0], [0, 1, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]])
H = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0]])
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class TrackOutput:
    candidate: Candidate
    predicted: bool


class Tracker:
    def __init__(self, vision: VisionConfig | None = None) -> None:
        self.cfg = vision or VisionConfig()
        self._x: FloatArray | None = None  # state: x, y, vx, vy (pixels, per frame)
        self._p: FloatArray = np.eye(4)
        self.size = 0.0
        self.score = 0.0
        self.misses = 0
        self.age = 0  # frames since the track started

    @property
    def active(self) -> bool:
        return self._x is not None

    def reset(self) -> None:
        self._x = None
        self.misses = self.age = 0

    def _start(self, c: Candidate) -> None:
        self._x = np.array([c.cx, c.cy, 0.0, 0.0])
        self._p = np.diag([MEASUREMENT_PX**2, MEASUREMENT_PX**2, 100.0, 100.0])
        self.size, self.score, self.misses, self.age = c.size, c.score, 0, 0

    def _correct(self, c: Candidate) -> None:
        assert self._x is not None
        r = np.eye(2) * MEASUREMENT_PX**2
        s = H @ self._p @ H.T + r
        k = self._p @ H.T @ np.linalg.inv(s)
        self._x = self._x + k @ (np.array([c.cx, c.cy]) - H @ self._x)
        self._p = (np.eye(4) - k @ H) @ self._p
        self.size = 0.5 * self.size + 0.5 * c.size
        self.score, self.misses = c.score, 0

    def expected(self) -> tuple[float, float, float] | None:
        """Where (x, y) and how large the next frame should show the target, if a track lives."""
        if self._x is None:
            return None
        x = F @ self._x
        return float(x[0]), float(x[1]), self.size

    def takes(self, candidates: list[Candidate], width: int) -> bool:
        """Whether the next ``update`` would find the target among ``candidates`` (a track lives)."""
        expected = self.expected()
        return expected is not None and self._match(candidates, expected[0], expected[1], width) is not None

    def _match(self, candidates: list[Candidate], px: float, py: float, width: int) -> Candidate | None:
        """The best candidate within reach of (px, py) with a size consistent with the track's."""
        reach = self.cfg.max_jump * width + self.size
        for c in candidates:  # best first
            near = (c.cx - px) ** 2 + (c.cy - py) ** 2 <= reach * reach
            if near and 1.0 / SIZE_RATIO <= c.size / self.size <= SIZE_RATIO:
                return c
        return None

    def update(self, candidates: list[Candidate], width: int) -> TrackOutput | None:
        """One frame: the candidates (best first) -> the target's candidate, measured or predicted, or None."""
        if self._x is None:
            if not candidates:
                return None
            self._start(candidates[0])
            return TrackOutput(candidates[0], False)
        q = (ACCELERATION * width) ** 2
        self._x = F @ self._x
        self._p = F @ self._p @ F.T + np.diag([q / 4, q / 4, q, q])
        self.age += 1
        px, py = float(self._x[0]), float(self._x[1])
        c = self._match(candidates, px, py, width)
        if c is not None:
            self._correct(c)
            return TrackOutput(c, False)
        self.misses += 1
        if self.misses <= self.cfg.bridge_frames:
            return TrackOutput(Candidate(px, py, self.size, self.score * BRIDGE_DECAY**self.misses), True)
        self.reset()
        if candidates:  # the old target is gone: the best of this frame starts afresh
            self._start(candidates[0])
            return TrackOutput(candidates[0], False)
        return None
