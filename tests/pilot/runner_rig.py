"""The runner's test rig: a stepped clock that is also the pacer, and blank camera frames (a Ctrl-C in flight
after ``interrupt_at_s``)."""

from __future__ import annotations

import math

import numpy as np

from pilot.vision.sources import Frame


class Clock:
    t = 100.0

    def now(self) -> float:
        return self.t

    def wait_tick(self) -> None:
        self.t += 0.05


class Frames:
    """Blank frames until ``interrupt_at_s`` (then a Ctrl-C in flight)."""

    def __init__(self, clock: Clock, interrupt_at_s: float = math.inf) -> None:
        self.clock, self.at = clock, interrupt_at_s

    def read(self) -> Frame:
        if self.clock.t > self.at:
            raise KeyboardInterrupt
        return Frame(np.zeros((240, 320, 3), np.uint8), self.clock.t, 0)

    def close(self) -> None:
        pass

    def __enter__(self) -> Frames:
        return self

    def __exit__(self, *exc: object) -> None:
        pass
