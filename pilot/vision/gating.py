"""The gate between what the camera seems to show and what the pilot does about it.

The controller shows the gate every frame's detection (``observe``) and then asks it two questions:

* ``acquired()``: is there a target worth acting on now: found (measured, or bridged by the tracker)
  with a confidence at or above ``controller.acquire_confidence``. Turning towards it, approaching and
  aiming need this; anything less counts as a miss.
* ``confirmed()``: may the laser be on now: the last ``controller.confirm_frames`` frames in a row were
  each measured (not bridged), acquired, centred within ``controller.fire_tolerance`` and estimated
  closer than ``controller.fire_range_max_m``.

A bad frame (``FrameStatus`` other than OK) is never a sighting and breaks the confirmation; ``fault`` and
``fault_frames`` tell the controller to hold and, after ``controller.blind_frames`` of them, to land.
"""

from __future__ import annotations

from ..common.config import ControllerConfig
from .detection import Detection, FrameStatus


class Gate:
    def __init__(self, config: ControllerConfig | None = None) -> None:
        self.cfg = config or ControllerConfig()
        self.fault: FrameStatus | None = None
        self.fault_frames = 0  # bad frames in a row
        self.streak = 0  # frames in a row that would allow the laser
        self._acquired = False

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
        self.streak = self.streak + 1 if good else 0

    def acquired(self) -> bool:
        return self._acquired

    def confirmed(self) -> bool:
        return self.streak >= self.cfg.confirm_frames
