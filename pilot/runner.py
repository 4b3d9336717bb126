"""The pilot loop: frame -> detection -> decision -> wire, at a steady tick, and the safe way out.

The same loop flies the real drone (a camera, a serial link, wall-clock pacing) and the simulated
one (the simulated camera, the virtual drone's pty, the world's stepped clock as the pacer).

Safety: whatever ends the loop — the mission done, the time limit, the end of a video, a lost camera,
Ctrl-C/SIGTERM (``KeyboardInterrupt``), or an exception in any stage (source, detector, controller,
link, observers) — the controller's safe steps go on the wire before ``run`` returns, one per tick:
laser off (if on), sticks neutral, servos home, down until landed (if it was flying), disarm; then
keep-alives while the firmware's disarm sequence runs.
"""

from __future__ import annotations

import math
import sys
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Protocol, TextIO

import drone_protocol as dp

from .controller import Controller, State
from .detect import Detection, Detector
from .errors import FrameSourceError
from .sources import Frame, FrameSource


class StopRequested(KeyboardInterrupt):
    """A stop asked from another thread (the live view's Stop button), raised in the loop by an observer
    (pilot.observers.StopSwitch): the same safe way out as Ctrl-C."""


class Sink(Protocol):
    def send(self, frame: bytes) -> bool: ...

    def poll(self) -> list[dp.Reply]: ...


class Pacer(Protocol):
    def now(self) -> float: ...

    def wait_tick(self) -> None: ...


