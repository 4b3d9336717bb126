"""The heights the target was seen from: a target hidden from above (a panel, a shelf's edge) is approached from
below, and the other way round.

The pilot has no altimeter. In AltHold the throttle stick sets a climb rate, so ``Height`` integrates the pilot's
own throttle commands (``climb_mps_per_step`` a control step, reached with a lag): an estimate that drifts over a
flight but holds over the few seconds between a sighting and its loss, which is all ``SeenFrom`` compares.

``SeenFrom`` remembers the height of the last measured sighting. A target lost after the drone climbed above that
height sets a ceiling just below it (a floor, after a descent): the search starts back at the height it was seen
from, and TRACK approaches without crossing the limit, the target off the frame's centre (AIM centres it with the
tilt servo). ``APPROACH_FLOOR_M`` is such a floor always: a low target is approached from above the furniture
beside it. A target that leaves the middle of the frame is followed across a limit all the same.
"""

from __future__ import annotations

import math

MARGIN_M = 0.1  # a limit this far inside the height last seen from
MOVED_M = 0.03  # lost this far from the height last seen from: the climb (or descent) hid it
MIN_LIMIT_M = 0.4  # no ceiling this low (seen from the ground, lost on take-off: no reason to fly that low)
KEEP_IN_VIEW = 0.5  # a limit holds only while the target's vertical error is within this (of half the frame)
# TRACK descends no lower than this towards a low target (AIM tilts the camera down to it): below about 0.5 m the
# props' wash reads on the barometer AltHold holds (ArduCopter's baro ground effect, the EKF's EK3_GND_EFF_DZ), and
# the furniture a low target stands among is as tall as it (a coffee table, a seat: 0.4-0.5 m)
APPROACH_FLOOR_M = 0.6


class Height:
    """The height climbed since take-off, in metres, from the throttle commands (up positive)."""

    def __init__(self, climb_mps_per_step: float, lag_s: float = 0.2) -> None:
        self.climb_mps_per_step = climb_mps_per_step
        self.lag_s = lag_s
        self.m = 0.0
        self.rate = 0.0  # m/s

    def advance(self, throttle_steps: float, dt: float) -> None:
        """``throttle_steps``: the throttle stick held during ``dt``, in control steps (up positive)."""
        if dt <= 0.0:
            return
        target = self.climb_mps_per_step * throttle_steps
        decayed = 1.0 - math.exp(-dt / self.lag_s)
        self.m += target * dt + (self.rate - target) * self.lag_s * decayed  # the lag's exact integral
        self.rate += (target - self.rate) * decayed

    @property
    def settles_m(self) -> float:
        """Where the height settles if the stick is released now."""
        return self.m + self.rate * self.lag_s


class SeenFrom:
    def __init__(self) -> None:
        self.seen_m: float | None = None  # the height of the last measured sighting
        self.ceiling_m: float | None = None
        self.floor_m: float | None = None

    def saw(self, height_m: float) -> None:
        self.seen_m = height_m

    def lost(self, height_m: float) -> None:
        """The target is lost (or a search begins): a climb or descent since the last sighting sets a limit."""
        if self.seen_m is None:
            return
        if height_m > self.seen_m + MOVED_M and self.seen_m - MARGIN_M >= MIN_LIMIT_M:
            self.ceiling_m = self.seen_m - MARGIN_M
            if self.floor_m is not None and self.floor_m > self.ceiling_m:
                self.floor_m = None  # the newer evidence wins
        elif height_m < self.seen_m - MOVED_M:
            self.floor_m = self.seen_m + MARGIN_M
            if self.ceiling_m is not None and self.ceiling_m < self.floor_m:
                self.ceiling_m = None

    def return_to(self) -> float | None:
        """The height to search from first: where it was last seen, inside the limits; None if never seen."""
        if self.seen_m is None:
            return None
        h = self.seen_m
        if self.ceiling_m is not None:
            h = min(h, self.ceiling_m)
        if self.floor_m is not None:
            h = max(h, self.floor_m)
        return h

    def barred(self, up: bool, height_m: float, error_y: float) -> bool:
        """Whether a height correction this way would cross a limit, with the target still near the middle."""
        if abs(error_y) > KEEP_IN_VIEW:
            return False
        if up:
            return self.ceiling_m is not None and height_m >= self.ceiling_m
        return height_m <= APPROACH_FLOOR_M or (self.floor_m is not None and height_m <= self.floor_m)
