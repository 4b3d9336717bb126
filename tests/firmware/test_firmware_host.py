"""Host tests of the firmware logic: the real sources against the fake Arduino core, with a stepped clock.

Each test writes a script of serial bytes and clock steps for the virtual drone and checks its JSON output
lines and replies. No test waits in real time.
"""

from __future__ import annotations

import itertools

import drone_protocol as dp
import fwsupport as fw
import pytest

STICK_COMMANDS = [spec for spec in dp.COMMANDS.values() if spec.category in (dp.Category.MOVE, dp.Category.TURN)]
SERVO_MOVES = [spec for spec in dp.COMMANDS.values() if spec.category == dp.Category.SERVO and spec.target != "both"]
SELF_TEST_STEP_MS = 250  # the self-test's own pace (firmware/drone/drone_logic.cpp), not a protocol value


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


def test_boot_prints_ready_with_the_spec_fingerprint_and_outputs_are_safe() -> None:
    trace = fw.Script().step(5).run()
    assert trace.lines()[0] == fw.R.ready()
    assert trace.lines()[0].split()[2] == dp.SPEC_FINGERPRINT
    boot = trace.changes[0]
    assert boot["t_ms"] == 0
    # the boot may be a reset in flight: the failsafe throttle makes the flight controller land, not drop
    assert fw.sticks(boot) == {**fw.neutral(), "throttle": dp.FAILSAFE_THROTTLE_US}
    assert dp.CHANNELS[dp.ChannelName.THROTTLE].minimum > dp.FAILSAFE_THROTTLE_US
    assert boot["mode"] == dp.MODE_STABILIZE_US
    assert (boot["pan"], boot["tilt"]) == (dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default)
    assert boot["laser"] is False and boot["armed"] is False and boot["state"] == "disarmed"
    assert len(trace.changes) == 1  # nothing moves by itself before the failsafe time


