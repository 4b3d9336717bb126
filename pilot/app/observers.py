"""Observers of the pilot loop used by the command line: the laser tally of the run summary, wall-clock
pacing of a simulated flight that someone watches, and the thread-safe stop switch of the live view."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from .runner import StopRequested, Tick


class LaserTally:
    """How long the laser was lit, as the pilot knew it tick by tick (the summary's "laser fired")."""

    def __init__(self) -> None:
        self.lit_s = 0.0
        self._since: float | None = None
        self._last_t: float | None = None

    @property
    def fired(self) -> bool:
        return self.lit_s > 0.0 or self._since is not None

    def on_tick(self, tick: Tick) -> None:
        if tick.laser_on and self._since is None:
            self._since = tick.t
        elif not tick.laser_on and self._since is not None:
            self.lit_s += tick.t - self._since
            self._since = None
        self._last_t = tick.t

    def summary(self) -> str:
        lit = self.lit_s + (self._last_t - self._since if self._since is not None and self._last_t else 0.0)
        return f"laser fired: {'yes' if self.fired else 'no'} (lit {lit:.2f} s)"


class WallClockPacing:
    """Holds a simulated flight to real time (the simulator otherwise runs as fast as it can), so a
    live view shows it at the speed it would fly."""

    def __init__(self, clock: Callable[[], float] = time.monotonic, sleep: Callable[[float], None] = time.sleep):
        self._clock, self._sleep = clock, sleep
        self._origin: tuple[float, float] | None = None

    def on_tick(self, tick: Tick) -> None:
        if self._origin is None:
            self._origin = (tick.t, self._clock())
        ahead = (tick.t - self._origin[0]) - (self._clock() - self._origin[1])
        if ahead > 0:
            self._sleep(ahead)


class StopSwitch:
    """A stop any thread may request (the live view's Stop button); the pilot loop, at its next tick,
    raises ``StopRequested``, a ``KeyboardInterrupt``: the same safe way out as Ctrl-C."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self.why = ""

    def request(self, why: str) -> None:
        self.why = why
        self._event.set()

    @property
    def requested(self) -> bool:
        return self._event.is_set()

    def on_tick(self, tick: Tick) -> None:
        if self._event.is_set():
            raise StopRequested(self.why)
