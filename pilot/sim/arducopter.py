"""An emulation of ArduCopter's Stabilize, AltHold and Land modes, stick arming and radio failsafe.

It reads only the RC pulses (as the real flight controller does) and the airframe's attitude, rates and height,
and returns four motor thrusts, with ArduCopter's parameter names (``rc.py``); pilot/README.md ("The simulator")
says what each stick and mode does. An attitude off its target by more than 30° for 2 s disarms, as ArduCopter's
crash check does. Angles here are ArduCopter's (roll right, pitch nose-up and yaw clockwise positive);
``physics.py`` converts.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import drone_protocol as dp

from .rc import ANGLE_RANGE, THROTTLE_RANGE, SimParams

GRAVITY = 9.81
ARM_TICK_S = 0.1  # ArduCopter's arm_motors_check runs at 10 Hz


class Mode(enum.IntEnum):
    STABILIZE = 0
    ALT_HOLD = 2
    LAND = 9


@dataclass(frozen=True)
class Sensors:
    roll: float  # rad, right wing down positive
    pitch: float  # rad, nose up positive
    yaw: float  # rad, clockwise from above positive
    roll_rate: float  # rad/s, the same senses
    pitch_rate: float
    yaw_rate: float
    height: float  # m above the floor
    climb: float  # m/s, up positive


@dataclass(frozen=True)
class Demand:
    """What the attitude controller wants: angles (rad), yaw rate (rad/s) and collective (0..1 of full thrust)."""

    roll: float
    pitch: float
    yaw_rate: float
    collective: float
    motors_on: bool


def desired_climb_rate(params: SimParams, throttle: float) -> float:
    """AltHold's climb rate (m/s) for a throttle of 0..1000 (Copter::get_pilot_desired_climb_rate); mid-stick is
    the throttle's value halfway between its minimum and maximum (RC_Channel::get_control_mid)."""
    ch = params.sticks[dp.ChannelName.THROTTLE]
    mid = ch.range((ch.minimum + ch.maximum) / 2.0)
    dz = params["THR_DZ"]
    top, bottom = mid + dz, mid - dz
    up = params["PILOT_SPEED_UP"] / 100.0
    down = (params["PILOT_SPEED_DN"] or params["PILOT_SPEED_UP"]) / 100.0
    if throttle < bottom:
        return down * (throttle - bottom) / bottom
    if throttle > top:
        return up * (throttle - top) / (THROTTLE_RANGE - top)
    return 0.0


def desired_lean(params: SimParams, roll_in: float, pitch_in: float) -> tuple[float, float]:
    """Lean angles (rad) for stick angles of -4500..4500, with the circular ANGLE_MAX limit."""
    angle_max = params["ANGLE_MAX"]
    scale = angle_max / ANGLE_RANGE
    roll, pitch = roll_in * scale, pitch_in * scale
    total = math.hypot(roll, pitch)
    if total > angle_max:
        roll, pitch = roll * angle_max / total, pitch * angle_max / total
    return math.radians(roll / 100.0), math.radians(pitch / 100.0)


def stabilize_throttle(params: SimParams, throttle: float) -> float:
    """Stabilize's collective (0..1) for a throttle of 0..1000, mid-stick at hover (get_pilot_desired_throttle)."""
    thr = throttle / THROTTLE_RANGE
    hover = params["MOT_THST_HOVER"]
    expo = max(-0.5, min(1.0, -(hover - 0.5) / 0.375))
    return thr * (1.0 - expo) + expo * thr**3


