"""How far from its median each stick must go for the flight controller to answer as the controller wants.

The controller thinks in control steps: one step of pitch is a lean of ``unit_lean_deg``, one of throttle a climb
of ``climb_mps_per_step``, one of yaw a turn of ``turn_rate_dps`` (``ControllerConfig``). How many microseconds
that takes depends on how ArduCopter reads the sticks, which the spec sets: the channels' ranges and trims, the
throttle dead band (``THR_DZ``) and the other ``RCn_*`` of the generated parameter file, read here from
``drone_protocol.FLIGHT_CONTROLLER_PARAMETERS``. ArduCopter's own defaults stand in for what the file leaves
out (``ARDUCOPTER_DEFAULTS``, from its parameter documentation). So the spec's speed step, a wider dead band
or a new channel range change the pulses, never what the drone does for a step; ``speeds.step_us`` itself is
the firmware's nominal speed (its landing descent), not a unit of the pilot's.

The mapping mirrors ArduPilot's RC_Channel (``pwm_to_angle_dz``, ``pwm_to_range_dz``) and
``Copter::get_pilot_desired_climb_rate``; a pulse offset of ``f`` control steps is ``f`` times the offset of one.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import drone_protocol as dp

from ..common.config import ControllerConfig

# ArduCopter's defaults for what the generated parameter file does not set (its parameter documentation)
ARDUCOPTER_DEFAULTS: Mapping[str, float] = MappingProxyType({
    "ANGLE_MAX": 3000.0,  # cdeg: the lean at full roll or pitch stick
    "PILOT_Y_RATE": 202.5,  # deg/s at full yaw stick
    "PILOT_SPEED_UP": 250.0,  # cm/s at full throttle in AltHold
    "PILOT_SPEED_DN": 0.0,  # cm/s at zero throttle; 0: PILOT_SPEED_UP
    "THR_DZ": 100.0,  # 0-1000 around mid-throttle
    "RC_DZ": 20.0,  # µs: the roll, pitch and yaw dead zone ArduCopter sets on its sticks
    "RC3_DZ": 30.0,  # µs: the throttle's dead zone above its minimum
})
ANGLE_RANGE = 4500.0  # ArduPilot's stick angle at full deflection (centidegrees of stick, not of lean)
THROTTLE_RANGE = 1000.0
GRAVITY = 9.81
_INPUTS = {dp.ChannelName.ROLL: 1, dp.ChannelName.PITCH: 2, dp.ChannelName.THROTTLE: 3, dp.ChannelName.YAW: 4}


@dataclass(frozen=True)
class Stick:
    """One RC input as ArduCopter reads it (µs)."""

    minimum: float
    maximum: float
    trim: float
    dead_zone: float

    def _span(self, up: bool) -> float:
        """The pulses past the dead zone to full deflection, on one side of the trim."""
        return self.maximum - self.trim - self.dead_zone if up else self.trim - self.dead_zone - self.minimum

    def angle(self, offset_us: float) -> float:
        """The stick angle (0..4500) of a pulse ``offset_us`` above (or below, negative) the trim."""
        span = self._span(offset_us >= 0)
        beyond = abs(offset_us) - self.dead_zone
        return 0.0 if beyond <= 0.0 or span <= 0.0 else min(ANGLE_RANGE, ANGLE_RANGE * beyond / span)

    def offset_for_angle(self, angle: float, up: bool) -> float:
        """The smallest pulse offset (µs, positive) that gives ``angle`` (0..4500) on that side of the trim."""
        return self.dead_zone + self._span(up) * min(angle, ANGLE_RANGE) / ANGLE_RANGE

    def throttle(self, pwm: float) -> float:
        """0..1000 above the minimum plus the dead zone (RC_Channel::pwm_to_range_dz)."""
        low = self.minimum + self.dead_zone
        pwm = max(self.minimum, min(self.maximum, pwm))
        return 0.0 if pwm <= low else THROTTLE_RANGE * (pwm - low) / (self.maximum - low)

    def pwm_for_throttle(self, value: float) -> float:
        low = self.minimum + self.dead_zone
        return low + (self.maximum - low) * value / THROTTLE_RANGE


class StickModel:
    """The flight controller's answer to a pulse, and the pulse offsets of one control step per channel."""

    def __init__(self, config: ControllerConfig | None = None,
                 parameters: Mapping[str, float] = dp.FLIGHT_CONTROLLER_PARAMETERS) -> None:
        cfg = config or ControllerConfig()
        self.params: dict[str, float] = {**ARDUCOPTER_DEFAULTS, **{k: float(v) for k, v in parameters.items()}}
        p = self.params
        self.sticks: dict[dp.ChannelName, Stick] = {}
        for name, default in _INPUTS.items():
            n = int(p.get(f"RCMAP_{name.value.upper()}", default))
            ch = dp.CHANNELS[name]
            lo, hi = p.get(f"RC{n}_MIN", ch.minimum), p.get(f"RC{n}_MAX", ch.maximum)
            dz = p["RC3_DZ"] if name is dp.ChannelName.THROTTLE else p["RC_DZ"]
            self.sticks[name] = Stick(lo, hi, p.get(f"RC{n}_TRIM", ch.median), dz)
        self.unit_lean_deg = cfg.unit_lean_deg
        self.unit_turn_dps = cfg.turn_rate_dps
        self.unit_climb_mps = cfg.climb_mps_per_step
        self._unit_us: dict[tuple[dp.ChannelName, bool], float] = {}
        for name in _INPUTS:
            for up in (True, False):
                self._unit_us[(name, up)] = self._offset_for_unit(name, up)

    # -- the flight controller's answer -------------------------------------------------------------
    def lean_deg(self, offset_us: float, channel: dp.ChannelName = dp.ChannelName.PITCH) -> float:
        """The lean (degrees) a roll or pitch pulse this far from the median asks for."""
        return self.sticks[channel].angle(self._from_trim(channel, offset_us)) * self.params["ANGLE_MAX"] / (
            ANGLE_RANGE * 100.0)

    def turn_dps(self, offset_us: float) -> float:
        """The yaw rate (deg/s) a yaw pulse this far from the median asks for."""
        angle = self.sticks[dp.ChannelName.YAW].angle(self._from_trim(dp.ChannelName.YAW, offset_us))
        return self.params["PILOT_Y_RATE"] * angle / ANGLE_RANGE

    def climb_mps(self, offset_us: float) -> float:
        """AltHold's climb rate (m/s, down negative) for a throttle pulse this far from the median."""
        stick = self.sticks[dp.ChannelName.THROTTLE]
        value = stick.throttle(dp.CHANNELS[dp.ChannelName.THROTTLE].median + offset_us)
        mid, dz = stick.throttle((stick.minimum + stick.maximum) / 2.0), self.params["THR_DZ"]
        up = self.params["PILOT_SPEED_UP"] / 100.0
        down = (self.params["PILOT_SPEED_DN"] or self.params["PILOT_SPEED_UP"]) / 100.0
        if value > mid + dz:
            return up * (value - mid - dz) / (THROTTLE_RANGE - mid - dz)
        if value < mid - dz:
            return down * (value - mid + dz) / (mid - dz)
        return 0.0

    def _from_trim(self, channel: dp.ChannelName, offset_us: float) -> float:
        """A pulse offset from the spec's median, as an offset from the flight controller's trim."""
        return dp.CHANNELS[channel].median + offset_us - self.sticks[channel].trim

    # -- the pulses of one control step ----------------------------------------------------------------
    def _offset_for_unit(self, channel: dp.ChannelName, up: bool) -> float:
        stick, sign = self.sticks[channel], 1.0 if up else -1.0
        median = dp.CHANNELS[channel].median
        if channel is dp.ChannelName.THROTTLE:
            lo, hi = 0.0, (stick.maximum - median if up else median - stick.minimum)
            for _ in range(60):  # bisection: the climb rate is monotonic in the pulse
                mid = (lo + hi) / 2.0
                if abs(self.climb_mps(sign * mid)) < self.unit_climb_mps:
                    lo = mid
                else:
                    hi = mid
            return hi
        if channel is dp.ChannelName.YAW:
            angle = ANGLE_RANGE * self.unit_turn_dps / self.params["PILOT_Y_RATE"]
        else:
            angle = ANGLE_RANGE * self.unit_lean_deg * 100.0 / self.params["ANGLE_MAX"]
        trim_shift = stick.trim - median
        return abs(sign * stick.offset_for_angle(angle, up) + trim_shift)

    def unit_us(self, channel: dp.ChannelName, up: bool) -> float:
        """The pulse offset (µs from the median) of one control step on ``channel``, above (up) or below it."""
        return self._unit_us[(channel, up)]

    def lean_offset_us(self, channel: dp.ChannelName, lean_deg: float) -> int:
        """The pulse offset (µs from the median, the sign of ``lean_deg``) that asks for a roll or pitch lean of
        ``lean_deg`` past the dead zone, however small: right or forward positive, as the movement commands."""
        if lean_deg == 0.0:
            return 0
        stick, up = self.sticks[channel], lean_deg > 0.0
        angle = ANGLE_RANGE * abs(lean_deg) * 100.0 / self.params["ANGLE_MAX"]
        from_trim = (1.0 if up else -1.0) * stick.offset_for_angle(angle, up)
        return round(stick.trim + from_trim - dp.CHANNELS[channel].median)

    def steps(self, channel: dp.ChannelName, offset_us: float) -> float:
        """A pulse offset from the median as control steps (its sign kept)."""
        unit = self.unit_us(channel, offset_us >= 0)
        return offset_us / unit if unit > 0.0 else 0.0

