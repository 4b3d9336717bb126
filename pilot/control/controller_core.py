"""The controller's core: its states, the pilot's view of the drone, the laser, arming and landing.

The vision-driven phases (SEARCH .. FIRE) are in ``pilot.control.controller``; everything that keeps the drone
safe whatever the camera sees is here, driven by what the drone's replies confirm (``DroneView``).
"""

from __future__ import annotations

import enum
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import drone_protocol as dp

from ..common.config import ControllerConfig
from ..link.drone_view import DroneView
from ..vision.detection import Detection
from .pulses import StickModel


class State(enum.Enum):
    IDLE = "idle"
    ARM = "arm"
    TAKEOFF = "takeoff"
    HOLD = "hold"
    SEARCH = "search"
    ACQUIRE = "acquire"
    TRACK = "track"
    AIM = "aim"
    FIRE = "fire"
    LAND = "land"
    DONE = "done"


FLYING = frozenset({State.TAKEOFF, State.HOLD, State.SEARCH, State.ACQUIRE, State.TRACK, State.AIM, State.FIRE})
LOCKED = frozenset({State.ACQUIRE, State.TRACK, State.AIM, State.FIRE})
RESET_ERROR = 0.4  # a servo reset in TRACK may leave the target this far off the middle (of the half-width)
# a servo step shows in the frames only this long after it is sent: a frame is 30-120 ms old when the pilot reads it
# (one camera period more after a dropped frame), the servo slews 0.1-0.2 s per 60°, and the step goes out at a tick
SERVO_SEEN_MS = 200


@dataclass(frozen=True)
class Transition:
    t_ms: int
    old: State
    new: State
    reason: str


def speed_for(command: dp.CommandName, fraction: float, pulses: StickModel) -> int:
    """A speed for ``command`` at ``fraction`` (0..2) of a control step beyond its channel median (the pulse offset
    ``pulses`` derives from the spec), in the command's own sense and clamped to its allowed range."""
    spec = dp.COMMANDS[command]
    channel = dp.ChannelName(spec.target)
    median = dp.CHANNELS[channel].median
    default = spec.default if spec.default is not None else median
    sense = 1 if default >= median else -1
    value = median + sense * round(pulses.unit_us(channel, sense > 0) * max(0.0, fraction))
    return max(spec.minimum, min(spec.maximum, value))


def turn_towards(error_x: float, pulses: StickModel) -> bytes:
    """A turn towards a horizontal error (-1 .. +1 of the half-width): gentle near the middle, full from half-way."""
    frac = 0.35 + 0.65 * min(1.0, abs(error_x) / 0.5)
    if error_x > 0:
        return dp.turn_right(speed_for(dp.CommandName.TURN_RIGHT, frac, pulses))
    return dp.turn_left(speed_for(dp.CommandName.TURN_LEFT, frac, pulses))


