"""The closing speed on the target, from the ranges the detector estimates (apparent size against known size).

The flight controller holds altitude but not position: a drone that stops commanding forward coasts on. The
pilot has no other velocity sensor, so it fits a line to the last ``window_s`` of range estimates: 0.4 s, a compromise
between the slope's noise (about 0.35 m/s for a 25 px target at 3 m at 20 Hz, a quarter of it at 1.5 m) and
its lag (0.2 s, which makes a brake overshoot). A brake counts only the speed the ranges show for certain: the fit
less its standard error (``ClosingSpeed.sure``), from the ball's size (``SIZE_JITTER_PX``).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

# the detector's diameter of a ball jitters by about half a pixel from frame to frame (13-17 px balls at 4-6 m in
# ``occluded`` 3010 and ``distractor`` 3012): a range from it errs by range * 0.5 / size, 0.15 m at 5 m, and a fit
# of four such ranges over 0.15 s then reads 1.1 m/s on a drone closing at 0.16 (``distractor`` 3012 braked on it)
SIZE_JITTER_PX = 0.5


class ClosingSpeed:
    def __init__(self, window_s: float = 0.4, min_samples: int = 4, max_rate: float = 2.5) -> None:
        self.window_s = window_s
        self.min_samples = min_samples
        self.max_rate = max_rate  # m/s between two samples that no flight reaches: a new target, start again
        self._samples: deque[tuple[float, float]] = deque()
        self._noise: deque[float] = deque()  # each range's expected error (m), beside its sample

    def reset(self) -> None:
        self._samples.clear()
        self._noise.clear()

    def update(self, t: float, range_m: float, size_px: float = 0.0) -> None:
        """A range estimate at ``t`` (s); ``size_px``: the apparent diameter it rests on (0: no expected error)."""
        if range_m <= 0.0 or not math.isfinite(range_m):
            return
        if self._samples:
            t0, r0 = self._samples[-1]
            if t <= t0 or abs(range_m - r0) > self.max_rate * (t - t0):
                self.reset()
        self._samples.append((t, range_m))
        self._noise.append(range_m * SIZE_JITTER_PX / size_px if size_px > 0.0 else 0.0)
        while self._samples and t - self._samples[0][0] > self.window_s:
            self._samples.popleft()
            self._noise.popleft()

    @property
    def closing(self) -> float | None:
        """m/s towards the target (negative: receding); None until enough samples."""
        if len(self._samples) < self.min_samples:
            return None
        rate = slope(self._samples)
        return None if rate is None else -rate

    @property
    def error(self) -> float | None:
        """The closing speed's standard error (m/s) from the ranges' expected errors, None with ``closing``. Not
        their scatter: a few ranges fall on a line by chance (``distractor`` 3012: four of a 16 px ball, 0.27 m/s
        for 1.1), and a near ball clipped by the frame's edges scatters for a reason (``low`` 3009: 0.47 m/s at
        150 px, which then braked too little at a loss, into the ball)."""
        n = len(self._samples)
        if n < self.min_samples:
            return None
        mt = sum(t for t, _ in self._samples) / n
        spread = sum((t - mt) ** 2 for t, _ in self._samples)
        return math.sqrt(sum(e * e for e in self._noise) / n / spread) if spread > 0.0 else 0.0

    @property
    def sure(self) -> float | None:
        """The closing speed less its standard error: as fast as the ranges show for certain."""
        closing, error = self.closing, self.error
        return None if closing is None else closing - (error or 0.0)


def slope(samples: Sequence[tuple[float, float]]) -> float | None:
    """The least-squares slope of (t, value) samples, value per second (None: no spread in time)."""
    n = len(samples)
    if n < 2:
        return None
    mt = sum(t for t, _ in samples) / n
    mv = sum(v for _, v in samples) / n
    var = sum((t - mt) ** 2 for t, _ in samples)
    if var <= 0.0:
        return None
    return sum((t - mt) * (v - mv) for t, v in samples) / var


def allowed_speed(remaining_m: float, brake_mps2: float, top_mps: float) -> float:
    """The closing speed from which the drone can still stop within ``remaining_m``."""
    return min(top_mps, math.sqrt(2.0 * brake_mps2 * max(0.0, remaining_m)))


class Momentum:
    """Dead reckoning of the forward speed from the pitch commands the pilot sent, for when vision has none (the
    target lost while closing in): a pitch command of one control step accelerates at ``accel_per_step``, and
    with the stick released the speed decays with drag over ``decay_s``. Any vision estimate replaces it."""

    def __init__(self, accel_per_step: float, decay_s: float = 3.0) -> None:
        self.accel_per_step = accel_per_step
        self.decay_s = decay_s
        self.speed = 0.0  # m/s forward
        self.error = 0.0  # the standard error of the vision estimate it last took (``ClosingSpeed.error``)

    def reset(self) -> None:
        self.speed = self.error = 0.0

    def observe(self, closing: float | None, error: float | None = None) -> None:
        if closing is not None:
            self.speed, self.error = closing, error or 0.0

    @property
    def sure(self) -> float:
        """The speed less the standard error of the vision estimate it was last given."""
        return self.speed - self.error

    def advance(self, pitch_steps: float, dt: float) -> None:
        """``pitch_steps``: the pitch stick held during ``dt``, in control steps (forward positive)."""
        self.speed += self.accel_per_step * pitch_steps * dt - self.speed * dt / self.decay_s


GRAVITY = 9.81


class Lean:
    """The airframe's pitch, estimated from the pitch commands (forward, nose down, positive): in AltHold the
    stick sets the lean angle, reached with a lag (``ATC_INPUT_TC`` and the attitude loop). The camera leans
    with the airframe, so a brake that pitches the nose up moves the target down the frame by the change."""

    def __init__(self, accel_per_step: float, lag_s: float = 0.2) -> None:
        self.deg_per_step = math.degrees(math.atan(accel_per_step / GRAVITY))  # the lean that accelerates so
        self.lag_s = lag_s
        self.deg = 0.0

    def advance(self, pitch_steps: float, dt: float) -> None:
        """``pitch_steps``: the pitch stick held during ``dt`` (its lean follows whatever the state: no reset)."""
        if dt > 0.0:
            self.deg += (self.deg_per_step * pitch_steps - self.deg) * (1.0 - math.exp(-dt / self.lag_s))


class Lead:
    """What the pitch commands of the last ``lag_s`` added to the speed, which the closing-speed fit cannot show
    yet: the fit describes the middle of its window, and each frame reaches the pilot up to 120 ms after its
    exposure. Added to the fit, it keeps a brake from running on past the stop (and the drone flying backwards)."""

    def __init__(self, accel_per_step: float, lag_s: float = 0.3) -> None:
        self.accel_per_step = accel_per_step
        self.lag_s = lag_s
        self._steps: deque[tuple[float, float]] = deque()  # (dt, pitch steps held during it), newest last

    def advance(self, pitch_steps: float, dt: float) -> None:
        if dt <= 0.0:
            return
        self._steps.append((dt, pitch_steps))
        total = sum(d for d, _ in self._steps)
        while self._steps and total - self._steps[0][0] >= self.lag_s:
            total -= self._steps.popleft()[0]

    @property
    def speed(self) -> float:
        """m/s forward the recent pitch commands added."""
        return self.accel_per_step * sum(d * s for d, s in self._steps)


def brake_steps(speed: float) -> float:
    """The pitch-back stick, in control steps, against a closing speed: harder the faster it closes, up to 1.4."""
    return min(1.4, 0.8 + speed)
