"""The pilot's decision logic: one explicit state machine over detections, with an injected clock.

``Controller.update(detection)`` is called once per frame and returns the frame to send now (or
``None``: nothing new, the link keeps the firmware alive). Every frame is built by a
``drone_protocol`` function; every time and pulse limit comes from its constants.

States (``State``)::

    IDLE -> ARM -> TAKEOFF -> HOLD -> SEARCH <-> ACQUIRE -> TRACK <-> AIM -> FIRE -> LAND -> DONE
                                        ^                    |        |      |
                                        +---- target lost ---+--------+------+   (neutral first)

* ARM sends ``arm()`` and waits the firmware's arming hold (``ARMING_HOLD_MS``) plus a margin.
* TAKEOFF climbs (``move_up``) for ``takeoff_ms``; HOLD sends ``hold_altitude()`` for ``settle_ms``.
* SEARCH turns (a bounded sweep: ``search_max_ms`` in all, unconfirmed sightings included, then LAND)
  towards the side the target was last seen.
* ACQUIRE stops turning and needs ``acquire_frames`` consecutive sightings to go on to TRACK; after
  ``lost_frames`` misses in a row it searches again.
* TRACK corrects one axis per frame: yaw while the horizontal error is outside its dead band, then
  height while the vertical error is, else forward until the apparent size reaches ``approach_size``.
  AIM begins there and returns to TRACK only below ``retreat_size`` (hysteresis). Up to ``coast_frames``
  missed frames during a forward approach keep it going (a far target flickers in and out of detection).
* AIM holds position and centres the target with the pan/tilt servos; after ``aim_frames`` centred
  frames FIRE switches the laser on. The laser stays on only while the target is found and centred;
  after ``fire_ms`` lit it is switched off and the drone lands (LAND: ``move_down`` for ``land_ms``,
  then ``disarm()``). While firing, small errors (within twice the aim tolerance) are still corrected
  with the servos; larger ones switch the laser off and go back to AIM.
* Losing the target (``lost_frames`` misses in a row) in ACQUIRE/TRACK/AIM/FIRE: laser off, sticks
  neutral (``hold_altitude()``), servos reset, and SEARCH again.
"""

from __future__ import annotations

import enum
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import drone_protocol as dp

from pilot.config import ControllerConfig
from pilot.detection import Detection
from pilot.gating import Gate


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


@dataclass(frozen=True)
class Transition:
    t_ms: int
    old: State
    new: State
    reason: str


def _speed(command: str, fraction: float) -> int:
    """A speed for ``command`` at ``fraction`` (0..2) of the spec's speed step beyond its channel median,
    in the command's own sense and clamped to its allowed range."""
    spec = dp.COMMANDS[command]
    median = dp.CHANNELS[spec.target].median
    default = spec.default if spec.default is not None else median
    sense = 1 if default >= median else -1
    value = median + sense * round(dp.SPEED_STEP_US * max(0.0, fraction))
    return max(spec.minimum, min(spec.maximum, value))


