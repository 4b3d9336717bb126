"""LAND's first part: the pilot's own descent to near the floor, before the firmware's landing routine.

The routine (``il0000``) descends at the throttle's low speed (about 0.46 m/s) with roll and pitch centred, 3 s
from a room's firing height: a level-trim drift of up to 0.5 m/s (``trim.py``) carried the drone a metre or more
sideways on the way down, into walls and furniture. So the pilot descends itself first, at ``DESCENT_STEPS``
control steps (twice the routine's speed, half the time to drift), down to ``LAND_FROM_M`` by its height estimate
(``vertical.Height``); the routine lands the rest. Only a mission's own landing descends (not a stop, an
emergency, or a drone no longer flying under the pilot's sticks).
"""

from __future__ import annotations

import drone_protocol as dp

LAND_FROM_M = 0.3  # the routine takes over at this height (the pilot's estimate)
DESCENT_STEPS = 2.0  # the descent's throttle, control steps below the median
DESCENT_MARGIN = 1.5  # the descent ends after this times the time its estimate needs, whatever the estimate says
FLYING_STATES = frozenset({dp.DroneState.HOLD_ALTITUDE, dp.DroneState.MOVING})  # airborne under the pilot's sticks


class Descent:
    def __init__(self, climb_mps_per_step: float) -> None:
        self.rate_mps = climb_mps_per_step * DESCENT_STEPS
        self._plan: tuple[int, int] | None = None  # its start and its longest time, ms

    @property
    def active(self) -> bool:
        return self._plan is not None

    def begin(self, now_ms: int, height_m: float, drone: dp.DroneState | None) -> None:
        """A mission's landing begins: descend if the drone confirmed it is flying under the pilot's sticks."""
        if drone in FLYING_STATES:
            self._plan = (now_ms, round(1000.0 * DESCENT_MARGIN * max(0.0, height_m - LAND_FROM_M) / self.rate_mps))

    def cancel(self) -> None:
        self._plan = None

    def over(self, now_ms: int, settles_m: float, drone: dp.DroneState | None) -> bool:
        """Whether the descent ends now (low enough by the estimate, its time up, or the drone no longer flying);
        it is then no longer active."""
        if self._plan is None:
            return True
        start, longest = self._plan
        if settles_m <= LAND_FROM_M or now_ms - start >= longest or drone not in FLYING_STATES:
            self._plan = None
        return self._plan is None
