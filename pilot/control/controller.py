"""The pilot's decision logic: one explicit state machine over detections, with an injected clock.

``Controller.update(detection)`` is called once per frame and returns the frame to send now (or ``None``: the link
keeps the firmware alive). Every frame is built by a ``drone_protocol`` function; every pulse comes from the spec
(``pulses.py``). The vision phases (SEARCH .. FIRE) are here, arming and landing in ``controller_core.py``::

    IDLE -> ARM -> TAKEOFF -> HOLD -> SEARCH <-> ACQUIRE -> TRACK <-> AIM -> FIRE -> LAND -> DONE

The drone's state and laser are only what its replies confirmed (``DroneView``). What each state does and why:
pilot/README.md, "The controller".
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping

import drone_protocol as dp

from ..common.config import FIRE_RANGE_SHARE, ControllerConfig
from ..vision.detection import Detection
from ..vision.gating import Gate, centred
from .approach import ClosingSpeed, Lead, Lean, Momentum, allowed_speed, brake_steps
from .controller_core import FLYING, LOCKED, ControllerCore, State, Transition, turn_towards
from .descent import DESCENT_STEPS, Descent
from .lock import Lock
from .response import TurnResponse, turn_sense
from .search import Look, glimpse, return_sense, sweep_sense
from .sticks import HeldSticks
from .trim import DriftHold
from .vertical import Height, SeenFrom

__all__ = ["FLYING", "LOCKED", "Controller", "State", "Transition"]

HOLD_MPS = 0.12  # closing speeds within this are left alone near the target (the estimate's noise)
VIEW_EDGE = 0.9  # a brake's lean keeps the target's lower edge above this share of the frame's lower half
MIN_BRAKE = 0.4  # control steps: the gentlest brake, whatever the view allows
TRIMMED = FLYING - {State.TAKEOFF}  # the states that lean against the drift (the take-off's climb takes every frame)
HELD = frozenset({State.ACQUIRE, State.AIM, State.FIRE})  # no approach commanded: the closing speed is drift
PITCH_CALM_MS = 1500  # ... once the pilot's own pitch has been neutral this long (a brake's lean and speed gone)


class Controller(ControllerCore):
    def __init__(self, config: ControllerConfig | None = None, clock: Callable[[], float] = time.monotonic,
                 parameters: Mapping[str, float] = dp.FLIGHT_CONTROLLER_PARAMETERS) -> None:
        super().__init__(config, clock, parameters)
        self.gate = Gate(self.cfg)  # vision gate (issue 12): every sighting and every laser-on goes through it
        self.closing = ClosingSpeed()
        # the same over 1.2 s, for the speed at a loss: a target going out of sight (covered, clipped by the
        # frame's edge) shrinks in its last frames, and the short fit then reads a closing speed near zero
        self.closing_trend = ClosingSpeed(window_s=1.2, min_samples=8)
        self.momentum = Momentum(self.cfg.pitch_accel_mps2)
        # the same from the commands alone, never reset by vision: a target being covered keeps its size while the
        # drone flies on, and vision's speed then drops to zero just before the loss
        self.reckoned = Momentum(self.cfg.pitch_accel_mps2)
        self.lean = Lean(self.cfg.pitch_accel_mps2)
        self.lead = Lead(self.cfg.pitch_accel_mps2)
        self.height = Height(self.cfg.climb_mps_per_step)
        self.seen_from = SeenFrom()
        self._return_m: float | None = None  # a search first goes back to this height
        self.sticks = HeldSticks(self.pulses)
        self.response = TurnResponse()
        self._turned = 0  # the last frame's hard turn (+1 right, -1 left), whose effect this frame shows
        self._last_ms = self._now()
        self._brake_until_ms = 0  # target lost while closing in: brake this long before searching
        self._brake_speed = 0.0
        self.drift = DriftHold(self.pulses, self.cfg.unit_lean_deg)
        self._pitch_calm_ms = self._now()
        self.descent = Descent(self.cfg.climb_mps_per_step)  # LAND's own descent, before the firmware's routine
        self.look, self.lock, self._sighted = Look(), Lock(), False  # _sighted: this frame's, the lock's kept too

    def _hold_range(self, det: Detection) -> bytes | None:
        """Near the target nothing holds position but the pilot: brake a closing speed, nudge forward against a
        receding one; None while the range holds (within ``HOLD_MPS``)."""
        closing = self._closing_now()
        if closing is None or abs(closing) <= HOLD_MPS:
            return None
        if closing > 0.0:
            return self._brake(closing, det)
        return self._emit(dp.move_forward(self._speed(dp.CommandName.MOVE_FORWARD, min(1.2, 0.6 - closing))))

    def _closing_now(self) -> float | None:
        """The closing speed's fit, plus what the pitch commands since the frames it rests on added (``Lead``)."""
        closing = self.closing.closing
        return None if closing is None else closing + self.lead.speed

    def _brake(self, speed: float, det: Detection | None = None) -> bytes:
        """Pitch back against a closing speed (``approach.brake_steps``), with the target in view no harder than
        keeps it in the frame (the nose comes up with the brake, see ``_brake_room``)."""
        frac = brake_steps(speed)
        if det is not None and det.found:
            frac = max(MIN_BRAKE, min(frac, self._brake_room(det)))
        return self._emit(dp.move_backward(self._speed(dp.CommandName.MOVE_BACKWARD, frac)))

    def _brake_room(self, det: Detection) -> float:
        """The backward lean, in control steps, that keeps the target's lower edge within ``VIEW_EDGE`` of the
        frame: the target moves down the frame by the change from the present lean."""
        tan_v = self._tan_v(det)
        edge = det.error_y + (det.size / det.height if det.height else 0.0)
        room_deg = math.degrees(math.atan(VIEW_EDGE * tan_v) - math.atan(edge * tan_v))
        return (room_deg - self.lean.deg) / self.lean.deg_per_step

    def _decide(self, det: Detection | None) -> bytes | None:
        now = self._now()
        held = self.sticks.pitch(now)
        dt = (now - self._last_ms) / 1000.0
        self.momentum.advance(held, dt)
        self.reckoned.advance(held, dt)
        self.lean.advance(held, dt)
        self.lead.advance(held, dt)
        self.height.advance(self.sticks.throttle(now), dt)
        self._last_ms = now
        if det is not None and det.found and self.state in LOCKED:
            self.closing.update(now / 1000.0, det.range_m, det.size)
            self.closing_trend.update(now / 1000.0, det.range_m, det.size)
            self.momentum.observe(self.closing.closing, self.closing.error)
        elif self.state not in LOCKED and self.state is not State.SEARCH:
            self.closing.reset()
            self.closing_trend.reset()
            self.momentum.reset()
            self.reckoned.reset()
        cx = det.cx if det is not None and det.found and not det.predicted else None
        if self.state is not State.TRACK:
            self.response.reset()
        elif self.response.observe(now, self._turned, cx, det.width if det is not None else 0):
            self._go(State.LAND, "the drone does not answer the yaw stick (the target stood still through a hard "
                                 "turn): crashed or caught on something")
        frame = self._decide_frame(det)
        if det is not None and self.gate.acquired() and not det.predicted:
            self.seen_from.saw(self.height.m)
        self.sticks.sent(frame, self._now())  # dead reckoning: the controller's own commands, not the trim
        frame = self._trimmed(frame, det)
        self._turned = turn_sense(frame, self.pulses)
        return frame

    def _trimmed(self, frame: bytes | None, det: Detection | None) -> bytes | None:
        """Learn the drift from the target's sightings and lean against it (``trim.py``)."""
        seen = self.state in FLYING and det is not None and self._found(det) and not det.predicted
        sighting = (det.range_m, self._bearing(det)) if seen and det is not None else None
        # the closing speed is the drift's only where no pitch of the pilot's own is still carrying the drone on
        if self.sticks.pitch(self._now()) or self.state not in HELD:
            self._pitch_calm_ms = self._now()
        calm = self._now() - self._pitch_calm_ms >= PITCH_CALM_MS
        closing = self.closing.closing if calm else None
        shaped = self.drift.step(frame, self._now(), sighting, closing, self.state in TRIMMED)
        if shaped is not frame and shaped is not None:
            self.last_command = shaped
        return shaped

    def _decide_frame(self, det: Detection | None) -> bytes | None:
        # -- vision gate (issue 12): a bad frame holds (laser off), too many in a row land ------------
        self.gate.observe(det)
        self._sighted = self.lock.sighted(det, self.gate.acquired(), self.state in LOCKED, self.cfg.acquire_confidence)
        if self.gate.fault is not None and self.state in FLYING - {State.TAKEOFF, State.HOLD}:
            if self.gate.fault_frames >= self.cfg.blind_frames:
                off = self._laser(False)
                self._go(State.LAND, f"camera: {self.gate.fault.value} frames")
                return off if off is not None else self._on_land(det)
            off = self._laser(False)
            return off if off is not None else self._emit(dp.hold_altitude())
        # -- end of the vision gate --------------------------------------------------------------------
        return super()._decide(det)

    def _found(self, det: Detection | None) -> bool:
        return det is not None and det.found and self._sighted  # vision gate: confident enough (or kept)

    def _on_search(self, det: Detection | None) -> bytes | None:
        if self._found(det):
            self._go(State.ACQUIRE, "target seen")
            return self._on_acquire(det)
        if self._now() < self._brake_until_ms:
            return self._brake(self._brake_speed)
        if self._now() - self._search_started_ms >= self.cfg.search_max_ms:
            self._go(State.LAND, "search sweep exhausted")
            return self._on_land(det)
        if self._pan_offset or self._tilt_offset:
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        if self.look.holds(self._now(), glimpse(det, self.cfg.acquire_confidence)):  # turn after it, gently
            off = det.error_x if det is not None and det.found and abs(det.error_x) > self.cfg.dead_band_x else 0.0
            return self._emit(turn_towards(off, self.pulses) if off else dp.hold_altitude())
        sense = self._height_move()
        if sense:
            return self._emit(dp.move_up(self._speed(dp.CommandName.MOVE_UP, 1.0)) if sense > 0 else
                              dp.move_down(self._speed(dp.CommandName.MOVE_DOWN, 1.0)))
        if self._search_sign > 0:
            return self._emit(dp.turn_right(self._speed(dp.CommandName.TURN_RIGHT, 1.0)))
        return self._emit(dp.turn_left(self._speed(dp.CommandName.TURN_LEFT, 1.0)))

    def _go(self, new: State, reason: str) -> None:
        if new is State.SEARCH and self.state is not State.SEARCH:
            self.seen_from.lost(self.height.m)
            self._return_m = self.seen_from.return_to()
        if new is State.LAND and self.state in FLYING:
            self.descent.begin(self._now(), self.height.m, self.drone.state)
        super()._go(new, reason)

    def abort(self, reason: str) -> None:
        """A stop (the user's, or an error): the firmware's landing routine at once, no descent of the pilot's."""
        super().abort(reason)
        self.descent.cancel()

    def _on_land(self, det: Detection | None) -> bytes | None:
        """Down to ``LAND_FROM_M`` under the pilot's own sticks first (the laser off and the servos home before),
        then the firmware's landing routine (``ControllerCore._on_land``), whose time limit starts then."""
        if self.descent.active:
            if self._emergency or self.descent.over(self._now(), self.height.settles_m, self.drone.state):
                self.descent.cancel()
                self._land_clock_ms = self._now()
            elif self.want_laser or self.drone.laser or self._pan_offset or self._tilt_offset:
                return super()._on_land(det)  # laser off, servos home: the core's first steps
            else:
                return self._emit(dp.move_down(self._speed(dp.CommandName.MOVE_DOWN, DESCENT_STEPS)))
        return super()._on_land(det)

    def _height_move(self) -> int:
        """The search's climb (+1) or descent (-1), or 0 (turn): back to where it was seen first (``search.py``)."""
        if self._return_m is not None:
            sense = return_sense(self._return_m, self.height.settles_m, self._elapsed())
            if sense:
                return sense
            self._return_m = None
        return sweep_sense(self._now() - self._search_started_ms, self.cfg.search_leg_ms, self.cfg.search_step_ms)

    def _lost(self, det: Detection | None, limit: int) -> bool:
        if self._found(det):
            self._misses = 0
            return False
        self._misses += 1
        return self._misses >= limit

    def _to_search(self, reason: str) -> bytes | None:
        """Target lost: laser off first, then sticks neutral, then the servos home, then search; lost while
        closing in, the search starts by braking for as long as the last closing speed needs."""
        off = self._laser(False)
        # vision's last estimate carried on by dead reckoning, the commands' own reckoning, or the longer trend:
        # whichever is fastest, vision's less their standard errors (``approach.py``: far, a fit swings by 1 m/s)
        closing = max(self.momentum.sure, self.reckoned.speed, self.closing_trend.sure or 0.0)
        if closing > 0.15:
            # as long as that brake takes to stop it (plus the lean's lag), not longer: a brake held on flies the
            # drone backwards into whatever is behind it, where the camera does not look
            decel = self.cfg.pitch_accel_mps2 * brake_steps(closing)
            self._brake_until_ms = self._now() + round(1000.0 * (closing / decel + self.lean.lag_s))
            self._brake_speed = closing
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
            return self._hold(det)
        self._hits = 0  # the sightings must be consecutive
        self._misses += 1
        if self._misses >= self.cfg.lost_frames:  # hovering, a flickering far target gets a few chances
            self._go(State.SEARCH, "sighting not confirmed")
        return self._hold(det)

    def _hold(self, det: Detection | None) -> bytes | None:
        """Sticks neutral while a sighting is confirmed, unless the brake planned at a loss is not over: a target
        seen again at once (half covered, flickering) would otherwise let the drone coast on into what covers it."""
        if self._now() < self._brake_until_ms:
            return self._brake(self._brake_speed, det)
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
            turn = self._turn_to_camera(det)  # the body first, where a reset would lose the target
            if turn is not None:
                return self._emit(turn)
            self._pan_offset = self._tilt_offset = 0
            return self._emit(dp.servo_reset())
        ex, ey, size = det.error_x, det.error_y, det.relative_size
        self._remember_side(det)
        if size >= cfg.approach_size:  # close enough whatever else is off: AIM centres it with the servos
            self._go(State.AIM, f"close enough (size {size:.3f})")
            return self._on_aim(det)
        closing, allowed, error = self._closing_now(), cfg.approach_speed_mps, self.closing.error
        if closing is None or error is None:  # too few consistent ranges yet: the speed its own pitch commands gave it
            closing, error = self.momentum.speed, self.momentum.error
        if det.range_m > 0.0:
            # the range still to go before the aim range (range scales as 1/size), and the speed allowed there
            allowed = allowed_speed(det.range_m * (1.0 - size / cfg.approach_size), cfg.brake_mps2,
                                    cfg.approach_speed_mps)
            if closing - error > allowed + 0.15:  # braking first, for the speed shown for certain (approach.py)
                return self._brake(closing - error - allowed, det)
        if abs(ex) > cfg.dead_band_x:
            return self._emit(turn_towards(ex, self.pulses))
        if abs(ey) > cfg.dead_band_y and not self.seen_from.barred(ey < 0, self.height.settles_m, ey):
            frac = 0.5 + 0.5 * min(1.0, abs(ey) / 0.6)
            if ey < 0:
                return self._emit(dp.move_up(self._speed(dp.CommandName.MOVE_UP, frac)))
            return self._emit(dp.move_down(self._speed(dp.CommandName.MOVE_DOWN, frac)))
        if closing > allowed - 0.1:
            return self._emit(dp.hold_altitude())  # coasting at about the right speed
        frac = 1.8 if size < 0.45 * cfg.approach_size else (1.0 if size < 0.75 * cfg.approach_size else 0.6)
        self._coast = self._emit(dp.move_forward(self._speed(dp.CommandName.MOVE_FORWARD, frac)))
        return self._coast

    def _on_aim(self, det: Detection | None) -> bytes | None:
        if self._lost(det, self.cfg.lost_frames):
            return self._to_search("target lost while aiming")
        if det is None or not self._found(det):
            return self._emit(dp.hold_altitude())
        self._remember_side(det)
        if self._too_far(det):
            self._go(State.TRACK, f"target receded (size {det.relative_size:.3f}, {det.range_m:.2f} m)")
            return self._on_track(det)
        if det.relative_size > self.cfg.back_off_size:
            # coasted in too close (a lock lost on the way): a landing from here comes down on the target's
            # stand, so back off first (once backing away, the range hold below brakes it)
            self._centred = 0
            closing = self.closing.closing
            if closing is None or closing > -HOLD_MPS:
                return self._brake(max(0.0, closing or 0.0), det)
        hold = self._hold_range(det)
        if hold is not None:  # still coasting in (or drifting away): that first
            self._centred = 0
            return hold
        if det.predicted:
            # bridged, not seen: the prediction knows nothing of the servo step just sent (whose swing may be what
            # blurred the target away), so another step from it would repeat that one
            return self._emit(dp.hold_altitude())
        correction = self._servo_correction(det)
        if correction is not None:
            self._centred = 0
            return correction
        self._centred += 1
        # vision gate: confirmed to fire, and nothing in front of the target's middle where the ray goes
        if self._centred >= self.cfg.aim_frames and self.gate.confirmed() and det.aim_on_target is not False:
            self._go(State.FIRE, "locked and centred")
            self._fire_started_ms = self._now()
            self.lit_ms = 0
            return self._laser(True)
        return self._emit(dp.hold_altitude())

    def _too_far(self, det: Detection) -> bool:
        """Too far to fire and hold the spot: smaller than ``retreat_size``, or further than ``FIRE_RANGE_SHARE``
        of ``fire_range_max_m`` (the range's estimate errs with the target's true size, and the drone drifts)."""
        far = det.range_m > FIRE_RANGE_SHARE * self.cfg.fire_range_max_m
        return det.relative_size < self.cfg.retreat_size or far

    def _on_fire(self, det: Detection | None) -> bytes | None:
        lit_now = self.lit_ms
        if lit_now < self.cfg.fire_ms and self._now() - self._fire_started_ms >= 4 * self.cfg.fire_ms:
            off = self._laser(False)
            self._go(State.LAND, f"laser confirmed on for only {lit_now} ms")
            return off if off is not None else self._on_land(det)
        if lit_now >= self.cfg.fire_ms:
            self.fired = True
            off = self._laser(False)
            self._go(State.LAND, f"laser on target for {lit_now} ms")
            return off if off is not None else self._on_land(det)
        if det is None or not self._found(det):
            self._misses += 1
            off = self._laser(False)  # never lit without a lock
            self.lit_ms = 0  # the fire time is one unbroken stay on the target: it starts again
            if self._misses >= self.cfg.lost_frames:
                self._go(State.SEARCH, "target lost while firing")
            return off if off is not None else self._emit(dp.hold_altitude())
        self._misses = 0
        self._remember_side(det)
        far = self._too_far(det)  # drifted back out of range (AIM approaches again)
        near = det.relative_size > self.cfg.back_off_size  # coasting into it (AIM backs off)
        blocked = det.aim_on_target is False  # something in front of the target, where the ray goes
        # off centre: the spot about to leave the target (the gate's room: the tolerance, or half its radius)
        if far or near or blocked or not centred(det, self.cfg.fire_tolerance):
            off = self._laser(False)
            why = ("out of range" if far else "too close" if near else
                   "something in front of the target" if blocked else "off centre")
            self._go(State.AIM, f"{why} while firing")
            return off if off is not None else self._on_aim(det)
        if not self.gate.confirmed():  # vision gate: found, but not confirmed in enough frames in a row
            off = self._laser(False)
            self.lit_ms = 0
            return off if off is not None else self._emit(dp.hold_altitude())
        on = self._laser(True)
        if on is not None:
            return on
        # still on the target: hold the range first (a closing speed carries the drone into it), else keep centring
        # it (a drifting drone); the laser stays on
        hold = self._hold_range(det)
        if hold is not None:
            return hold
        correction = self._servo_correction(det)
        return correction if correction is not None else self._emit(dp.hold_altitude())
