"""The pilot's pulses come from the spec (its channels and the flight controller's parameters), never from a
count of speed steps: a spec with a speed step of 70, 100 or 150 µs, or a wider throttle dead band, flies the
same, and the simulator's own ArduCopter emulation answers each control step as the tuning assumes."""

from __future__ import annotations

import math

import drone_protocol as dp
import pytest
from controller_rig import CFG, seen, to_state

from pilot.control.controller import Controller, State
from pilot.control.controller_core import speed_for
from pilot.control.pulses import StickModel
from pilot.sim import rc
from pilot.sim.arducopter import desired_climb_rate, desired_lean

C = dp.CommandName
STEPS = (70, 100, 150)


def _track_frames(step_us: int, monkeypatch: pytest.MonkeyPatch) -> list[bytes]:
    """The take-off climb and TRACK's turn, climb and approach with the spec's speed step at ``step_us``."""
    monkeypatch.setattr(dp, "SPEED_STEP_US", step_us)
    c, rig = to_state(State.TRACK)
    takeoff = next(f for f in rig.sent if dp.decode(f).name is C.MOVE_UP)
    frames = [takeoff]
    for det in (seen(ex=0.8), seen(ex=-0.2), seen(ey=-0.7), seen(ey=0.3), seen()):
        rig.tick(det)
        assert c.last_command is not None
        frames.append(c.last_command)
    return frames


def test_the_speed_step_does_not_change_what_the_pilot_asks_of_the_drone(monkeypatch: pytest.MonkeyPatch) -> None:
    flown = {step: _track_frames(step, monkeypatch) for step in STEPS}
    assert [dp.decode(f).name for f in flown[100]] == [C.MOVE_UP, C.TURN_RIGHT, C.TURN_LEFT, C.MOVE_UP, C.MOVE_DOWN,
                                                       C.MOVE_FORWARD]
    assert flown[70] == flown[100] == flown[150]


def _sim(overrides: dict[str, float] | None = None) -> rc.SimParams:
    return rc.load(overrides=overrides)


@pytest.mark.parametrize("dead_band", [0, 10, 100, 200])
def test_a_climb_step_is_the_tuned_climb_rate_whatever_the_dead_band(dead_band: int) -> None:
    """The simulator's AltHold (its own code, ArduCopter's formula) answers the pilot's climb and descent of one
    control step with the tuned rate; with THR_DZ 100 the old 100 µs step barely climbed."""
    params = {**dp.FLIGHT_CONTROLLER_PARAMETERS, "THR_DZ": dead_band}
    pulses = StickModel(CFG, params)
    sim = _sim({"THR_DZ": dead_band})
    throttle = sim.sticks[dp.ChannelName.THROTTLE]
    for command, sense in ((C.MOVE_UP, 1), (C.MOVE_DOWN, -1)):
        pwm = speed_for(command, 1.0, pulses)
        rate = desired_climb_rate(sim, throttle.range(pwm))
        assert rate == pytest.approx(sense * CFG.climb_mps_per_step, rel=0.03), (command, pwm)
        # more than one step: that many times the pulse offset (as the tuning was made)
        median = dp.CHANNELS[dp.ChannelName.THROTTLE].median
        assert speed_for(command, 1.8, pulses) == median + sense * round(1.8 * pulses.unit_us(
            dp.ChannelName.THROTTLE, sense > 0))


def test_a_wider_dead_band_widens_the_climb_pulse() -> None:
    """THR_DZ 100 (98 µs of this throttle range) instead of 10: the climb pulse reaches past it."""
    wide = StickModel(CFG, {**dp.FLIGHT_CONTROLLER_PARAMETERS, "THR_DZ": 100})
    assert wide.unit_us(dp.ChannelName.THROTTLE, True) > StickModel(CFG).unit_us(dp.ChannelName.THROTTLE, True) + 60


def test_a_lean_and_a_turn_step_are_the_tuned_ones() -> None:
    pulses = StickModel(CFG)
    sim = _sim()
    pitch, yaw = sim.sticks[dp.ChannelName.PITCH], sim.sticks[dp.ChannelName.YAW]
    forward = speed_for(C.MOVE_FORWARD, 1.0, pulses)
    _, lean = desired_lean(sim, 0.0, pitch.angle(forward))
    assert math.degrees(lean) == pytest.approx(-CFG.unit_lean_deg, rel=0.02)  # nose down: forward
    right = speed_for(C.TURN_RIGHT, 1.0, pulses)
    rate = sim["PILOT_Y_RATE"] * yaw.angle(right) / rc.ANGLE_RANGE
    assert rate == pytest.approx(CFG.turn_rate_dps, rel=0.02)


def test_a_narrower_channel_range_gives_a_smaller_pulse() -> None:
    """The pulse of a step follows the channel's range in the parameter file (RCn_MAX): ArduCopter scales the
    stick over the range, so half the range needs about half the pulse for the same lean."""
    params = dict(dp.FLIGHT_CONTROLLER_PARAMETERS)
    wide = StickModel(CFG, params).unit_us(dp.ChannelName.PITCH, True)
    params["RC2_MAX"] = (params["RC2_TRIM"] + params["RC2_MAX"]) // 2
    narrow = StickModel(CFG, params).unit_us(dp.ChannelName.PITCH, True)
    assert narrow < 0.6 * wide
    c = Controller(CFG, parameters=params)
    assert c.pulses.unit_us(dp.ChannelName.PITCH, True) == narrow

