"""The gate between what the camera seems to show and what the pilot does about it.

The controller shows the gate every frame's detection (``observe``) and then asks it two questions:

* ``acquired()``: is there a target worth acting on now: found (measured, or bridged by the tracker)
  with a confidence at or above ``controller.acquire_confidence``. Turning towards it, approaching and
  aiming need this; anything less counts as a miss.
* ``confirmed()``: may the laser be on now: the last ``controller.confirm_frames`` frames in a row were
  each measured (not bridged), acquired, centred within ``controller.fire_tolerance``, estimated closer
  than ``controller.fire_range_max_m``, and the same steady thing as the frame before (``steady``: a hovering
  drone's ball changes little from frame to frame; a film's patches come and go, the track hopping between them).

A bad frame (``FrameStatus`` other than OK) is never a sighting and breaks the confirmation; ``fault`` and
``fault_frames`` tell the controller to hold and, after ``controller.blind_frames`` of them, to land. Figures:
bench/vision/HISTORY.md ("Thirty-fifth session").
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
            and abs(det.error_x) <= cfg.fire_tolerance
            and abs(det.error_y) <= cfg.fire_tolerance
            and 0.0 < det.range_m <= cfg.fire_range_max_m
        )
        if not good or det is None:
            self.streak = 0
            return
        same = not self.steadiness or (self.streak > 0 and self._last is not None and steady(self._last, det))
        self.streak = self.streak + 1 if same or self.streak == 0 else 1
        self._last = det

    def acquired(self) -> bool:
        return self._acquired

    def confirmed(self) -> bool:
        return self.streak >= self.cfg.confirm_frames
