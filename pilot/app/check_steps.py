"""The steps of ``pilot check``: a guided bring-up of the bench (props off) over an open link.

Each step sends frames from the generated module and judges only what the drone's replies confirm (the status
suffix: the state and the laser). What the protocol cannot read back (an RC pulse width, a servo angle, the laser's
light) is named in the step's ``look`` text: what the user must watch to confirm it. Whatever happens, ``make_safe``
ends with the laser off and the drone disarmed, and says whether the drone confirmed it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import drone_protocol as dp

from ..link.drone_view import DroneView

KEEPALIVE_S = dp.FAILSAFE_TIMEOUT_MS / 4000.0  # the query's period while waiting: the failsafe stays away
ANSWER_S = 0.5  # a reply takes a few ms over USB; this much silence means no answer
HOLD_S = min(0.3, dp.COMMAND_TIMEOUT_MS / 2000.0)  # each channel step is held this long (watch it move)
S = dp.DroneState


class Sink(Protocol):
    """What the check talks to: the serial link, or a fake drone in tests."""

    def send(self, frame: bytes) -> bool: ...
    def poll(self) -> list[dp.Reply]: ...


@dataclass
class Step:
    name: str
    ok: bool
    detail: str
    look: str = ""  # what the protocol cannot confirm, for the user to watch


class StepFailed(Exception):
    """A step found the bench not doing what the spec says; the message says what to check."""


@dataclass
class Bench:
    sink: Sink
    clock: Callable[[], float]
    sleep: Callable[[float], None]
    view: DroneView = field(default_factory=DroneView)
    failsafes: list[float] = field(default_factory=list)  # when a failsafe reply arrived
    sent: list[tuple[float, bytes]] = field(default_factory=list)

    def _read(self) -> list[dp.Reply]:
        replies = self.sink.poll()
        for reply in replies:
            self.view.update(reply, round(self.clock() * 1000))
            if reply.kind is dp.ReplyKind.FAILSAFE:
                self.failsafes.append(self.clock())
        return replies

    def exchange(self, frame: bytes) -> dp.Reply:
        """Send one frame and return its answer (accepted or rejected); StepFailed when none comes."""
        self._read()
        self.sent.append((self.clock(), frame))
        if not self.sink.send(frame):
            raise StepFailed("the serial port failed while sending: check the USB cable")
        deadline = self.clock() + ANSWER_S
        while self.clock() < deadline:
            for reply in self._read():
                if reply.kind in (dp.ReplyKind.ACCEPTED, dp.ReplyKind.REJECTED):
                    return reply
            self.sleep(0.005)
        name = dp.decode(frame).name
        raise StepFailed(f"no answer to {frame.decode()} ({name}) within {ANSWER_S:g} s: check the USB cable and "
                         "that no other program uses the port")

    def accepted(self, frame: bytes, *states: dp.DroneState) -> dp.Reply:
        """``frame``'s answer, which must accept it and (if given) report one of ``states``."""
        reply = self.exchange(frame)
        name = dp.decode(frame).name
        if reply.kind is dp.ReplyKind.REJECTED:
            error = reply.error.name.lower() if reply.error else "refused"
            raise StepFailed(f"the drone refused {frame.decode()} ({name}): {error} in state "
                             f"{_state(reply)}")
        if states and reply.state not in states:
            raise StepFailed(f"{frame.decode()} ({name}) was accepted but the drone reports {_state(reply)}, not "
                             f"{' or '.join(s.value for s in states)}")
        return reply

    def wait_state(self, wanted: dp.DroneState, seconds: float) -> float:
        """Query every KEEPALIVE_S until the drone reports ``wanted``; the seconds it took."""
        start = self.clock()
        while self.clock() - start <= seconds:
            reply = self.exchange(dp.query_status())
            if reply.state is wanted:
                return self.clock() - start
            self.sleep(KEEPALIVE_S)
        raise StepFailed(f"the drone did not report {wanted.value} within {seconds:g} s (it reports "
                         f"{self.view.describe()})")

    def silence(self, seconds: float, until: Callable[[], bool]) -> float:
        """Send nothing for up to ``seconds``, reading replies, until ``until()``; the seconds waited."""
        start = self.clock()
        while self.clock() - start < seconds and not until():
            self._read()
            self.sleep(0.005)
        return self.clock() - start