@pytest.mark.parametrize("frame", [dp.arm(), dp.disarm(), dp.first_test()], ids=["arm", "disarm", "self-test"])
def test_the_first_sequence_brings_the_boot_throttle_to_its_minimum(frame: bytes) -> None:
    trace = fw.Script().step(10).send(frame).step(20).run()
    after = trace.changes[-1]
    assert after["state"] != "disarmed" and after["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].minimum


@pytest.mark.parametrize("spec", STICK_COMMANDS, ids=lambda s: s.name)
def test_movement_is_refused_while_disarmed(spec: dp.CommandSpec) -> None:
    frame = dp.encode(spec.category, spec.direction, spec.default)
    trace = fw.Script().step(10).send(frame).step(20).run()
    assert trace.replies(since_ms=10) == [fw.rejected(dp.ErrorKind.NOT_ARMED)]
    assert len(trace.changes) == 1, trace.changes  # no output changed


def test_arming_holds_throttle_low_and_yaw_right_for_the_arming_time() -> None:
    script = fw.Script().step(10).send(dp.arm())
    # Keep the link alive during the hold, as the Pi must; servo_reset changes nothing here.
    for _ in range(dp.ARMING_HOLD_MS // 200 + 2):
        script.step(200).send(dp.servo_reset())
    trace = script.step(50).run()
    assert trace.replies(since_ms=10)[0] == fw.accepted(dp.arm())
    start = trace.first_change(state="arming")
    assert start["t_ms"] == 11  # the frame is read on the next millisecond
    assert start["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert start["yaw"] == dp.CHANNELS[dp.ChannelName.YAW].maximum  # full right
    assert start["mode"] == dp.MODE_STABILIZE_US
    done = trace.first_change(armed=True)
    assert done["t_ms"] == start["t_ms"] + dp.ARMING_HOLD_MS
    assert done["state"] == "armed"
    assert fw.sticks(done) == fw.on_ground()  # armed on the ground: throttle stays at its minimum
    assert [c["state"] for c in trace.changes] == ["disarmed", "arming", "armed"]


def test_disarming_holds_throttle_low_and_yaw_left_then_disarms() -> None:
    script = fw.Script().arm().step(10)  # on the ground: ik0000 is honoured (in the air it is refused)
    t0 = script.t_ms
    script.send(dp.disarm())
    for _ in range(dp.ARMING_HOLD_MS // 200 + 2):
        script.step(200).send(dp.servo_reset())
    trace = script.step(10).run()
    assert fw.accepted(dp.disarm()) in trace.replies(since_ms=t0)
    start = trace.first_change(since_ms=t0, state="disarming")
    assert start["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert start["yaw"] == dp.CHANNELS[dp.ChannelName.YAW].minimum  # full left
    assert start["mode"] == dp.MODE_STABILIZE_US  # stick disarming needs a manual-throttle mode
    assert start["armed"] is True
    done = trace.first_change(since_ms=t0, armed=False)
    assert done["t_ms"] == start["t_ms"] + dp.ARMING_HOLD_MS
    assert done["state"] == "disarmed"
    assert fw.sticks(done) == fw.on_ground()


@pytest.mark.parametrize("spec", STICK_COMMANDS, ids=lambda s: s.name)
@pytest.mark.parametrize("which", ["minimum", "default", "maximum"])
def test_every_move_and_turn_sets_its_channel_others_median_then_times_out(spec: dp.CommandSpec, which: str) -> None:
    value = {"minimum": spec.minimum, "default": spec.default, "maximum": spec.maximum}[which]
    assert value is not None
    frame = dp.encode(spec.category, spec.direction, value)
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(frame).step(dp.COMMAND_TIMEOUT_MS + 50).run()
    assert trace.replies(since_ms=t0) == [fw.accepted(frame)]
    moving = trace.first_change(since_ms=t0, state="moving")
    assert moving["t_ms"] == t0 + 1
    assert fw.sticks(moving) == {**fw.neutral(), spec.target: value}
    assert moving["mode"] == dp.MODE_STABILIZE_US  # a movement leaves the flight mode alone
    back = trace.first_change(since_ms=t0 + 2, state="hold_altitude")
    assert back["t_ms"] == moving["t_ms"] + dp.COMMAND_TIMEOUT_MS
    assert fw.sticks(back) == fw.neutral()


def test_a_new_movement_restarts_the_command_timeout() -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.move_forward(1600)).step(400).send(dp.turn_left(1424)).step(dp.COMMAND_TIMEOUT_MS + 10).run()
    turn = trace.first_change(since_ms=t0, yaw=1424)
    assert turn["t_ms"] == t0 + 401
    assert fw.sticks(turn) == {**fw.neutral(), "yaw": 1424}  # the earlier pitch is released
    back = trace.first_change(since_ms=t0 + 402, state="hold_altitude")
    assert back["t_ms"] == turn["t_ms"] + dp.COMMAND_TIMEOUT_MS


def test_servo_and_laser_frames_do_not_end_a_movement() -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    script.send(dp.move_forward(1700)).step(100).send(dp.servo_left(20) + dp.laser_toggle()).step(100)
    trace = script.step(dp.COMMAND_TIMEOUT_MS).run()
    during = trace.state_at(t0 + 150)
    assert during["state"] == "moving" and during["pitch"] == 1700
    assert during["pan"] == dp.SERVOS[dp.ServoName.PAN].default - 20 and during["laser"] is True
    back = trace.first_change(since_ms=t0 + 2, state="hold_altitude")
    assert back["t_ms"] == t0 + 1 + dp.COMMAND_TIMEOUT_MS  # timed from the movement, not the servo frame


def test_hold_altitude_sets_alt_hold_mode_and_neutral_sticks_and_needs_arming() -> None:
    disarmed = fw.Script().step(5).send(dp.hold_altitude()).step(10).run()
    assert disarmed.replies(since_ms=5) == [fw.rejected(dp.ErrorKind.NOT_ARMED)]
    assert len(disarmed.changes) == 1
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.hold_altitude()).step(dp.FAILSAFE_TIMEOUT_MS - 100).run()
    assert trace.replies(since_ms=t0) == [fw.accepted(dp.hold_altitude())]
    hold = trace.first_change(since_ms=t0, state="hold_altitude")
    assert hold["mode"] == dp.MODE_ALT_HOLD_US
    assert fw.sticks(hold) == fw.neutral()  # throttle at its median: the hover point
    assert trace.changes[-1] == hold  # it holds: no timeout of its own


@pytest.mark.parametrize("spec", SERVO_MOVES, ids=lambda s: s.name)
def test_servo_moves_by_degrees_and_clamps_to_its_range(spec: dp.CommandSpec) -> None:
    limits = dp.SERVOS[spec.target]
    frame = dp.encode(spec.category, spec.direction, 45)
    trace = fw.Script().step(5).send(frame).step(5).send(frame).step(5).send(frame).step(5).run()
    assert trace.replies(since_ms=5) == [fw.accepted(frame)] * 3
    angles = [c[spec.target] for c in trace.changes]
    d = spec.sense * 45
    expected = [limits.default] + [max(limits.minimum, min(limits.maximum, limits.default + k * d)) for k in (1, 2, 3)]
    # the third move hits the end of the range and changes nothing more
    assert angles == [a for i, a in enumerate(expected) if i == 0 or a != expected[i - 1]]
    other = "pan" if spec.target == "tilt" else "tilt"
    assert {c[other] for c in trace.changes} == {dp.SERVOS[other].default}
    assert trace.changes[-1][spec.target] in (limits.minimum, limits.maximum)


def test_servo_reset_returns_both_servos_to_their_defaults() -> None:
    trace = fw.Script().step(5).send(dp.servo_right(30) + dp.servo_up(60)).step(5).send(dp.servo_reset()).step(5).run()
    assert trace.replies(since_ms=5) == [
        fw.accepted(dp.servo_right(30)),
        fw.accepted(dp.servo_up(60)),
        fw.accepted(dp.servo_reset()),
    ]
    moved = trace.state_at(7)
    pan, tilt = dp.SERVOS[dp.ServoName.PAN], dp.SERVOS[dp.ServoName.TILT]
    assert (moved["pan"], moved["tilt"]) == (pan.default + 30, tilt.default + 60)
    final = trace.changes[-1]
    assert (final["pan"], final["tilt"]) == (dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default)


def test_laser_toggles() -> None:
    trace = fw.Script().step(5).send(dp.laser_toggle()).step(5).send(dp.laser_toggle()).step(5).run()
    assert trace.replies(since_ms=5) == [fw.accepted(dp.laser_toggle())] * 2
    assert [c["laser"] for c in trace.changes] == [False, True, False]
    assert [c["t_ms"] for c in trace.changes[1:]] == [6, 11]


def test_movement_during_a_sequence_is_busy_but_disarm_always_wins() -> None:
    script = fw.Script().step(5).send(dp.arm()).step(100)
    script.send(dp.move_forward(1600)).step(5).send(dp.first_test()).step(5).send(dp.hold_altitude()).step(5)
    t_disarm = script.t_ms
    trace = script.send(dp.disarm()).step(5).run()
    assert trace.replies(since_ms=7) == [fw.rejected(dp.ErrorKind.BUSY)] * 3 + [fw.accepted(dp.disarm())]
    start = trace.first_change(since_ms=t_disarm, state="disarming")  # the arming sequence is aborted
    yaw, throttle = dp.CHANNELS[dp.ChannelName.YAW], dp.CHANNELS[dp.ChannelName.THROTTLE]
    assert start["yaw"] == yaw.minimum and start["throttle"] == throttle.minimum
    assert all(c["pitch"] == fw.neutral()["pitch"] for c in trace.changes)


def test_self_test_sweeps_servos_blinks_laser_nudges_sticks_without_throttle() -> None:
    script = fw.Script().step(5).send(dp.first_test()).step(100)
    script.send(dp.laser_toggle()).step(5)  # refused while the test runs
    for _ in range(40):  # keep the link alive for the whole routine
        script.step(150).send(dp.move_forward(1600))
    trace = script.step(10).run()
    replies = trace.replies(since_ms=5)
    assert replies[0] == fw.accepted(dp.first_test())
    assert replies[1] == fw.rejected(dp.ErrorKind.BUSY)
    run = [c for c in trace.changes if c["state"] == "self_test"]
    assert run, trace.changes
    pan = dp.SERVOS[dp.ServoName.PAN]
    tilt = dp.SERVOS[dp.ServoName.TILT]
    assert {pan.minimum, pan.maximum} <= {c["pan"] for c in run}
    assert {tilt.minimum, tilt.maximum} <= {c["tilt"] for c in run}
    blinks = [c["laser"] for c in run]
    assert sum(1 for a, b in itertools.pairwise(blinks) if not a and b) >= 1 and blinks.count(True) >= 2
    for name in ("roll", "pitch", "yaw"):
        seen = {c[name] for c in run}
        assert {dp.CHANNELS[name].low, dp.CHANNELS[name].high} <= seen, name
    assert {c["throttle"] for c in run} == {dp.CHANNELS[dp.ChannelName.THROTTLE].minimum}
    assert all(c["armed"] is False for c in trace.changes)
    end = trace.changes[-1]
    assert end["state"] == "disarmed"
    assert fw.sticks(end) == fw.on_ground() and end["laser"] is False
    assert (end["pan"], end["tilt"]) == (pan.default, tilt.default)
    steps = len({(c["pan"], c["tilt"], c["laser"], c["roll"], c["pitch"], c["yaw"]) for c in run})
    assert end["t_ms"] - run[0]["t_ms"] >= (steps - 1) * SELF_TEST_STEP_MS
    # movements sent during the test were all refused as busy (disarmed afterwards: not armed)
    assert set(trace.replies(since_ms=run[0]["t_ms"] + 1)[1:]) <= {
        fw.rejected(dp.ErrorKind.BUSY),
        fw.rejected(dp.ErrorKind.NOT_ARMED),
    }


def test_self_test_is_refused_when_armed() -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.first_test()).step(10).run()
    assert trace.lines(since_ms=t0) == [fw.R.line(fw.rejected(dp.ErrorKind.ARMED), "armed", False)]
    assert [c for c in trace.changes if c["t_ms"] >= t0] == []
