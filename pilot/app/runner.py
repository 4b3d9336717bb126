"""The pilot loop: frame -> detection -> decision -> wire, at a steady tick, and the safe way out.

The same loop flies the real drone (a camera, a serial link, wall-clock pacing) and the simulated one (the
simulated camera, the virtual drone's pty, the world's stepped clock as the pacer). Each tick reads the replies
first (the pilot's view of the drone is what they confirm), then decides and sends one frame; whatever ends the
loop, ``run`` lands before it returns.
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

from ..common.errors import FrameSourceError, PortLost
from ..control.controller import Controller, State
from ..vision.detect import Detection, Detector
from ..vision.sources import Frame, FrameSource


class StopRequested(KeyboardInterrupt):
    """A stop asked from another thread (the live view's Stop button), raised in the loop by an observer
    (pilot.app.observers.StopSwitch): the same safe way out as Ctrl-C."""


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
    laser_on: bool | None = None  # the laser as the drone's replies confirmed it (None: no status yet)
    drone: str = ""  # the drone's state as its replies confirmed it
    armed: bool | None = None  # armed as the drone's replies confirmed it


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
    confirmed: str = ""  # what the drone last confirmed (its state and laser)
    safe: bool = False  # the drone confirmed not armed and laser off
    port_lost: str = ""  # the one line to print when the serial port vanished


class StatusLine:
    """One line on a terminal, rewritten: state, target seen, command rate, time, last command."""

    def __init__(self, out: TextIO | None = None, every_s: float = 0.25, live: bool | None = None) -> None:
        self.out = out = out if out is not None else sys.stderr
        self.every_s = every_s
        # on a terminal the line is rewritten in place; elsewhere (a log, make) one line per state change
        self.live = out.isatty() if live is None else live
        self._last = -math.inf
        self._state: tuple[State, str] | None = None
        self._sends: deque[float] = deque()
        self._t0: float | None = None  # the first tick: times are printed from the start of the run

    def on_tick(self, tick: Tick) -> None:
        if tick.command is not None:
            self._sends.append(tick.t)
        while self._sends and self._sends[0] <= tick.t - 1.0:
            self._sends.popleft()
        changed = (tick.state, tick.drone) != self._state
        self._state = (tick.state, tick.drone)
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
                f"{len(self._sends):3d} cmd/s  last {last}  drone {tick.drone or '?'}")
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
    """Fly until the mission, the time limit or the frames end, then land.

    Whatever ends the loop (also a lost camera, Ctrl-C/SIGTERM as ``KeyboardInterrupt``, or an exception in the
    source, detector, controller, link or an observer), the controller lands before this returns, one frame per
    tick: laser off until confirmed, servos home, the firmware's landing routine, keep-alives until the drone
    confirms it is not armed (or the landing time passes). A second Ctrl-C/SIGTERM while landing cuts that to the
    shortest sequence the firmware accepts (laser off, land, until confirmed disarmed, or no answer for the
    failsafe time); a third stops sending at once. A lost serial port ends the run at once: nothing can reach the
    drone, and the result says when its failsafe fires."""
    watchers = list(observers)
    start = pacer.now()
    link = _LinkState(pacer.now())
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
            replies = _poll(sink, controller)
            frame = source.read()
            frame_wall = wall_clock()  # the frame has arrived
            if frame is None:
                reason = "end of frames"
                break
            det = detector.detect(frame.image)
            command = controller.update(det)
            command = link.send(sink, command, now, keepalive_ms, controller.state is not State.DONE,
                                _copies(controller))
            tick = Tick(
                ticks, now, frame, det, controller.state, command, tuple(replies), frame_wall,
                wall_clock() if command is not None else None,
                laser_on=controller.laser_on, drone=controller.drone.describe(), armed=controller.drone.armed,
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
    except PortLost as exc:
        reason, error = f"serial port lost: {exc}", exc
    except StopRequested as exc:
        reason, error = f"stop requested ({exc})", exc
    except KeyboardInterrupt as exc:
        reason, error = "interrupted", exc
    except BaseException as exc:  # any stage: land safely first, report afterwards
        reason, error = f"{type(exc).__name__}: {exc}", exc
    result = RunResult(reason, ticks, controller.state, controller.fired, error)
    if isinstance(error, PortLost):
        result.port_lost = _port_lost_line(error, link, pacer.now())
    elif controller.state is not State.DONE or not controller.drone.safe:
        controller.abort(reason)
        _shutdown(controller, sink, pacer, keepalive_ms, link, result)
    result.state = controller.state
    result.confirmed = controller.drone.describe()
    result.safe = controller.drone.safe
    return result


# A status poll (the controller waiting for the drone to confirm a change: arming, landing, disarming) goes out
# this many times in its tick. Only a reply confirms a change, and each copy gets one: over a link losing 10 % of
# its bytes, a frame and its reply both survive about one tick in four (bench/lossy). Every other frame goes out
# once: a copy is another chance for a damaged byte to make another command of it where no check catches that.
POLL_COPIES = 3


class _LinkState:
    """When the last frame went out (the keep-alive and the failsafe countdown start there)."""

    def __init__(self, now: float) -> None:
        self.last_send = -math.inf
        self.last_ok = now

    def send(self, sink: Sink, command: bytes | None, now: float, keepalive_ms: int, alive: bool,
             copies: int = 1) -> bytes | None:
        if command is None and alive and (now - self.last_send) * 1000.0 >= keepalive_ms:
            command = dp.hold_altitude()  # keep-alive: shorter than the firmware's command timeout
        if command is not None:
            self.last_send = now
            for _ in range(copies):
                if not sink.send(command):
                    break
                self.last_ok = now
        return command


def _copies(controller: Controller) -> int:
    return POLL_COPIES if controller.polling else 1


def _poll(sink: Sink, controller: Controller) -> list[dp.Reply]:
    replies = sink.poll()
    for reply in replies:
        controller.on_reply(reply)
    return replies


def _port_lost_line(error: PortLost, link: _LinkState, now: float) -> str:
    silent_ms = max(0, round((now - link.last_ok) * 1000.0))
    left = dp.FAILSAFE_TIMEOUT_MS - silent_ms
    when = f"will failsafe in {left} ms" if left > 0 else f"has failsafed ({silent_ms} ms without a frame)"
    return (
        f"{error}; nothing more can be sent: the drone {when} (failsafe after {dp.FAILSAFE_TIMEOUT_MS} ms "
        "without a valid frame: failsafe throttle, laser off); no landing was sent"
    )


def _shutdown(
    controller: Controller, sink: Sink, pacer: Pacer, keepalive_ms: int, link: _LinkState, result: RunResult
) -> None:
    """Land: one frame per tick until the controller is DONE. A second interrupt cuts it to the shortest
    safe sequence; a third stops sending; a lost port stops at once."""
    interrupts = 0
    stuck = 0
    while controller.state is not State.DONE:
        try:
            before = pacer.now()
            _guarded(result, "poll", lambda: _poll(sink, controller))
            frame = controller.update(None)
            sent = link.send(sink, frame, pacer.now(), keepalive_ms, True, _copies(controller))
            if sent is not None:
                result.safe_frames.append(sent)
            pacer.wait_tick()
            stuck = stuck + 1 if pacer.now() <= before else 0
            if stuck > 3:  # a pacer that cannot move on: stop rather than spin
                result.shutdown_errors.append("the clock stopped while landing")
                break
        except PortLost as exc:
            result.port_lost = _port_lost_line(exc, link, pacer.now())
            break
        except KeyboardInterrupt:
            interrupts += 1
            if interrupts > 1:
                left = max(0, dp.FAILSAFE_TIMEOUT_MS - round((pacer.now() - link.last_ok) * 1000.0))
                result.shutdown_errors.append(
                    f"interrupted a third time: stopped sending; the drone will failsafe in {left} ms"
                )
                break
            controller.emergency()
            result.shutdown_errors.append(
                "interrupted again while landing: the shortest safe sequence (laser off, land, until the drone "
                "confirms it disarmed or stops answering)"
            )
        except Exception as exc:  # the shutdown must go on whatever fails
            result.shutdown_errors.append(f"{type(exc).__name__}: {exc}")
            stuck += 1
            if stuck > 3:
                break


def _guarded(result: RunResult, what: str, fn: Callable[[], object]) -> None:
    try:
        fn()
    except PortLost:
        raise
    except Exception as exc:  # the shutdown must go on whatever fails
        result.shutdown_errors.append(f"{what}: {type(exc).__name__}: {exc}")
