"""The closing speed on the target, from the ranges the detector estimates (apparent size against known size).

The flight controller holds altitude but not position: a drone that stops commanding forward coasts on. The
pilot has no other velocity sensor, so it fits a line to the last ``window_s`` of range estimates: 0.4 s, a compromise
between the slope's noise (about 0.35 m/s for a 25 px target at 3 m at 20 Hz, a quarter of it at 1.5 m) and
its lag (0.2 s, which makes a brake overshoot).
"""

from __future__ import annotations

import math
from collections import deque


class ClosingSpeed:
    def __init__(self, window_s: float = 0.4, min_samples: int = 4) -> None:
        self.window_s = window_s
        self.min_samples = min_samples
        self._samples: deque[tuple[float, float]] = deque()

    def reset(self) -> None:
        self._samples.clear()

    def update(self, t: float, range_m: float) -> None:
        if range_m <= 0.0 or not math.isfinite(range_m):
            return
        self._samples.append((t, range_m))
        while self._samples and t - self._samples[0][0] > self.window_s:
            self._samples.popleft()

    @property
    def closing(self) -> float | None:
        """m/s towards the target (negative: receding); None until enough samples."""
        n = len(self._samples)
        if n < self.min_samples:
            return None
        mt = sum(t for t, _ in self._samples) / n
        mr = sum(r for _, r in self._samples) / n
        var = sum((t - mt) ** 2 for t, _ in self._samples)
        if var <= 0.0:
            return None
        slope = sum((t - mt) * (r - mr) for t, r in self._samples) / var
        return -slope


def allowed_speed(remaining_m: float, brake_mps2: float, top_mps: float) -> float:
    """The closing speed from which the drone can still stop within ``remaining_m``."""
    return min(top_mps, math.sqrt(2.0 * brake_mps2 * max(0.0, remaining_m)))
