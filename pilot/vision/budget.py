"""A per-frame time budget for the detectors: the frame's first look always runs, each further refinement only
while time is left, so a frame full of the target's colour costs about the budget and never the tick.

The clock is the calling thread's CPU time: a frame is cut short by its own content, never by another process's
turns on a shared core, so the same frame gets the same answer at any load. It is injected (tests advance it by
hand, or freeze ``CLOCK`` to judge a detector's rules alone); ``exhausted`` tells the caller that the frame's answer
is the best candidate found before the time ran out, which the pilot's log records.
"""

from __future__ import annotations

import time
from collections.abc import Callable

CLOCK: Callable[[], float] = time.thread_time  # seconds of this thread's CPU; the clock of a budget given none


class FrameBudget:
    def __init__(self, budget_ms: float, clock: Callable[[], float] | None = None) -> None:
        self.budget_ms = budget_ms
        self.clock = clock if clock is not None else CLOCK
        self._t0 = self.clock()
        self.exhausted = False  # this frame ran out of time

    def start(self) -> None:
        """A new frame: the budget counts from now."""
        self._t0 = self.clock()
        self.exhausted = False

    def spent_ms(self) -> float:
        return 1e3 * (self.clock() - self._t0)

    def out(self) -> bool:
        """Whether the frame's time is spent (and stays spent until the next ``start``)."""
        if not self.exhausted and self.spent_ms() >= self.budget_ms:
            self.exhausted = True
        return self.exhausted
