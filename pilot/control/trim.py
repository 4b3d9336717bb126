"""The airframe's level-trim error: learnt from the target, cancelled with the roll and pitch sticks.

AltHold levels what the flight controller's accelerometers call level; a level off by a fraction of a degree drifts
the airframe at up to about 0.5 m/s with centred sticks, and nothing holds position. The pilot sees the drift only
through the target: its lateral offset (range times the sine of its bearing, across the line of sight at a reference
heading) moves at the drift's sideways speed, its range at the forward one. The heading is held, or turned gently
and reckoned from the yaw commands (a drifting drone's target slides, and the tracking turns after it all the way:
learning only with the heading held, the drift was never learnt). ``Drift`` fits that sideways speed and learns the
lean that cancels both (an integral of the speeds, kept while the target is out of view). ``TrimSticks`` applies it:
the firmware drives one stick per frame and centres the others, so a frame that would centre every stick (a hold)
carries a roll or pitch trim instead, whichever axis is owed the most lean, and a pitch command carries the pitch
trim. Degrees of lean throughout; ``StickModel`` turns them into pulses from the spec.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import drone_protocol as dp

from .approach import slope
from .pulses import StickModel

LATERAL_WINDOW_S = 1.0  # the sideways speed is the slope of this much of the lateral offset
LATERAL_MIN_SAMPLES = 6
SETTLE_MS = 300  # after a hard turn or a pan step, the frames (up to 120 ms old) show the heading still moving
LEARN_DPS_PER_MPS = 1.0  # the trim's integral: degrees of lean a second per m/s of drift
DAMP_DEG_PER_MPS = 3.0  # the lean against a measured sideways speed, beyond the trim
TRIM_MAX_DEG = 2.0  # the trim learnt, at most (a drift of 0.5 m/s takes about 0.6-0.8°)
DEBT_MAX_DEG_S = 0.5  # lean owed (degrees times seconds) that carries over to the next free frame, at most
PAY_MIN_DEG_S = 0.005  # owed less than this on both axes: the hold stays a hold
# the body's heading, reckoned from the yaw commands (pulses.turn_dps, the spec's PILOT_Y_RATE), as the frames show
# it: a frame is 30-120 ms old (pilot/sim/README.md; libcamera hands one over one to three frame periods late), so
# the middle of that; a turn of 12°/s then puts at most 0.54° (2 cm at 2 m) into an offset, constant while it lasts
FRAME_AGE_S = 0.075
# a turn's start and stop lag the reckoning by rate^2 / (2 ATC_ACCEL_Y_MAX): 0.55° at half a step (17°/s at
# ArduCopter's default ATC_ACCEL_Y_MAX, 270°/s^2), 2.2° at a full step; harder turns than half a step restart the
# window and settle as before
GENTLE_TURN_STEPS = 0.5
REANCHOR_DEG = 10.0  # the window restarts past this change of heading (about 1° of lag each turn adds)
_AXES = (dp.ChannelName.ROLL, dp.ChannelName.PITCH)
_SENSE = {dp.CommandName.MOVE_RIGHT: (dp.ChannelName.ROLL, 1.0), dp.CommandName.MOVE_LEFT: (dp.ChannelName.ROLL, -1.0),
          dp.CommandName.MOVE_FORWARD: (dp.ChannelName.PITCH, 1.0),
          dp.CommandName.MOVE_BACKWARD: (dp.ChannelName.PITCH, -1.0)}
_LEAN = {axis_sense: name for name, axis_sense in _SENSE.items()}  # (axis, sense) -> the command that leans so
# a turn gives its frame to the lean owed once the debt is at its cap: tracking a drifting drone's target turns in
# every frame, and the drift then has its way while the pilot turns after it
_YIELDING = frozenset({dp.CommandName.TURN_LEFT, dp.CommandName.TURN_RIGHT})
_STICK_TARGETS = frozenset(c.value for c in dp.ChannelName)  # a command of these targets sets a stick


class Drift:
    """The trim lean (degrees, right and forward positive) that cancels the airframe's drift, learnt from the
    target's sideways and closing speeds while the heading is held."""

    def __init__(self, max_deg: float = TRIM_MAX_DEG) -> None:
        self.max_deg = max_deg
        self.right = 0.0
        self.forward = 0.0
        self._lateral: deque[tuple[float, float]] = deque()
        self._ref_deg = 0.0  # the heading the window's offsets are measured across

    def heading_moved(self) -> None:
        """The lateral offsets so far are from another reference heading (or the target was lost)."""
        self._lateral.clear()

    def see(self, t: float, range_m: float, bearing_deg: float, heading_deg: float = 0.0) -> None:
        """A sighting: the target's range and its bearing from the body's axis (right positive), the body's heading
        then (reckoned, clockwise positive): the offset is across the line of sight at the window's first heading."""
        if range_m <= 0.0 or not math.isfinite(range_m):
            return
        if not self._lateral or abs(heading_deg - self._ref_deg) > REANCHOR_DEG:
            self._lateral.clear()
            self._ref_deg = heading_deg
        self._lateral.append((t, range_m * math.sin(math.radians(bearing_deg + heading_deg - self._ref_deg))))
        while self._lateral and t - self._lateral[0][0] > LATERAL_WINDOW_S:
            self._lateral.popleft()

    @property
    def sideways(self) -> float | None:
        """The drone's speed to the right of the target's line (m/s), None until enough sightings."""
        if len(self._lateral) < LATERAL_MIN_SAMPLES:
            return None
        rate = slope(self._lateral)
        return None if rate is None else -rate  # the drone moving right moves the target left

    def learn(self, sideways: float | None, forward: float | None, dt: float) -> None:
        """Integrate the measured speeds (m/s; None: not measured) into the trim."""
        if sideways is not None:
            self.right = _clamp(self.right - LEARN_DPS_PER_MPS * sideways * dt, self.max_deg)
        if forward is not None:
            self.forward = _clamp(self.forward - LEARN_DPS_PER_MPS * forward * dt, self.max_deg)


