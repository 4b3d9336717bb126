"""The gate between what the camera seems to show and what the pilot does about it.

The controller shows the gate every frame's detection (``observe``) and then asks it two questions:

* ``acquired()``: is there a target worth acting on now: found (measured, or bridged by the tracker) with a
  confidence at or above ``controller.acquire_confidence``. Turning, approaching and aiming need this; less is a miss.
* ``confirmed()``: may the laser be on now: the last ``controller.confirm_frames`` frames in a row were
  each measured (not bridged), acquired, centred (``centre_room``: within ``controller.fire_tolerance``, or
  within half the target's apparent radius when that is more), estimated closer than
  ``controller.fire_range_max_m``, and the same steady thing as the frame before (``steady``: a ball changes
  little from frame to frame; a film's patches come and go). Figures: bench/vision/HISTORY.md.

A bad frame (``FrameStatus`` other than OK) is never a sighting and breaks the confirmation; ``fault`` and
``fault_frames`` tell the controller to hold and, after ``controller.blind_frames`` of them, to land.
"""

from __future__ import annotations

import math

from ..common.config import ControllerConfig
from .detection import Detection, FrameStatus

STEADY_SIZE = 1.3  # frame to frame: 99.2 % of a ball's measures on the tuning sources' sequences
STEADY_STEP = 0.35  # of the size, frame to frame: a ball's measures at most 0.27 there


def steady(before: Detection, now: Detection) -> bool:
    """Whether ``now`` measures the same steady thing as ``before`` (size and centre, frame to frame)."""
    big, small = max(before.size, now.size), min(before.size, now.size)
    return small > 0.0 and big <= STEADY_SIZE * small and math.hypot(
        now.cx - before.cx, now.cy - before.cy) <= STEADY_STEP * big


SPOT_SHARE = 0.5  # the aim may stray this share of the target's apparent radius: the spot stays on it a late frame on


def centre_room(det: Detection, tolerance: float) -> tuple[float, float]:
    """How far from the target's centre the aim point (the frame's middle, where the laser points) may be, as
    normalised errors (x, y), for the spot to stay on the target: ``tolerance``, or ``SPOT_SHARE`` of the target's
    apparent radius where that is more (a near target's spot has room a fixed tolerance would throw away)."""
    radius = det.size / 2.0
    room_x = SPOT_SHARE * radius / (det.width / 2.0) if det.width else 0.0
    room_y = SPOT_SHARE * radius / (det.height / 2.0) if det.height else 0.0
    return max(tolerance, room_x), max(tolerance, room_y)


class Gate:
    def __init__(self, config: ControllerConfig | None = None, steadiness: bool = True) -> None:
        """``steadiness``: False leaves the steadiness rule out (the bench measures what it does)."""
        self.cfg = config or ControllerConfig()
        self.steadiness = steadiness
        self.fault: FrameStatus | None = None
        self.fault_frames = 0  # bad frames in a row
        self.streak = 0  # frames in a row that would allow the laser
        self._acquired = False
        self._last: Detection | None = None  # the streak's last frame

    def observe(self, det: Detection | None) -> None:
        cfg = self.cfg
        if det is not None and det.status is not FrameStatus.OK:
            self.fault = det.status
            self.fault_frames += 1
            self.streak = 0
            self._acquired = False
            return
        self.fault, self.fault_frames = None, 0
        self._acquired = det is not None and det.found and det.confidence >= cfg.acquire_confidence
        good = (
            self._acquired
            and det is not None
            and not det.predicted
            and centred(det, cfg.fire_tolerance)
            and 0.0 < det.range_m <= cfg.fire_range_max_m
        )
        if not good or det is None:
            self.streak = 0
            return
        other = self.steadiness and self.streak > 0 and self._last is not None and not steady(self._last, det)
        self.streak = 1 if other else self.streak + 1  # another thing: the streak starts again at it
        self._last = det

    def acquired(self) -> bool:
        return self._acquired

    def confirmed(self) -> bool:
        return self.streak >= self.cfg.confirm_frames


def centred(det: Detection, tolerance: float) -> bool:
    """Whether the aim point is within ``centre_room`` of the target's centre."""
    room_x, room_y = centre_room(det, tolerance)
    return abs(det.error_x) <= room_x and abs(det.error_y) <= room_y