class RealPacer:
    """A steady wall-clock tick (e.g. 20 Hz): deadlines on a fixed grid, resynchronised when late."""

    def __init__(
        self,
        rate_hz: float,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.period = 1.0 / rate_hz
        self._clock = clock
        self._sleep = sleep
        self._next = clock() + self.period

    def now(self) -> float:
        return self._clock()

    def wait_tick(self) -> None:
        delay = self._next - self._clock()
        if delay > 0:
            self._sleep(delay)
            self._next += self.period
        else:  # late: start a new grid from now rather than sending a burst
            self._next = self._clock() + self.period


class DryRunSink:
    """``--dry-run``: decide and print the commands, send nothing."""

    def __init__(self, out: TextIO | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        self.out = out if out is not None else sys.stdout
        self.sent: list[bytes] = []
        self._clock = clock

    def send(self, frame: bytes) -> bool:
        self.sent.append(frame)
        print(f"dry-run {frame.decode('ascii')}", file=self.out)
        return True

    def poll(self) -> list[dp.Reply]:
        return []


@dataclass(frozen=True)
class Tick:
    index: int
    t: float
    frame: Frame | None
    detection: Detection | None
    state: State
    command: bytes | None
    replies: tuple[dp.Reply, ...]
    frame_t: float  # when the frame arrived (the wall clock)
    sent_t: float | None  # when its command's last byte was written and flushed (the wall clock), if any
    laser_on: bool = False  # what the pilot believes of the laser after this tick


class Observer(Protocol):
    def on_tick(self, tick: Tick) -> None: ...


@dataclass
class RunResult:
    reason: str
    ticks: int
    state: State
    fired: bool
    error: BaseException | None = None
    safe_frames: list[bytes] = field(default_factory=list)
    shutdown_errors: list[str] = field(default_factory=list)


class StatusLine:
    """One line on a terminal, rewritten: state, target seen, command rate, time, last command."""

    def __init__(self, out: TextIO | None = None, every_s: float = 0.25, live: bool | None = None) -> None:
        self.out = out = out if out is not None else sys.stderr
        self.every_s = every_s
        # on a terminal the line is rewritten in place; elsewhere (a log, make) one line per state change
        self.live = out.isatty() if live is None else live
        self._last = -math.inf
        self._state: State | None = None
        self._sends: deque[float] = deque()
        self._t0: float | None = None  # the first tick: times are printed from the start of the run

    def on_tick(self, tick: Tick) -> None:
        if tick.command is not None:
            self._sends.append(tick.t)
        while self._sends and self._sends[0] <= tick.t - 1.0:
            self._sends.popleft()
        changed = tick.state is not self._state
        self._state = tick.state
        if self.live and tick.t - self._last < self.every_s and not changed:
            return
        if not self.live and not changed:
            return
        self._last = tick.t
        if self._t0 is None:
            self._t0 = tick.t
        seen = "yes" if tick.detection is not None and tick.detection.found else "no "
        last = tick.command.decode("ascii") if tick.command else "      "
        line = (f"t {tick.t - self._t0:7.2f}s  state {tick.state.value:8s}  target {seen}  "
                f"{len(self._sends):3d} cmd/s  last {last}")
        self.out.write(f"\r{line}" if self.live else f"{line}\n")
        self.out.flush()

    def finish(self) -> None:
        if self.live:
            self.out.write("\n")
            self.out.flush()


def run(
    source: FrameSource,
    detector: Detector,
    controller: Controller,
    sink: Sink,
    pacer: Pacer,
    *,
    max_seconds: float,
    keepalive_ms: int,
    observers: Iterable[Observer] = (),
    wall_clock: Callable[[], float] = time.perf_counter,
) -> RunResult:
    watchers = list(observers)
    start = pacer.now()
    last_send = -math.inf
    ticks = 0
    reason = ""
    error: BaseException | None = None
    controller.start()
    try:
        while True:
            now = pacer.now()
            if now - start >= max_seconds:
                reason = f"time limit ({max_seconds:g} s)"
                break
            frame = source.read()
            frame_wall = wall_clock()  # the frame has arrived
            if frame is None:
                reason = "end of frames"
                break
            det = detector.detect(frame.image)
            command = controller.update(det)
            if command is None and (now - last_send) * 1000.0 >= keepalive_ms and controller.state is not State.DONE:
                command = dp.hold_altitude()  # keep-alive: shorter than the firmware's command timeout
            sent_t = None
            if command is not None:
                sink.send(command)
                sent_t = wall_clock()
                last_send = now
            replies = sink.poll()
            for reply in replies:
                controller.on_reply(reply)
            tick = Tick(
                ticks, now, frame, det, controller.state, command, tuple(replies), frame_wall, sent_t,
                laser_on=controller.laser_on,
            )
            for w in watchers:
                w.on_tick(tick)
            ticks += 1
            if controller.state is State.DONE:
                reason = controller.transitions[-1].reason if controller.transitions else "done"
                break
            pacer.wait_tick()
    except FrameSourceError as exc:
        reason, error = f"camera lost: {exc}", exc
    except StopRequested as exc:
        reason, error = f"stop requested ({exc})", exc
    except KeyboardInterrupt as exc:
        reason, error = "interrupted", exc
    except BaseException as exc:  # any stage: land safely first, report afterwards
        reason, error = f"{type(exc).__name__}: {exc}", exc
    result = RunResult(reason, ticks, controller.state, controller.fired, error)
    landed = controller.state is State.DONE and error is None and controller.last_command == dp.disarm()
    if not landed:
        controller.abort(reason)
        _shutdown(controller, sink, pacer, keepalive_ms, result)
    else:
        _finish_disarm(sink, pacer, keepalive_ms, result)
    result.state = controller.state
    return result


def _guarded(result: RunResult, what: str, fn: Callable[[], object]) -> None:
    try:
        fn()
    except Exception as exc:  # the shutdown must go on whatever fails
        result.shutdown_errors.append(f"{what}: {type(exc).__name__}: {exc}")


def _shutdown(controller: Controller, sink: Sink, pacer: Pacer, keepalive_ms: int, result: RunResult) -> None:
    def sender(frame: bytes) -> Callable[[], object]:
        return lambda: sink.send(frame)

    try:
        for frame in controller.safe_steps():
            result.safe_frames.append(frame)
            _guarded(result, f"send {frame!r}", sender(frame))
            _guarded(result, "poll", sink.poll)
            _guarded(result, "pace", pacer.wait_tick)
        _finish_disarm(sink, pacer, keepalive_ms, result)
    except KeyboardInterrupt:
        # a second Ctrl-C (or SIGTERM) while landing: laser and sticks are already safe; disarm now and go
        if not result.safe_frames or result.safe_frames[-1] != dp.disarm():
            result.safe_frames.append(dp.disarm())
            _guarded(result, "send disarm", lambda: sink.send(dp.disarm()))
        result.shutdown_errors.append("interrupted again while landing: disarmed at once")


def _finish_disarm(sink: Sink, pacer: Pacer, keepalive_ms: int, result: RunResult) -> None:
    """Keep the link alive while the firmware's disarm sequence runs (it refuses them as busy)."""
    start = pacer.now()
    last = -math.inf
    while (pacer.now() - start) * 1000.0 < dp.ARMING_HOLD_MS + keepalive_ms:
        if (pacer.now() - last) * 1000.0 >= keepalive_ms:
            last = pacer.now()
            _guarded(result, "keep-alive", lambda: sink.send(dp.hold_altitude()))
        _guarded(result, "poll", sink.poll)
        before = pacer.now()
        _guarded(result, "pace", pacer.wait_tick)
        if pacer.now() <= before:  # a pacer that cannot move on: stop rather than spin
            break