@dataclass
class _Axis:
    held_deg: float = 0.0  # the lean the firmware's stick holds now
    own: bool = False  # ... set by a command of the controller's own (an approach, a brake): nothing is owed
    owed: float = 0.0  # degrees times seconds of lean wanted and not given


class TrimSticks:
    """Fits the wanted trim lean into the frames the controller sends (see the module's docstring)."""

    def __init__(self, pulses: StickModel, max_pulse_deg: float) -> None:
        self._pulses = pulses
        self._max_pulse_deg = max_pulse_deg  # one frame's trim lean, at most
        self._axes = {axis: _Axis() for axis in _AXES}
        self._until_ms = 0  # the firmware's sticks go neutral after its command timeout
        self._last_ms: int | None = None

    def reset(self) -> None:
        for axis in self._axes.values():
            axis.owed = 0.0

    def shape(self, frame: bytes | None, now_ms: int, right_deg: float, forward_deg: float,
              forward_trim_deg: float) -> bytes | None:
        """The frame to send instead of ``frame``, wanting a lean of ``right_deg`` and ``forward_deg`` (a pitch
        command of the controller's gets ``forward_trim_deg`` added: the trim, not the damping on top)."""
        dt = 0.0 if self._last_ms is None else max(0.0, (now_ms - self._last_ms) / 1000.0)
        self._last_ms = now_ms
        wanted = {dp.ChannelName.ROLL: right_deg, dp.ChannelName.PITCH: forward_deg}
        live = now_ms <= self._until_ms
        for name, axis in self._axes.items():
            if not (live and axis.own):
                held = axis.held_deg if live else 0.0
                axis.owed = _clamp(axis.owed + (wanted[name] - held) * dt, DEBT_MAX_DEG_S)
        command = _decode(frame)
        if command is None:
            return frame
        own = True
        saturated = max(abs(axis.owed) for axis in self._axes.values()) >= DEBT_MAX_DEG_S
        if command.name is dp.CommandName.HOLD_ALTITUDE or (saturated and command.name in _YIELDING):
            name = max(_AXES, key=lambda a: abs(self._axes[a].owed + wanted[a] * dt))
            due = self._axes[name].owed + wanted[name] * dt
            if abs(due) >= PAY_MIN_DEG_S and dt > 0.0:
                frame = self._lean_frame(name, _clamp(due / dt, self._max_pulse_deg))
                own = False
        elif command.name in (dp.CommandName.MOVE_FORWARD, dp.CommandName.MOVE_BACKWARD):
            _, sense = _SENSE[command.name]
            deg = self._pulses.lean_deg(command.value - dp.CHANNELS[dp.ChannelName.PITCH].median)
            frame = self._lean_frame(dp.ChannelName.PITCH, sense * deg + forward_trim_deg)
        self.sent(frame, now_ms, own)
        return frame

    def sent(self, frame: bytes | None, now_ms: int, own: bool = True) -> None:
        """What the firmware's roll and pitch sticks hold after ``frame`` (``own``: the controller's command)."""
        command = _decode(frame)
        if command is None:
            return
        for axis in self._axes.values():
            axis.held_deg = 0.0
            axis.own = False
        self._until_ms = now_ms + dp.COMMAND_TIMEOUT_MS
        if command.name in _SENSE:
            name, sense = _SENSE[command.name]
            median = dp.CHANNELS[name].median
            self._axes[name].held_deg = sense * self._pulses.lean_deg(command.value - median, name)
            self._axes[name].own = own

    def _lean_frame(self, name: dp.ChannelName, deg: float) -> bytes:
        offset = self._pulses.lean_offset_us(name, deg)
        median = dp.CHANNELS[name].median
        cmd = _LEAN[name, 1.0 if offset >= 0 else -1.0]
        spec = dp.COMMANDS[cmd]
        value = max(spec.minimum, min(spec.maximum, median + offset))
        return dp.command_frame(cmd, value)


