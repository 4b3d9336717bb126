"""Time between the world and the pilot: a frame shows the room as it was at its exposure, 30-120 ms before the
pilot reads it (a dropped frame: one camera period older still), and the pan/tilt servos slew at their rated
speed instead of jumping. ``History`` keeps the poses of the last few hundred milliseconds so that a frame can
be rendered from the past; ``Servos`` moves the mount.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .randomise import CAMERA_FPS, Effects

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Pose:
    """What a render needs of one moment: the airframe's position and attitude, the target's position (it may
    move) and the mount's servo angles."""

    t_ms: int
    qpos: FloatArray
    mocap: FloatArray
    pan: float
    tilt: float


class History:
    """The poses of the last ``keep_s`` seconds, one per physics step."""

    def __init__(self, keep_s: float, step_ms: int) -> None:
        self._poses: deque[Pose] = deque(maxlen=max(2, math.ceil(keep_s * 1000.0 / step_ms) + 2))

    def record(self, pose: Pose) -> None:
        self._poses.append(pose)

    def at(self, t_ms: float) -> Pose | None:
        """The newest pose at or before ``t_ms`` (the oldest kept when none is that old; None: nothing kept)."""
        if not self._poses:
            return None
        for pose in reversed(self._poses):
            if pose.t_ms <= t_ms:
                return pose
        return self._poses[0]


class FrameTiming:
    """When each frame the pilot reads was exposed: ``frame_latency_s`` before, plus one camera period for each
    dropped frame (seeded)."""

    def __init__(self, e: Effects, seed: int) -> None:
        self.latency_s = e.frame_latency_s
        self.drop = e.frame_drop
        self._rng = np.random.default_rng([seed, 0xD809])
        self.dropped = 0

    @property
    def keep_s(self) -> float:
        """How far back a frame can reach."""
        return self.latency_s + 2.0 / CAMERA_FPS

    def exposure(self, t: float) -> float:
        if self.drop > 0.0 and float(self._rng.random()) < self.drop:
            self.dropped += 1
            return t - self.latency_s - 1.0 / CAMERA_FPS
        return t - self.latency_s


class Servos:
    """The pan/tilt servos: each turns towards its commanded angle at 60 degrees per ``servo_s_per_60deg``
    (0: at once)."""

    def __init__(self, e: Effects, pan: float, tilt: float) -> None:
        self.rate = 60.0 / e.servo_s_per_60deg if e.servo_s_per_60deg > 0.0 else math.inf  # deg/s
        self.pan, self.tilt = pan, tilt

    def step(self, pan: float, tilt: float, dt: float) -> bool:
        """Move towards (pan, tilt) over ``dt`` seconds; whether the mount moved."""
        if pan == self.pan and tilt == self.tilt:
            return False
        if math.isinf(self.rate):
            self.pan, self.tilt = pan, tilt
            return True
        most = self.rate * dt
        self.pan += max(-most, min(most, pan - self.pan))
        self.tilt += max(-most, min(most, tilt - self.tilt))
        return True