class Controller:
    def __init__(
        self,
        config: ControllerConfig | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.cfg = config or ControllerConfig()
        self._clock = clock
        self.gate = Gate(self.cfg)  # vision gate (issue 12): every sighting and every laser-on goes through it
        self.state = State.IDLE
        self.transitions: list[Transition] = []
        self.laser_on = False
        self.lit_ms = 0  # total time the laser has been on
        self.fired = False  # the laser was on at the target for the whole fire time
        self.last_command: bytes | None = None
        self._entered_ms = self._now()
        self._hits = 0
        self._misses = 0
        self._centred = 0
        self._search_sign = 1  # +1 right, -1 left
        self._fire_started_ms = 0
        self._laser_since_ms = 0
        self._sent_entry = False
        self._airborne_at_abort = False
        self._coast: bytes | None = None
        self._search_started_ms = self._now()
        self._pan_offset = 0  # degrees the pilot has moved the pan servo from its default
        self._tilt_offset = 0
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
        self._entered_ms = self._now()
        self._sent_entry = False
        self._hits = 0 if new is State.SEARCH else self._hits
        self._misses = 0
        self._coast = None
        self._centred = 0

    def _emit(self, frame: bytes) -> bytes:
        self.last_command = frame
        return frame

    def _laser(self, on: bool) -> bytes | None:
        if self.laser_on == on:
            return None
        now = self._now()
        if self.laser_on:
            self.lit_ms += now - self._laser_since_ms
        self.laser_on = on
        self._laser_since_ms = now
        return self._emit(dp.laser_toggle())

    @property
    def flying(self) -> bool:
        return self.state in FLYING or self.state is State.ARM

    # -- external events -----------------------------------------------------------------------
    def start(self) -> None:
        if self.state is State.IDLE:
            self._go(State.ARM, "start")

    def on_reply(self, reply: dp.Reply) -> None:
        """Firmware replies: a failsafe switched the laser off; a refused movement means not armed."""
        if reply.kind is dp.ReplyKind.FAILSAFE:
            if self.laser_on:
                self.lit_ms += self._now() - self._laser_since_ms
            self.laser_on = False
            if self.state in FLYING:
                self._go(State.LAND, "firmware failsafe")
        elif (
            reply.kind is dp.ReplyKind.REJECTED
            and reply.error is dp.ErrorKind.NOT_ARMED
            and self.state in FLYING
        ):
            self._go(State.LAND, "firmware says not armed")

    def abort(self, reason: str) -> None:
        """Stop the mission: the caller then sends ``safe_steps()``."""
        self._airborne_at_abort = self.state in FLYING or self.state is State.LAND
        if self.state not in (State.DONE, State.IDLE):
            self._go(State.DONE, f"abort: {reason}")

    def safe_steps(self) -> Iterator[bytes]:
        """What goes on the wire before exit, one frame per tick: laser off (if on), sticks neutral,
        servos home; if it was flying, down for ``land_ms`` (the flight controller disarms only on the
        ground, after the sticks are held there); then disarm. Timed on the injected clock."""
        off = self._laser(False)
        if off is not None:
            yield off
        yield self._emit(dp.hold_altitude())
        self._pan_offset = self._tilt_offset = 0
        yield self._emit(dp.servo_reset())
        if self._airborne_at_abort:
            start = self._now()
            for _ in range(self.cfg.land_ms // 5 + 1):  # bounded even if the clock stands still
                if self._now() - start >= self.cfg.land_ms:
                    break
                yield self._emit(dp.move_down(_speed("move_down", 1.5)))
        yield self._emit(dp.disarm())

    # -- the state machine -----------------------------------------------------------------------
    def update(self, det: Detection | None) -> bytes | None:
        """One frame's decision. ``det`` is None when there is no frame this tick."""
        # -- vision gate (issue 12): a bad frame holds (laser off), too many in a row land ------------
        self.gate.observe(det)
        if self.gate.fault is not None and self.state in FLYING - {State.TAKEOFF, State.HOLD}:
            if self.gate.fault_frames >= self.cfg.blind_frames:
                off = self._laser(False)
                self._go(State.LAND, f"camera: {self.gate.fault.value} frames")
                return off if off is not None else self._on_land(det)
            off = self._laser(False)
            return off if off is not None else self._emit(dp.hold_altitude())
        # -- end of the vision gate --------------------------------------------------------------------
        handler = getattr(self, f"_on_{self.state.value}")
        result: bytes | None = handler(det)
        return result

    def _on_idle(self, det: Detection | None) -> bytes | None:
        return None

    def _on_done(self, det: Detection | None) -> bytes | None:
        return None

    def _on_arm(self, det: Detection | None) -> bytes | None:
        if not self._sent_entry:
            self._sent_entry = True
            return self._emit(dp.arm())
        if self._elapsed() >= dp.ARMING_HOLD_MS + self.cfg.arm_margin_ms:
            self._go(State.TAKEOFF, "armed")
            return self._on_takeoff(det)
        return None

    def _on_takeoff(self, det: Detection | None) -> bytes | None:
        if self._elapsed() >= self.cfg.takeoff_ms:
            self._go(State.HOLD, "take-off climb done")
            return self._on_hold(det)
        return self._emit(dp.move_up(_speed("move_up", 1.0)))

    def _on_hold(self, det: Detection | None) -> bytes | None:
        if self._elapsed() >= self.cfg.settle_ms:
            self._go(State.SEARCH, "altitude held")
            return self._on_search(det)
        return self._emit(dp.hold_altitude())

    def _found(self, det: Detection | None) -> bool:
        return det is not None and det.found and self.gate.acquired()  # vision gate: confident enough

    def _on_search(self, det: Detection | None) -> bytes | None:
        if self._found(det):
            self._go(State.ACQUIRE, "target seen")
            return self._on_acquire(det)
        if self._now() - self._search_started_ms >= self.cfg.search_max_ms:
            self._go(State.LAND, "search sweep exhausted")
            return self._on_land(det)
        if self._pan_offset or self._tilt_offset:
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        if self._search_sign > 0:
            return self._emit(dp.turn_right(_speed("turn_right", 1.0)))
        return self._emit(dp.turn_left(_speed("turn_left", 1.0)))

    def _lost(self, det: Detection | None, limit: int) -> bool:
        if self._found(det):
            self._misses = 0
            return False
        self._misses += 1
        return self._misses >= limit

    def _to_search(self, reason: str) -> bytes | None:
        """Target lost: laser off first, then sticks neutral, then the servos home, then search."""
        off = self._laser(False)
        self._go(State.SEARCH, reason)
        return off if off is not None else self._emit(dp.hold_altitude())

    def _on_acquire(self, det: Detection | None) -> bytes | None:
        if self._found(det):
            assert det is not None
            self._hits += 1
            self._misses = 0
            self._remember_side(det)
            if self._hits >= self.cfg.acquire_frames:
                self._go(State.TRACK, f"seen in {self._hits} consecutive frames")
                return self._on_track(det)
            return self._emit(dp.hold_altitude())
        self._hits = 0  # the sightings must be consecutive
        self._misses += 1
        if self._misses >= self.cfg.lost_frames:  # hovering, a flickering far target gets a few chances
            self._go(State.SEARCH, "sighting not confirmed")
        return self._emit(dp.hold_altitude())

    def _on_track(self, det: Detection | None) -> bytes | None:
        if self._lost(det, self.cfg.lost_frames):
            return self._to_search("target lost while tracking")
        if det is None or not self._found(det):
            if self._coast is not None and self._misses <= self.cfg.coast_frames:
                return self._emit(self._coast)  # a missed frame or two (a far, flickering target): keep approaching
            return self._emit(dp.hold_altitude())
        self._coast = None
        cfg = self.cfg
        if self._pan_offset or self._tilt_offset:
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        ex, ey, size = det.error_x, det.error_y, det.relative_size
        self._remember_side(det)
        if abs(ex) > cfg.dead_band_x:
            frac = 0.35 + 0.65 * min(1.0, abs(ex) / 0.5)
            if ex > 0:
                return self._emit(dp.turn_right(_speed("turn_right", frac)))
            return self._emit(dp.turn_left(_speed("turn_left", frac)))
        if abs(ey) > cfg.dead_band_y:
            frac = 0.5 + 0.5 * min(1.0, abs(ey) / 0.6)
            if ey < 0:
                return self._emit(dp.move_up(_speed("move_up", frac)))
            return self._emit(dp.move_down(_speed("move_down", frac)))
        if size >= cfg.approach_size:
            self._go(State.AIM, f"close enough (size {size:.3f})")
            return self._on_aim(det)
        frac = 1.8 if size < 0.45 * cfg.approach_size else (1.0 if size < 0.75 * cfg.approach_size else 0.6)
        self._coast = self._emit(dp.move_forward(_speed("move_forward", frac)))
        return self._coast

    def _remember_side(self, det: Detection) -> None:
        """Which way to sweep if the target is lost: its bearing from the body (camera pan included)."""
        bearing = self._pan_offset + math.degrees(math.atan(det.error_x * self._tan_h))
        self._search_sign = 1 if bearing >= 0 else -1

    def _servo_correction(self, det: Detection) -> bytes | None:
        """One pan or tilt step towards the target, the larger error first; None when centred."""
        ex, ey = det.error_x, det.error_y
        tol = self.cfg.aim_tolerance
        tan_v = self._tan_h * (det.height / det.width) if det.width else self._tan_h
        if abs(ex) <= tol and abs(ey) <= tol:
            return None
        if abs(ex) >= abs(ey):
            deg = max(1, round(math.degrees(math.atan(abs(ex) * self._tan_h))))
            if ex > 0:
                self._pan_offset += deg
                return self._emit(dp.servo_right(deg))
            self._pan_offset -= deg
            return self._emit(dp.servo_left(deg))
        deg = max(1, round(math.degrees(math.atan(abs(ey) * tan_v))))
        if ey < 0:
            self._tilt_offset += deg
            return self._emit(dp.servo_up(deg))
        self._tilt_offset -= deg
        return self._emit(dp.servo_down(deg))

    def _on_aim(self, det: Detection | None) -> bytes | None:
        if self._lost(det, self.cfg.lost_frames):
            return self._to_search("target lost while aiming")
        if det is None or not self._found(det):
            return self._emit(dp.hold_altitude())
        self._remember_side(det)
        if det.relative_size < self.cfg.retreat_size:
            self._go(State.TRACK, f"target receded (size {det.relative_size:.3f})")
            return self._on_track(det)
        correction = self._servo_correction(det)
        if correction is not None:
            self._centred = 0
            return correction
        self._centred += 1
        if self._centred >= self.cfg.aim_frames and self.gate.confirmed():  # vision gate: confirmed to fire
            self._go(State.FIRE, "locked and centred")
            self._fire_started_ms = self._now()
            self.lit_ms = 0
            return self._laser(True)
        return self._emit(dp.hold_altitude())

    def _on_fire(self, det: Detection | None) -> bytes | None:
        lit_now = self.lit_ms + (self._now() - self._laser_since_ms if self.laser_on else 0)
        if lit_now >= self.cfg.fire_ms:
            self.fired = True
            off = self._laser(False)
            self._go(State.LAND, f"laser on target for {lit_now} ms")
            return off if off is not None else self._on_land(det)
        if det is None or not self._found(det):
            self._misses += 1
            off = self._laser(False)  # never lit without a lock
            if self._misses >= self.cfg.lost_frames:
                self._go(State.SEARCH, "target lost while firing")
            return off if off is not None else self._emit(dp.hold_altitude())
        self._misses = 0
        self._remember_side(det)
        loose = 2.0 * self.cfg.aim_tolerance
        if abs(det.error_x) > loose or abs(det.error_y) > loose:
            off = self._laser(False)
            self._go(State.AIM, "off centre while firing")
            return off if off is not None else self._on_aim(det)
        if not self.gate.confirmed():  # vision gate: found, but not confirmed in enough frames in a row
            off = self._laser(False)
            return off if off is not None else self._emit(dp.hold_altitude())
        on = self._laser(True)
        if on is not None:
            return on
        # still within the loose tolerance: keep centring it (a drifting drone), the laser stays on
        correction = self._servo_correction(det)
        return correction if correction is not None else self._emit(dp.hold_altitude())

    def _on_land(self, det: Detection | None) -> bytes | None:
        off = self._laser(False)
        if off is not None:
            return off
        if self._pan_offset or self._tilt_offset:
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        if self._elapsed() >= self.cfg.land_ms:
            self._go(State.DONE, "landed")
            return self._emit(dp.disarm())
        return self._emit(dp.move_down(_speed("move_down", 1.5)))