class FlightController:
    def __init__(self, params: SimParams, mass_kg: float, max_thrust_n: float) -> None:
        self.p = params
        self.hover = mass_kg * GRAVITY / max_thrust_n  # the collective that hovers (what MOT_THST_HOVER learns)
        self.armed = False
        self.landed = True
        self.mode = Mode.STABILIZE
        self.failsafe = False
        self._arm_ticks = 0
        self._disarm_ticks = 0
        self._clock = 0.0
        self._next_tick = 0.0
        self._land_timer = 0.0
        self._crash_timer = 0.0
        self._mode_pwm = -1.0
        self._climb_cmd = 0.0  # m/s, slewed by PILOT_ACCEL_Z
        self._alt_target = 0.0
        self._roll = 0.0  # shaped lean targets, rad
        self._pitch = 0.0
        self._yaw_rate = 0.0  # shaped yaw rate target, rad/s

    # -- the sticks --------------------------------------------------------------------------------------
    def _arming(self, throttle_zero: bool, yaw_in: float, dt: float) -> None:
        """ArduCopter's stick (dis)arming runs at 10 Hz and counts its ticks: the sticks held at ARM_DELAY_S'
        worth of ticks in a row (the last one up to a tick early, depending on the phase) arm or disarm."""
        self._clock += dt
        if self._clock < self._next_tick:
            return
        self._next_tick += ARM_TICK_S
        ticks = round(self.p["ARM_DELAY_S"] / ARM_TICK_S)
        if throttle_zero and yaw_in > 4000.0 and not self.armed and self.landed and not self.failsafe:
            self._arm_ticks += 1
            if self._arm_ticks >= ticks:
                self.armed, self._arm_ticks = True, 0
                self._alt_target = 0.0
        else:
            self._arm_ticks = 0
        if throttle_zero and yaw_in < -4000.0 and self.armed and self.landed:
            self._disarm_ticks += 1
            if self._disarm_ticks >= ticks:
                self.armed, self._disarm_ticks = False, 0
        else:
            self._disarm_ticks = 0

    def _modes(self, mode_pwm: float, throttle_pwm: float) -> None:
        fs_on = self.p["FS_THR_ENABLE"] != 0 and throttle_pwm < self.p["FS_THR_VALUE"]
        if fs_on and not self.failsafe:
            self.failsafe = True
            if self.armed and self.landed:
                self.armed = False  # failsafe on the ground: disarm at once
            elif self.armed:
                self.mode = Mode.LAND  # RTL without GPS, or FS_THR_ENABLE 3: Land
        elif not fs_on:
            self.failsafe = False
        if abs(mode_pwm - self._mode_pwm) > 10.0:  # the mode switch moved: a new mode (also after a failsafe)
            self._mode_pwm = mode_pwm
            if not self.failsafe:
                number = self.p.mode_number(mode_pwm)
                self.mode = Mode(number) if number in Mode._value2member_map_ else self.mode

    # -- one control step ----------------------------------------------------------------------------------
    def step(self, pulses: tuple[float, float, float, float, float], s: Sensors, dt: float) -> Demand:
        """``pulses``: roll, pitch, throttle, yaw and flight-mode pulse widths (µs)."""
        roll_pwm, pitch_pwm, throttle_pwm, yaw_pwm, mode_pwm = pulses
        sticks = self.p.sticks
        roll_in, pitch_in = sticks[dp.ChannelName.ROLL].angle(roll_pwm), sticks[dp.ChannelName.PITCH].angle(pitch_pwm)
        yaw_in = sticks[dp.ChannelName.YAW].angle(yaw_pwm)
        throttle = sticks[dp.ChannelName.THROTTLE].range(throttle_pwm)
        self._modes(mode_pwm, throttle_pwm)
        self._arming(throttle <= 0.0, yaw_in, dt)
        if not self.armed:
            self._roll = self._pitch = self._climb_cmd = self._yaw_rate = 0.0
            self.landed = abs(s.climb) < 0.1  # resting (on the floor or on a table), not falling
            return Demand(0.0, 0.0, 0.0, 0.0, False)
        want_roll, want_pitch = desired_lean(self.p, roll_in, pitch_in)
        yaw_rate = math.radians(self.p["PILOT_Y_RATE"]) * yaw_in / ANGLE_RANGE
        if self.mode is Mode.LAND:
            want_roll = want_pitch = yaw_rate = 0.0
            collective, climb_demand = self._vertical(-self.p["LAND_SPEED"] / 100.0, s, dt)
        elif self.mode is Mode.ALT_HOLD:
            collective, climb_demand = self._vertical(desired_climb_rate(self.p, throttle), s, dt)
        else:
            collective = stabilize_throttle(self.p, throttle)
            climb_demand = collective - self.hover
            self._alt_target = s.height
        self._land_detector(climb_demand, collective, s, dt)
        if self.landed:
            # spooled down on the ground: no lean, no turn, motors at their floor until a climb is asked for
            self._roll = self._pitch = self._yaw_rate = 0.0
            if self.mode is Mode.LAND or self.failsafe:
                self.armed = False
            return Demand(0.0, 0.0, 0.0, 0.0, self.armed)
        a = min(1.0, dt / self.p["ATC_INPUT_TC"])
        self._roll += (want_roll - self._roll) * a
        self._pitch += (want_pitch - self._pitch) * a
        turn = math.radians(self.p["ATC_ACCEL_Y_MAX"] / 100.0) * dt
        self._yaw_rate += max(-turn, min(turn, yaw_rate - self._yaw_rate))
        if self._crashed(s, dt):
            return Demand(0.0, 0.0, 0.0, 0.0, False)
        tilt = max(0.5, math.cos(s.roll) * math.cos(s.pitch))
        return Demand(self._roll, self._pitch, self._yaw_rate, collective / tilt, True)

    def _vertical(self, climb_target: float, s: Sensors, dt: float) -> tuple[float, float]:
        """AltHold's vertical controller: the collective (before tilt compensation) and the climb demand."""
        step = self.p["PILOT_ACCEL_Z"] / 100.0 * dt
        self._climb_cmd += max(-step, min(step, climb_target - self._climb_cmd))
        if self.landed:
            self._alt_target = s.height
        self._alt_target += self._climb_cmd * dt
        velocity = self._climb_cmd + self.p["PSC_POSZ_P"] * (self._alt_target - s.height)
        accel = self.p["PSC_VELZ_P"] * (velocity - s.climb)
        return max(0.0, self.hover * (1.0 + accel / GRAVITY)), self._climb_cmd

    def _crashed(self, s: Sensors, dt: float) -> bool:
        """ArduCopter's crash check: the attitude off its target by more than CRASH_ANGLE_DEG for CRASH_S
        (blown over, wedged against a wall) disarms the motors."""
        error = math.degrees(max(abs(s.roll - self._roll), abs(s.pitch - self._pitch)))
        self._crash_timer = self._crash_timer + dt if error > self.p["CRASH_ANGLE_DEG"] else 0.0
        if self._crash_timer >= self.p["CRASH_S"]:
            self.armed, self._crash_timer = False, 0.0
            return True
        return False

    def _land_detector(self, climb_demand: float, collective: float, s: Sensors, dt: float) -> None:
        """Landed as ArduCopter tells it, without knowing the height of what it stands on (the floor, a table):
        asked not to climb, thrust well under hover and yet not descending, for LAND_DETECT_S."""
        if climb_demand > 0.0:
            self.landed = False
            self._land_timer = 0.0
            return
        if collective < 0.75 * self.hover and abs(s.climb) < 0.1:
            self._land_timer += dt
            if self._land_timer >= self.p["LAND_DETECT_S"]:
                self.landed = True
        else:
            self._land_timer = 0.0