def _state(reply: dp.Reply) -> str:
    laser = "laser on" if reply.laser else "laser off"
    return f"{reply.state.name.lower() if reply.state else 'no state'}, {laser}"


def _frame(spec: dp.CommandSpec, value: int) -> bytes:
    return dp.encode(spec.category, spec.direction, value)


def _commands(target: str) -> list[dp.CommandSpec]:
    return [spec for spec in dp.COMMANDS.values() if spec.target == target]


def step_status(bench: Bench) -> Step:
    reply = bench.exchange(dp.query_status())
    return Step("status", True, f"the drone answers the status query: {_state(reply)}")


def step_laser(bench: Bench) -> Step:
    on = bench.accepted(dp.laser_on())
    if on.laser is not True:
        raise StepFailed(f"laser_on was accepted but the drone reports the laser off ({_state(on)})")
    bench.sleep(HOLD_S)
    off = bench.accepted(dp.laser_off())
    if off.laser is not False:
        raise StepFailed(f"laser_off was accepted but the drone reports the laser on ({_state(off)})")
    return Step("laser", True, "on, then off: both confirmed by the drone",
                look="the laser (and the board's LED on the laser pin) lit once, then went dark")


def step_servos(bench: Bench) -> Step:
    done = []
    for servo in dp.SERVOS.values():
        for spec in sorted(_commands(servo.name.value), key=lambda s: s.sense):
            span = (servo.default - servo.minimum) if spec.sense < 0 else (servo.maximum - servo.minimum)
            value = max(spec.minimum, min(spec.maximum, span))
            bench.accepted(_frame(spec, value))
            done.append(f"{spec.name.value} {value}")
            bench.sleep(HOLD_S)
    bench.accepted(dp.servo_reset())
    return Step("servos", True, f"sweep accepted ({', '.join(done)}, then back to centre)",
                look="each servo swung to one end, to the other, and back to the middle (angles are not reported)")


def step_arming(bench: Bench) -> Step:
    bench.accepted(dp.arm(), S.ARMING, S.ARMED)
    armed = bench.wait_state(S.ARMED, dp.ARMING_HOLD_MS / 1000.0 + 1.0)
    bench.accepted(dp.disarm(), S.DISARMING, S.DISARMED)
    disarmed = bench.wait_state(S.DISARMED, dp.ARMING_HOLD_MS / 1000.0 + 1.0)
    return Step("arming", True, f"armed after {armed:.1f} s, disarmed after {disarmed:.1f} s (the drone confirmed "
                f"both; the sticks are held {dp.ARMING_HOLD_MS} ms)",
                look="the flight controller armed (Mission Planner: ARMED; the motors may spin at idle) and then "
                "disarmed; if it did not, check the throttle and yaw wiring and the RC calibration")


def step_channel(bench: Bench, channel: dp.ChannelName) -> Step:
    """Each command driving ``channel`` at its default speed: accepted, the drone reports it moving."""
    if bench.view.state is not S.ARMED and bench.view.state not in (S.HOLD_ALTITUDE, S.MOVING):
        bench.accepted(dp.arm(), S.ARMING, S.ARMED)
        bench.wait_state(S.ARMED, dp.ARMING_HOLD_MS / 1000.0 + 1.0)
    done = []
    for spec in _commands(channel.value):
        value = spec.default if spec.default is not None else dp.CHANNELS[channel].median
        try:
            bench.accepted(_frame(spec, value), S.MOVING)
        except StepFailed as exc:
            raise StepFailed(f"{channel.value} did not move: {exc}; check that the firmware was built from this "
                             "spec and handles it") from exc
        done.append(f"{spec.name.value} {value} us")
        bench.sleep(HOLD_S)
    if not done:
        raise StepFailed(f"no command of the spec drives {channel.value}")
    median = dp.CHANNELS[channel].median
    return Step(f"channel {channel.value}", True, f"{', '.join(done)}: accepted, the drone reported moving",
                look=f"the flight controller's {channel.value} input (Mission Planner, Radio Calibration) went to "
                f"each of these and back to {median} us; the pulse width is not reported over the protocol")