def _decode(frame: bytes | None) -> dp.Command | None:
    """A stick or hold frame's command (None: no frame, or one that leaves the sticks as they are)."""
    command = _decode_any(frame)
    if command is None:
        return None
    target = dp.COMMANDS[command.name].target
    if target in _STICK_TARGETS or command.name is dp.CommandName.HOLD_ALTITUDE:
        return command
    return None


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


_TURNS = frozenset({dp.CommandName.TURN_LEFT, dp.CommandName.TURN_RIGHT})  # the body's heading moves
# the camera's pan moves: the bearing from the body (the pan included) is the same before and after, but the frames
# of the next ``SETTLE_MS`` show the old pan or the slew (30-120 ms old, the servo at 0.1-0.2 s per 60°)
_PANS = frozenset({dp.CommandName.SERVO_LEFT, dp.CommandName.SERVO_RIGHT, dp.CommandName.SERVO_RESET})


class DriftHold:
    """``Drift`` and ``TrimSticks`` together, one call a frame: learn from the sighting, then shape the frame."""

    def __init__(self, pulses: StickModel, max_pulse_deg: float) -> None:
        self.drift = Drift()
        self.sticks = TrimSticks(pulses, max_pulse_deg)
        self._pulses = pulses
        self._moved_ms = -SETTLE_MS  # when the pan last moved
        self._last_ms: int | None = None
        self.heading_deg = 0.0  # reckoned from the yaw commands sent
        self._yaw_dps = 0.0  # the yaw rate the firmware's stick holds ...
        self._yaw_until_ms = 0  # ... until its command timeout
        self._headings: deque[tuple[int, float]] = deque()  # (ms, heading) over the last FRAME_AGE_S

    def _reckon(self, now_ms: int, dt: float) -> float:
        """Advance the reckoned heading; the heading the present frame shows (``FRAME_AGE_S`` ago)."""
        if dt > 0.0 and self._last_ms is not None:
            held_s = max(0.0, min(now_ms, self._yaw_until_ms) - self._last_ms) / 1000.0
            self.heading_deg += self._yaw_dps * min(dt, held_s)
        self._headings.append((now_ms, self.heading_deg))
        shown = now_ms - round(1000.0 * FRAME_AGE_S)
        while len(self._headings) > 1 and self._headings[1][0] <= shown:
            self._headings.popleft()
        return self._headings[0][1]

    def step(self, frame: bytes | None, now_ms: int, sighting: tuple[float, float] | None,
             closing: float | None, apply: bool) -> bytes | None:
        """``sighting``: the target's range (m) and bearing from the body (degrees right) in this frame, if
        measured; ``closing``: its closing speed (m/s) where the pilot commands no approach; ``apply``: lean
        against the drift in this state (else the frame goes as it is)."""
        dt = 0.0 if self._last_ms is None else max(0.0, (now_ms - self._last_ms) / 1000.0)
        shown_deg = self._reckon(now_ms, dt)
        self._last_ms = now_ms
        sideways = None
        if sighting is None:
            self.drift.heading_moved()  # not seen: a loss, a cover, a frame the target was not confirmed in
        elif now_ms - self._moved_ms >= SETTLE_MS:
            self.drift.see(now_ms / 1000.0, sighting[0], sighting[1], shown_deg)
            sideways = self.drift.sideways
        self.drift.learn(sideways, closing, dt)
        if apply:
            right = self.drift.right - DAMP_DEG_PER_MPS * (sideways or 0.0)
            forward = self.drift.forward - DAMP_DEG_PER_MPS * (closing or 0.0)
            frame = self.sticks.shape(frame, now_ms, right, forward, self.drift.forward)
        else:
            self.sticks.reset()
            self.sticks.sent(frame, now_ms)
        self._held(_decode_any(frame), now_ms)
        return frame

    def _held(self, command: dp.Command | None, now_ms: int) -> None:
        """What the yaw stick holds after the frame sent, and when the pan moved."""
        if command is None:
            return
        if command.name in _PANS:
            self._moved_ms = now_ms
            self.drift.heading_moved()
        elif command.name in _TURNS:
            rate = self._pulses.turn_dps(command.value - dp.CHANNELS[dp.ChannelName.YAW].median)
            self._yaw_dps = rate if command.name is dp.CommandName.TURN_RIGHT else -rate
            if rate > GENTLE_TURN_STEPS * self._pulses.unit_turn_dps:
                self._moved_ms = now_ms  # a hard turn: the reckoning is not trusted across it
                self.drift.heading_moved()
            self._yaw_until_ms = now_ms + dp.COMMAND_TIMEOUT_MS
        elif dp.COMMANDS[command.name].target in _STICK_TARGETS or command.name is dp.CommandName.HOLD_ALTITUDE:
            self._yaw_dps = 0.0


def _decode_any(frame: bytes | None) -> dp.Command | None:
    if frame is None:
        return None
    try:
        return dp.decode(frame)
    except dp.ProtocolError:
        return None