class ControllerCore:
    def __init__(
        self,
        config: ControllerConfig | None = None,
        clock: Callable[[], float] = time.monotonic,
        parameters: Mapping[str, float] = dp.FLIGHT_CONTROLLER_PARAMETERS,
    ) -> None:
        self.cfg = config or ControllerConfig()
        self.pulses = StickModel(self.cfg, parameters)  # a control step's pulse on each stick, from the spec
        self._clock = clock
        self.state = State.IDLE
        self.transitions: list[Transition] = []
        self.drone = DroneView()  # what the drone's replies confirmed
        self.want_laser = False  # the pilot's intent: on only while firing
        self._laser_sent: bool | None = None  # the last laser command sent (used only while no status arrives)
        self.lit_ms = 0  # time the drone confirmed its laser on while the pilot wanted it, since FIRE began
        self._accounted_ms = self._now()
        self._armed_at_ms: int | None = None
        self._land_sent = False
        self._emergency = False
        self.fired = False  # the laser was on at the target for the whole fire time
        self.last_command: bytes | None = None
        self.polling = False  # this tick's frame is a status poll (the runner sends it more than once)
        self._entered_ms = self._now()
        self._land_clock_ms = self._now()  # LAND's time limit counts from here (the firmware's routine's start)
        self._hits = 0
        self._misses = 0
        self._centred = 0
        self._search_sign = 1  # +1 right, -1 left
        self._fire_started_ms = 0
        self._sent_entry = False
        self._coast: bytes | None = None
        self._search_started_ms = self._now()
        self._pan_offset = 0  # degrees the pilot has moved the pan servo from its default
        self._tilt_offset = 0
        self._servo_steps: dict[bool, tuple[int, float]] = {}  # by axis (True: across): the last step's time, degrees
        tan_h = math.tan(math.radians(self.cfg.horizontal_fov_deg) / 2.0)
        self._tan_h = tan_h

    # -- helpers -----------------------------------------------------------------------------
    def _now(self) -> int:
        return round(self._clock() * 1000.0)

    def _elapsed(self) -> int:
        return self._now() - self._entered_ms

    def _go(self, new: State, reason: str) -> None:
        if new is self.state:
            return
        self.transitions.append(Transition(self._now(), self.state, new, reason))
        if new is State.SEARCH and self.state is not State.ACQUIRE:
            self._search_started_ms = self._now()  # a sighting that is not confirmed does not restart the sweep
        self.state = new
        self._entered_ms = self._land_clock_ms = self._now()
        self._sent_entry = False
        self._hits = 0 if new is State.SEARCH else self._hits
        self._misses = 0
        self._coast = None
        self._centred = 0

    def _speed(self, command: dp.CommandName, fraction: float) -> int:
        return speed_for(command, fraction, self.pulses)

    def _emit(self, frame: bytes) -> bytes:
        self.last_command = frame
        return frame

    def _laser(self, on: bool) -> bytes | None:
        """Want the laser on or off: the deterministic command when the drone does not confirm it yet."""
        self.want_laser = on
        if self.drone.laser is None:  # no status yet: say it once per change
            if self._laser_sent is on:
                return None
        elif self.drone.laser is on:
            return None
        self._laser_sent = on
        return self._emit(dp.laser_on() if on else dp.laser_off())

    def _laser_fix(self) -> bytes | None:
        """The drone reports another laser state than the pilot wants: correct it before anything else."""
        if self.drone.laser is None or self.drone.laser is self.want_laser:
            return None
        return self._laser(self.want_laser)

    def _account(self) -> None:
        """Lit time: the drone confirmed the laser on while the pilot wanted it (its intent in a dry run)."""
        now = self._now()
        lit = self.drone.laser if self.drone.laser is not None else self.want_laser
        if lit and self.want_laser:
            self.lit_ms += now - self._accounted_ms
        self._accounted_ms = now

    @property
    def laser_on(self) -> bool | None:
        """The laser as the drone confirmed it (None: no status yet)."""
        return self.drone.laser

    @property
    def flying(self) -> bool:
        return self.state in FLYING or self.state is State.ARM

    # -- external events -----------------------------------------------------------------------
    def start(self) -> None:
        if self.state is State.IDLE:
            self._go(State.ARM, "start")

    def on_reply(self, reply: dp.Reply) -> None:
        """A reply: its status is the pilot's view of the drone. In flight, a drone that reports a failsafe
        or no longer armed is landed (the LAND state ends at once when it confirms it is not armed)."""
        self.drone.update(reply, self._now())
        if self.state not in FLYING:
            return
        if reply.kind is dp.ReplyKind.FAILSAFE:
            self._go(State.LAND, "firmware failsafe")
        elif reply.kind is dp.ReplyKind.REJECTED and reply.error is dp.ErrorKind.NOT_ARMED:
            self._go(State.LAND, "firmware says not armed")
        elif self.drone.armed is False:
            self._go(State.LAND, f"drone reports {self.drone.describe()}")

    def abort(self, reason: str) -> None:
        """Stop the mission: land (see LAND); the caller keeps calling ``update`` until DONE. Nothing more
        once DONE: landing already ended there, confirmed or timed out."""
        self.want_laser = False
        if self.state is State.IDLE:
            self._go(State.DONE, f"abort: {reason}")
        elif self.state is not State.DONE:
            self._go(State.LAND, f"abort: {reason}")

    def emergency(self) -> None:
        """Asked to stop again while landing: the shortest sequence the firmware accepts (laser off, land,
        keep-alives until confirmed disarmed), and stop as soon as the drone has not answered for its
        failsafe time."""
        self._emergency = True
        if self.state is not State.LAND:
            self._go(State.LAND, "emergency")

    @property
    def gave_up(self) -> bool:
        """Landing: no status for the firmware's failsafe time after an emergency; it is failsafing."""
        if not self._emergency or self.state is not State.LAND:
            return False
        since = self.drone.last_ms if self.drone.last_ms is not None else self._entered_ms
        return self._now() - max(since, self._entered_ms) >= dp.FAILSAFE_TIMEOUT_MS

    # -- the state machine -----------------------------------------------------------------------
    def update(self, det: Detection | None) -> bytes | None:
        """One frame's decision. ``det`` is None when there is no frame this tick."""
        self._account()
        self.polling = False
        if self.state is State.LAND and (self._now() - self._land_clock_ms >= self.cfg.land_ms or self.gave_up):
            # stop sending: the firmware's failsafe (laser off, failsafe throttle) takes over
            self._go(State.DONE, f"drone did not confirm it disarmed ({self.drone.describe()})")
            return None
        fix = self._laser_fix()
        if fix is not None:
            return fix
        return self._decide(det)

    def _decide(self, det: Detection | None) -> bytes | None:
        handler = getattr(self, f"_on_{self.state.value}")
        result: bytes | None = handler(det)
        return result

    # -- the camera's geometry: bearings, servo steps ------------------------------------------------
    def _tan_v(self, det: Detection) -> float:
        return self._tan_h * (det.height / det.width) if det.width else self._tan_h

    def _bearing(self, det: Detection) -> float:
        """The target's bearing from the body's axis, degrees right (the camera's pan included)."""
        return self._pan_offset + math.degrees(math.atan(det.error_x * self._tan_h))

    def _remember_side(self, det: Detection) -> None:
        """Which way to sweep if the target is lost: its bearing from the body."""
        self._search_sign = 1 if self._bearing(det) >= 0 else -1

    def _servo_correction(self, det: Detection) -> bytes | None:
        """One pan or tilt step towards the target, the larger error first; None when centred. A step not yet
        seen (``SERVO_SEEN_MS``) is taken out of its axis' error first: the frame may predate it, and the same step
        again would overshoot (a hold while it shows, ``_owed``)."""
        ex, ey = det.error_x, det.error_y
        tol = self.cfg.aim_tolerance
        tan_v = self._tan_v(det)
        if abs(ex) <= tol and abs(ey) <= tol:
            return None
        # degrees each axis must still turn (pan right, tilt up), and the tolerance in degrees
        pan = self._owed(True, math.degrees(math.atan(ex * self._tan_h)), math.degrees(math.atan(tol * self._tan_h)))
        tilt = self._owed(False, math.degrees(math.atan(-ey * tan_v)), math.degrees(math.atan(tol * tan_v)))
        if not pan and not tilt:
            return self._emit(dp.hold_altitude())  # the last step has not shown yet
        across = bool(pan) and (not tilt or abs(ex) >= abs(ey))  # the pan servo's axis, else the tilt's
        turn = pan if across else tilt
        deg = max(1, round(abs(turn)))
        self._servo_steps[across] = (self._now(), math.copysign(deg, turn))
        if across:
            self._pan_offset += deg if turn > 0 else -deg
            return self._emit(dp.servo_right(deg) if turn > 0 else dp.servo_left(deg))
        self._tilt_offset += deg if turn > 0 else -deg
        return self._emit(dp.servo_up(deg) if turn > 0 else dp.servo_down(deg))

    def _owed(self, axis: bool, seen_deg: float, tol_deg: float) -> float:
        """The step still due on ``axis`` (0: none): the error seen, less a step that may not show yet; while one
        may not, only more of the same way past the tolerance (never back: the frame may show it already)."""
        last = self._servo_steps.get(axis)
        if last is None or self._now() - last[0] >= SERVO_SEEN_MS:
            return seen_deg if abs(seen_deg) > tol_deg else 0.0
        rest = seen_deg - last[1]
        return rest if rest * last[1] > 0.0 and abs(rest) > tol_deg else 0.0

    def _turn_to_camera(self, det: Detection) -> bytes | None:
        """With the camera panned, the turn that brings the body round to the target until a servo reset would
        leave it within ``RESET_ERROR`` of the frame's middle (None: reset now)."""
        bearing = max(-80.0, min(80.0, self._bearing(det)))  # (the servo's own limit is nearer; past 90° tan turns)
        after = math.tan(math.radians(bearing)) / self._tan_h  # the horizontal error a reset would leave
        return None if abs(after) <= RESET_ERROR else turn_towards(after, self.pulses)

    def _on_idle(self, det: Detection | None) -> bytes | None:
        return None

    def _on_done(self, det: Detection | None) -> bytes | None:
        return None

    def _on_arm(self, det: Detection | None) -> bytes | None:
        if not self._sent_entry:
            self._sent_entry = True
            self._armed_at_ms = None
            return self._emit(dp.arm())
        state = self.drone.state
        # no drone answers (a dry run): go on after the firmware's arming hold
        armed = self._elapsed() >= dp.ARMING_HOLD_MS if state is None else state in dp.ARMED_STATES
        if armed:
            if self._armed_at_ms is None:
                self._armed_at_ms = self._now()
            if self._now() - self._armed_at_ms >= self.cfg.arm_margin_ms:
                why = f"drone confirmed armed ({state.name.lower()})" if state else "armed (unconfirmed)"
                self._go(State.TAKEOFF, why)
                return self._on_takeoff(det)
            if state is dp.DroneState.ARMED:
                return self._emit(dp.hold_altitude())  # AltHold, sticks neutral, before the climb
            return self._status_poll()
        if self._elapsed() >= 2 * dp.ARMING_HOLD_MS + dp.FAILSAFE_TIMEOUT_MS + self.cfg.arm_margin_ms:
            self._go(State.LAND, f"drone never confirmed armed ({self.drone.describe()})")
            return self._on_land(det)
        if state in (dp.DroneState.DISARMED, dp.DroneState.FAILSAFE):
            return self._emit(dp.arm())  # the arm frame (or its reply) was lost: again
        return self._status_poll()

    def _status_poll(self) -> bytes | None:
        """Waiting for the drone to confirm a change: the status query every tick, since only a reply tells (it
        changes nothing and is never refused); nothing when no drone answers (a dry run)."""
        if self.drone.state is None:
            return None
        self.polling = True
        return self._emit(dp.query_status())

    def _on_takeoff(self, det: Detection | None) -> bytes | None:
        if self._elapsed() >= self.cfg.takeoff_ms:
            self._go(State.HOLD, "take-off climb done")
            return self._on_hold(det)
        return self._emit(dp.move_up(self._speed(dp.CommandName.MOVE_UP, 1.0)))

    def _on_hold(self, det: Detection | None) -> bytes | None:
        if self._elapsed() >= self.cfg.settle_ms:
            self._go(State.SEARCH, "altitude held")
            return self._on_search(det)
        return self._emit(dp.hold_altitude())

    def _on_search(self, det: Detection | None) -> bytes | None:
        raise NotImplementedError  # the vision phases: pilot.control.controller.Controller

    def _on_land(self, det: Detection | None) -> bytes | None:
        off = self._laser(False)
        if off is not None:
            return off
        if (self._pan_offset or self._tilt_offset) and not self._emergency:
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        state = self.drone.state
        if state is None:  # no drone answers (a dry run): the landing routine once
            if self._land_sent:
                self._go(State.DONE, "land sent (no status to confirm it)")
                return None
            self._land_sent = True
            return self._emit(dp.land())
        owed = self.drone.disarm_owed_since_ms
        if owed is not None and state is dp.DroneState.DISARMED:
            # the rebooted board holds the failsafe throttle, so the flight controller lands on its own: after the
            # landing routine's time it is down, and then sees the disarm sticks too (it disarms only on the ground)
            return self._emit(dp.disarm()) if self._now() - owed >= dp.LANDING_MS else self._status_poll()
        if self.drone.safe:
            self._go(State.DONE, f"drone confirmed {self.drone.describe()}")
            return None
        if state is dp.DroneState.ARMED and not self.drone.refused_airborne:
            return self._emit(dp.disarm())  # armed on the ground: the plain disarm is shorter
        if state in dp.ARMED_STATES and state not in (dp.DroneState.LANDING, dp.DroneState.DISARMING):
            return self._emit(dp.land())
        return self._status_poll()  # landing, disarming, arming, self-test: until it ends