def _channel_step(channel: dp.ChannelName) -> Callable[[Bench], Step]:
    return lambda bench: step_channel(bench, channel)


def step_failsafe(bench: Bench) -> Step:
    """Stop sending: the drone must report its failsafe, laser off, in about FAILSAFE_TIMEOUT_MS."""
    bench.failsafes.clear()
    last = bench.sent[-1][0] if bench.sent else bench.clock()
    limit = dp.FAILSAFE_TIMEOUT_MS / 1000.0 + 1.0
    bench.silence(limit, lambda: bool(bench.failsafes))
    if not bench.failsafes:
        raise StepFailed(f"nothing sent for {limit:g} s and the drone reported no failsafe: reflash the firmware "
                         "from this spec")
    after = bench.failsafes[0] - last
    if bench.view.state is not S.FAILSAFE or bench.view.laser is not False:
        raise StepFailed(f"the failsafe reply reports {bench.view.describe()}, not failsafe with the laser off")
    return Step("failsafe", True, f"reported after {after:.2f} s without a frame (spec: "
                f"{dp.FAILSAFE_TIMEOUT_MS} ms), laser off, disarmed",
                look=f"the throttle went to {dp.FAILSAFE_THROTTLE_US} us: the flight controller's radio failsafe "
                "(it disarms on the ground)")


def make_safe(bench: Bench) -> Step:
    """Laser off and disarmed, confirmed by the drone (an airborne state is left to the failsafe first)."""
    try:
        reply = bench.exchange(dp.laser_off())
        if reply.state in (S.HOLD_ALTITUDE, S.MOVING, S.LANDING):  # the firmware refuses a disarm there
            bench.silence(dp.FAILSAFE_TIMEOUT_MS / 1000.0 + 1.0, lambda: bench.view.state is S.FAILSAFE)
        # on the ground, or after a failsafe: the disarm sticks, so that the flight controller disarms too
        bench.exchange(dp.disarm())
        bench.wait_state(S.DISARMED, dp.ARMING_HOLD_MS / 1000.0 + 1.0)
        reply = bench.exchange(dp.laser_off())
    except StepFailed as exc:
        return Step("safe", False, f"could not confirm the drone disarmed with the laser off ({exc}): unplug the "
                    "flight battery")
    if bench.view.safe:
        return Step("safe", True, f"the drone confirmed: {_state(reply)}")
    return Step("safe", False, f"the drone reports {bench.view.describe()}: unplug the flight battery")


def checklist(bench: Bench, report: Callable[[Step], None] = lambda step: None) -> list[Step]:
    """Every step in order, each reported as it ends, stopping at the first failure; then the safe end, always."""
    steps = _Steps(report)
    plan: list[tuple[str, Callable[[Bench], Step]]] = [
        ("status", step_status), ("laser", step_laser), ("servos", step_servos), ("arming", step_arming),
        *((f"channel {c.value}", _channel_step(c)) for c in dp.ChannelName), ("failsafe", step_failsafe),
    ]
    try:
        for name, run in plan:
            try:
                steps.append(run(bench))
            except StepFailed as exc:
                steps.append(Step(name, False, str(exc)))
                break
    finally:
        steps.append(make_safe(bench))
    return list(steps)


class _Steps(list[Step]):
    """The steps so far; each one reported as it is added."""

    def __init__(self, report: Callable[[Step], None]) -> None:
        super().__init__()
        self._report = report

    def append(self, step: Step) -> None:
        super().append(step)
        self._report(step)
