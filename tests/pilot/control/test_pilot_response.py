"""A drone that does not answer its sticks, a panned camera on the way back to TRACK, and a target that drifts out of
range while the laser is on."""

from __future__ import annotations

import dataclasses
import math

import drone_protocol as dp
from controller_rig import CFG, name, seen, st, to_state

from pilot.control.controller import State
from pilot.control.controller_core import RESET_ERROR
from pilot.control.pulses import StickModel
from pilot.control.response import NO_RESPONSE_MS, TurnResponse, turn_sense

PULSES = StickModel()
YAW = dp.ChannelName.YAW


def test_only_hard_turns_count() -> None:
    median = dp.CHANNELS[YAW].median
    assert turn_sense(dp.turn_right(median + round(PULSES.unit_us(YAW, True))), PULSES) == 1
    assert turn_sense(dp.turn_left(median - round(PULSES.unit_us(YAW, False))), PULSES) == -1
    assert turn_sense(dp.turn_right(median + round(PULSES.unit_us(YAW, True) / 4)), PULSES) == 0
    assert turn_sense(dp.hold_altitude(), PULSES) == 0
    assert turn_sense(None, PULSES) == 0
    assert turn_sense(b"garbage", PULSES) == 0


def test_a_target_that_moves_or_a_pause_in_turning_restarts_the_count() -> None:
    r = TurnResponse()
    t = 0
    for i in range(200):
        t = i * 50
        assert not r.observe(t, 1, 100.0 + (i % 2) * 20.0, 320)  # a moving target: never stuck
    assert not r.observe(t + 50, 1, 100.0, 320)
    assert not r.observe(t + NO_RESPONSE_MS, 0, 100.0, 320)  # not turning: nothing to judge
    assert not r.observe(t + NO_RESPONSE_MS + 50, 1, 100.0, 320)  # a new episode
    assert r.observe(t + 2 * NO_RESPONSE_MS + 50, 1, 101.0, 320)


def test_a_drone_whose_hard_turns_move_nothing_lands() -> None:
    c, rig = to_state(State.TRACK)
    frames = []
    for _ in range(NO_RESPONSE_MS // 50 + 10):  # the target far right, and it stays there whatever is sent
        if st(c) is not State.TRACK:
            break
        frames.append(name(rig.tick(seen(ex=0.8, size=0.05))))
    assert st(c) is State.LAND
    assert frames.count("turn_right") >= NO_RESPONSE_MS // 50 - 2
    assert "does not answer the yaw stick" in c.transitions[-1].reason


def test_a_drone_that_turns_keeps_tracking() -> None:
    c, rig = to_state(State.TRACK)
    ex = 0.8
    for _ in range(NO_RESPONSE_MS // 50 + 20):
        frame = rig.tick(seen(ex=ex, size=0.05))
        if frame is not None and name(frame) == "turn_right":
            ex -= 0.01  # the target creeps towards the middle as the body turns
    assert st(c) is State.TRACK


def test_track_with_the_camera_panned_turns_the_body_before_the_servos_reset() -> None:
    c, rig = to_state(State.AIM)
    assert name(rig.tick(seen(ex=-0.9, size=0.2))) == "servo_left"  # the target far left: AIM pans after it
    assert c._pan_offset < -20
    first = name(rig.tick(seen(ex=0.0, size=0.1)))  # centred by the pan, now receding: back to TRACK
    assert st(c) is State.TRACK
    assert first == "turn_left"  # a reset now would leave the target at the frame's left edge
    frames = [first]
    ex, pan = 0.0, c._pan_offset
    for _ in range(40):
        pan = c._pan_offset
        frame = name(rig.tick(seen(ex=ex, size=0.1)))
        frames.append(frame)
        if frame == "servo_reset":
            break
        if frame == "turn_left":
            ex += 0.05  # the body turns left, the panned camera with it: the target moves right in the frame
    assert frames[-1] == "servo_reset"
    assert set(frames[:-1]) == {"turn_left"}
    tan_h = math.tan(math.radians(CFG.horizontal_fov_deg / 2))
    after = math.tan(math.radians(pan + math.degrees(math.atan(ex * tan_h)))) / tan_h
    assert abs(after) <= RESET_ERROR  # where the reset left the target: well inside the frame


def test_a_target_drifting_out_of_range_switches_the_laser_off() -> None:
    c, rig = to_state(State.FIRE)
    assert c.laser_on is True
    frame = rig.tick(seen(size=CFG.retreat_size * 0.9))
    assert st(c) is State.AIM
    assert frame == dp.laser_off()
    assert c.transitions[-1].reason == "out of range while firing"


def test_something_in_front_of_the_target_switches_the_laser_off_and_holds_the_fire() -> None:
    c, rig = to_state(State.FIRE)
    assert c.laser_on is True
    blocked = dataclasses.replace(seen(size=0.3), aim_on_target=False)
    assert rig.tick(blocked) == dp.laser_off()
    assert st(c) is State.AIM and c.transitions[-1].reason == "something in front of the target while firing"
    for _ in range(40):  # centred and confirmed, but the ray would hit the thing in front
        assert name(rig.tick(blocked)) != "laser_on"
    assert st(c) is State.AIM
    for _ in range(10):
        rig.tick(dataclasses.replace(seen(size=0.3), aim_on_target=True))
    assert st(c) is State.FIRE
