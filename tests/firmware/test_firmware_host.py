"""Host tests of the firmware logic: the real sources against the fake Arduino core, with a stepped clock.

Each test writes a script of serial bytes and clock steps for the virtual drone and checks its JSON output
lines and replies. No test waits in real time.
"""

from __future__ import annotations

import itertools
import json
import os
import select
import subprocess
from typing import Any

import drone_protocol as dp
import fwsupport as fw
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

STICK_COMMANDS = [spec for spec in dp.COMMANDS.values() if spec.category in (dp.Category.MOVE, dp.Category.TURN)]
SERVO_MOVES = [spec for spec in dp.COMMANDS.values() if spec.category == dp.Category.SERVO and spec.target != "both"]
SELF_TEST_STEP_MS = 250  # the self-test's own pace (firmware/drone/drone_logic.cpp), not a protocol value


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


def sticks(change: dict[str, Any]) -> dict[str, int]:
    return {name: change[name] for name in fw.STICKS}


def accepted(frame: bytes) -> str:
    return fw.R.accepted(frame)


def rejected(kind: dp.ErrorKind) -> str:
    return fw.R.rejected(kind.name.lower())


def test_boot_prints_ready_with_the_spec_fingerprint_and_outputs_are_safe() -> None:
    trace = fw.Script().step(5).run()
    assert trace.lines()[0] == fw.R.ready()
    assert trace.lines()[0].split()[2] == dp.SPEC_FINGERPRINT
    boot = trace.changes[0]
    assert boot["t_ms"] == 0
    # the boot may be a reset in flight: the failsafe throttle makes the flight controller land, not drop
    assert sticks(boot) == {**fw.neutral(), "throttle": dp.FAILSAFE_THROTTLE_US}
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
    assert trace.replies(since_ms=10) == [rejected(dp.ErrorKind.NOT_ARMED)]
    assert len(trace.changes) == 1, trace.changes  # no output changed


def test_arming_holds_throttle_low_and_yaw_right_for_the_arming_time() -> None:
    script = fw.Script().step(10).send(dp.arm())
    # Keep the link alive during the hold, as the Pi must; servo_reset changes nothing here.
    for _ in range(12):
        script.step(200).send(dp.servo_reset())
    trace = script.step(50).run()
    assert trace.replies(since_ms=10)[0] == accepted(dp.arm())
    start = trace.first_change(state="arming")
    assert start["t_ms"] == 11  # the frame is read on the next millisecond
    assert start["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert start["yaw"] == dp.CHANNELS[dp.ChannelName.YAW].maximum  # full right
    assert start["mode"] == dp.MODE_STABILIZE_US
    done = trace.first_change(armed=True)
    assert done["t_ms"] == start["t_ms"] + dp.ARMING_HOLD_MS
    assert done["state"] == "armed"
    assert sticks(done) == fw.on_ground()  # armed on the ground: throttle stays at its minimum
    assert [c["state"] for c in trace.changes] == ["disarmed", "arming", "armed"]


def test_disarming_holds_throttle_low_and_yaw_left_then_disarms() -> None:
    script = fw.Script().arm().step(10)  # on the ground: ik0000 is honoured (in the air it is refused)
    t0 = script.t_ms
    script.send(dp.disarm())
    for _ in range(12):
        script.step(200).send(dp.servo_reset())
    trace = script.step(10).run()
    assert accepted(dp.disarm()) in trace.replies(since_ms=t0)
    start = trace.first_change(since_ms=t0, state="disarming")
    assert start["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert start["yaw"] == dp.CHANNELS[dp.ChannelName.YAW].minimum  # full left
    assert start["mode"] == dp.MODE_STABILIZE_US  # stick disarming needs a manual-throttle mode
    assert start["armed"] is True
    done = trace.first_change(since_ms=t0, armed=False)
    assert done["t_ms"] == start["t_ms"] + dp.ARMING_HOLD_MS
    assert done["state"] == "disarmed"
    assert sticks(done) == fw.on_ground()


@pytest.mark.parametrize("spec", STICK_COMMANDS, ids=lambda s: s.name)
@pytest.mark.parametrize("which", ["minimum", "default", "maximum"])
def test_every_move_and_turn_sets_its_channel_others_median_then_times_out(spec: dp.CommandSpec, which: str) -> None:
    value = {"minimum": spec.minimum, "default": spec.default, "maximum": spec.maximum}[which]
    assert value is not None
    frame = dp.encode(spec.category, spec.direction, value)
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(frame).step(dp.COMMAND_TIMEOUT_MS + 50).run()
    assert trace.replies(since_ms=t0) == [accepted(frame)]
    moving = trace.first_change(since_ms=t0, state="moving")
    assert moving["t_ms"] == t0 + 1
    assert sticks(moving) == {**fw.neutral(), spec.target: value}
    assert moving["mode"] == dp.MODE_STABILIZE_US  # a movement leaves the flight mode alone
    back = trace.first_change(since_ms=t0 + 2, state="hold_altitude")
    assert back["t_ms"] == moving["t_ms"] + dp.COMMAND_TIMEOUT_MS
    assert sticks(back) == fw.neutral()


def test_a_new_movement_restarts_the_command_timeout() -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.move_forward(1600)).step(400).send(dp.turn_left(1424)).step(dp.COMMAND_TIMEOUT_MS + 10).run()
    turn = trace.first_change(since_ms=t0, yaw=1424)
    assert turn["t_ms"] == t0 + 401
    assert sticks(turn) == {**fw.neutral(), "yaw": 1424}  # the earlier pitch is released
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
    assert disarmed.replies(since_ms=5) == [rejected(dp.ErrorKind.NOT_ARMED)]
    assert len(disarmed.changes) == 1
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.hold_altitude()).step(dp.FAILSAFE_TIMEOUT_MS - 100).run()
    assert trace.replies(since_ms=t0) == [accepted(dp.hold_altitude())]
    hold = trace.first_change(since_ms=t0, state="hold_altitude")
    assert hold["mode"] == dp.MODE_ALT_HOLD_US
    assert sticks(hold) == fw.neutral()  # throttle at its median: the hover point
    assert trace.changes[-1] == hold  # it holds: no timeout of its own


@pytest.mark.parametrize("spec", SERVO_MOVES, ids=lambda s: s.name)
def test_servo_moves_by_degrees_and_clamps_to_its_range(spec: dp.CommandSpec) -> None:
    limits = dp.SERVOS[spec.target]
    frame = dp.encode(spec.category, spec.direction, 45)
    trace = fw.Script().step(5).send(frame).step(5).send(frame).step(5).send(frame).step(5).run()
    assert trace.replies(since_ms=5) == [accepted(frame)] * 3
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
        accepted(dp.servo_right(30)),
        accepted(dp.servo_up(60)),
        accepted(dp.servo_reset()),
    ]
    moved = trace.state_at(7)
    pan, tilt = dp.SERVOS[dp.ServoName.PAN], dp.SERVOS[dp.ServoName.TILT]
    assert (moved["pan"], moved["tilt"]) == (pan.default + 30, tilt.default + 60)
    final = trace.changes[-1]
    assert (final["pan"], final["tilt"]) == (dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default)


def test_laser_toggles() -> None:
    trace = fw.Script().step(5).send(dp.laser_toggle()).step(5).send(dp.laser_toggle()).step(5).run()
    assert trace.replies(since_ms=5) == [accepted(dp.laser_toggle())] * 2
    assert [c["laser"] for c in trace.changes] == [False, True, False]
    assert [c["t_ms"] for c in trace.changes[1:]] == [6, 11]


def test_failsafe_after_silence_sets_failsafe_throttle_neutral_sticks_laser_off_mode_kept() -> None:
    script = fw.Script().arm().send(dp.hold_altitude() + dp.laser_toggle()).step(1)
    last_frame = script.t_ms  # both frames are read at this millisecond
    trace = script.step(dp.FAILSAFE_TIMEOUT_MS + 100).run()
    before = trace.state_at(last_frame)
    assert before["laser"] is True and before["mode"] == dp.MODE_ALT_HOLD_US
    fs = trace.first_change(state="failsafe")
    assert fs["t_ms"] == last_frame + dp.FAILSAFE_TIMEOUT_MS
    assert fs["throttle"] == dp.FAILSAFE_THROTTLE_US
    assert {k: fs[k] for k in ("roll", "pitch", "yaw")} == {k: fw.neutral()[k] for k in ("roll", "pitch", "yaw")}
    assert fs["laser"] is False
    assert fs["mode"] == dp.MODE_ALT_HOLD_US  # the mode channel stays as it was
    assert (fw.Trace(tx=[(t, x) for t, x in trace.tx if t == fs["t_ms"]]).lines()) == [
        fw.R.line(fw.R.failsafe(), "failsafe", False)
    ]
    assert trace.changes[-1] == fs  # and it stays there


def test_failsafe_fires_at_boot_without_a_pi() -> None:
    trace = fw.Script().step(dp.FAILSAFE_TIMEOUT_MS + 10).run()
    fs = trace.first_change(state="failsafe")
    assert fs["t_ms"] == dp.FAILSAFE_TIMEOUT_MS
    assert fs["throttle"] == dp.FAILSAFE_THROTTLE_US


def test_garbage_does_not_keep_the_link_alive() -> None:
    script = fw.Script().arm().send(dp.hold_altitude()).step(1)
    last_frame = script.t_ms
    for _ in range(10):  # garbage every 100 ms, no valid frame
        script.send(b"xyz#mf12?9").step(100)
    trace = script.step(100).run()
    assert trace.first_change(state="failsafe")["t_ms"] == last_frame + dp.FAILSAFE_TIMEOUT_MS


def test_refused_frames_still_prove_the_link_and_failsafe_recovers_on_a_valid_frame() -> None:
    script = fw.Script().step(dp.FAILSAFE_TIMEOUT_MS + 10)  # failsafe while disarmed
    script.send(dp.move_forward(1600)).step(10)  # refused (not armed) but well formed
    trace = script.step(dp.FAILSAFE_TIMEOUT_MS - 50).run()
    assert trace.replies(since_ms=dp.FAILSAFE_TIMEOUT_MS + 10) == [rejected(dp.ErrorKind.NOT_ARMED)]
    recovered = trace.changes[-1]
    assert recovered["state"] == "disarmed" and sticks(recovered) == fw.on_ground()
    assert recovered["t_ms"] == dp.FAILSAFE_TIMEOUT_MS + 11


def test_an_armed_drone_leaving_failsafe_is_disarmed_and_must_arm_again() -> None:
    script = fw.Script().arm()
    script.step(dp.FAILSAFE_TIMEOUT_MS + 10)
    t0 = script.t_ms
    trace = script.send(dp.servo_reset()).step(5).send(dp.move_forward()).step(5).run()
    assert trace.state_at(t0 - 1)["state"] == "failsafe" and trace.state_at(t0 - 1)["armed"] is False
    after = trace.state_at(t0 + 1)
    assert after["state"] == "disarmed" and after["armed"] is False
    assert sticks(after) == fw.on_ground()
    assert trace.lines(since_ms=t0) == [fw.R.line(accepted(dp.servo_reset()), "disarmed", False),
                                        fw.R.line(rejected(dp.ErrorKind.NOT_ARMED), "disarmed", False)]


def test_a_frame_split_by_a_long_pause_is_dropped() -> None:
    frame = dp.move_forward(1600)
    script = fw.Script().arm()
    t0 = script.t_ms
    script.send(frame[:3]).step(dp.INTER_BYTE_TIMEOUT_MS + 5).send(frame[3:]).step(5)
    trace = script.send(dp.turn_right(1624)).step(5).run()
    replies = trace.replies(since_ms=t0)
    assert replies[0] == rejected(dp.ErrorKind.TIMEOUT)
    assert accepted(frame) not in replies
    assert replies[-1] == accepted(dp.turn_right(1624))  # the parser resynchronised
    assert all(c["pitch"] == fw.neutral()["pitch"] for c in trace.changes if c["t_ms"] >= t0)


def test_a_partial_frame_does_not_survive_a_silence_that_wraps_the_parsers_16_bit_gap() -> None:
    """feed() measures the gap in 16 bits; the failsafe drops the partial frame long before 65.536 s pass."""
    frame = dp.arm()
    script = fw.Script()
    script.step(dp.FAILSAFE_TIMEOUT_MS + 10)  # boot's failsafe is over: the next valid frame is honoured
    script.send(dp.servo_reset()).step(5)
    t0 = script.t_ms
    script.send(frame[:4]).step(65536).send(frame[4:]).step(5)
    trace = script.run()
    assert "arming" not in {c["state"] for c in trace.changes if c["t_ms"] >= t0}
    assert accepted(frame) not in trace.replies(since_ms=t0)


def test_a_frame_with_a_short_pause_is_accepted() -> None:
    frame = dp.move_forward(1600)
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(frame[:3]).step(dp.INTER_BYTE_TIMEOUT_MS - 2).send(frame[3:]).step(5).run()
    assert trace.replies(since_ms=t0) == [accepted(frame)]
    assert trace.first_change(since_ms=t0, state="moving")["pitch"] == 1600


@pytest.mark.parametrize(
    ("frame", "kind"),
    [
        (b"xf1600", dp.ErrorKind.BAD_CATEGORY),
        (b"mz1600", dp.ErrorKind.BAD_DIRECTION),
        (b"mf16a0", dp.ErrorKind.BAD_DIGIT),
        (b"mf0999", dp.ErrorKind.OUT_OF_RANGE),
        (b"mf2001", dp.ErrorKind.OUT_OF_RANGE),
        (b"sr0181", dp.ErrorKind.OUT_OF_RANGE),
        (b"sx0001", dp.ErrorKind.OUT_OF_RANGE),
        (b"100000", dp.ErrorKind.BAD_CATEGORY),
    ],
)
def test_malformed_frames_are_rejected_and_change_nothing(frame: bytes, kind: dp.ErrorKind) -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(frame).step(20).run()
    assert trace.replies(since_ms=t0)[0] == rejected(kind)
    assert not any(r.startswith("A") for r in trace.replies(since_ms=t0))
    assert [c for c in trace.changes if c["t_ms"] >= t0] == []


def test_movement_during_a_sequence_is_busy_but_disarm_always_wins() -> None:
    script = fw.Script().step(5).send(dp.arm()).step(100)
    script.send(dp.move_forward(1600)).step(5).send(dp.first_test()).step(5).send(dp.hold_altitude()).step(5)
    t_disarm = script.t_ms
    trace = script.send(dp.disarm()).step(5).run()
    assert trace.replies(since_ms=7) == [rejected(dp.ErrorKind.BUSY)] * 3 + [accepted(dp.disarm())]
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
    assert replies[0] == accepted(dp.first_test())
    assert replies[1] == rejected(dp.ErrorKind.BUSY)
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
    assert sticks(end) == fw.on_ground() and end["laser"] is False
    assert (end["pan"], end["tilt"]) == (pan.default, tilt.default)
    steps = len({(c["pan"], c["tilt"], c["laser"], c["roll"], c["pitch"], c["yaw"]) for c in run})
    assert end["t_ms"] - run[0]["t_ms"] >= (steps - 1) * SELF_TEST_STEP_MS
    # movements sent during the test were all refused as busy (disarmed afterwards: not armed)
    assert set(trace.replies(since_ms=run[0]["t_ms"] + 1)[1:]) <= {
        rejected(dp.ErrorKind.BUSY),
        rejected(dp.ErrorKind.NOT_ARMED),
    }


def test_self_test_is_refused_when_armed() -> None:
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(dp.first_test()).step(10).run()
    assert trace.lines(since_ms=t0) == [fw.R.line(rejected(dp.ErrorKind.ARMED), "armed", False)]
    assert [c for c in trace.changes if c["t_ms"] >= t0] == []


def test_a_burst_of_garbage_is_answered_once_and_does_not_delay_the_next_reply() -> None:
    garbage = bytes(range(0x80, 0x80 + 60)) * 10  # 600 bytes that are no category: one error each
    script = fw.Script().arm()
    t0 = script.t_ms
    for i in range(0, len(garbage), 50):
        script.send(garbage[i : i + 50]).step(5)
    t1 = script.t_ms
    trace = script.send(dp.move_up(1621)).step(5).stats().run()
    assert trace.stats[-1]["errors"]["bad_category"] == len(garbage)  # every byte counted...
    assert trace.replies(since_ms=t0) == [rejected(dp.ErrorKind.BAD_CATEGORY), accepted(dp.move_up(1621))]
    (t_reply,) = [t for t, text in trace.tx if t >= t1]
    assert t_reply == t1 + 1  # ...and answered once, so the next frame's reply leaves at once


def test_replies_never_block_when_the_transmit_buffer_is_full_they_are_dropped_and_counted() -> None:
    # Alternating error kinds ("mfX": bad digit, "Z": bad category) ask for 6 reply bytes per 4 bytes received:
    # more than the line can send, so the transmit buffer fills.
    noise = b"mfXZ" * 150
    script = fw.Script().arm()
    t0 = script.t_ms
    for i in range(0, len(noise), 40):
        script.send(noise[i : i + 40]).step(4)
    script.step(60)
    t1 = script.t_ms
    trace = script.send(dp.move_up(1621)).step(5).stats().run()
    stats = trace.stats[-1]
    assert stats["errors"]["bad_digit"] == 150 and stats["errors"]["bad_category"] >= 150
    sent = trace.replies(since_ms=t0)
    assert stats["replies_dropped"] > 0
    assert len(sent) - 1 + stats["replies_dropped"] == 300  # every reply either sent or counted as dropped
    # the loop was never held up: the next frame is served on time
    assert trace.first_change(since_ms=t1, state="moving")["t_ms"] == t1 + 1


@settings(max_examples=25, deadline=None)
@given(st.lists(st.binary(min_size=1, max_size=40), min_size=1, max_size=12), st.integers(0, 2**16))
def test_random_bytes_never_drive_an_output_outside_its_limits(chunks: list[bytes], seed: int) -> None:
    script = fw.Script().arm()
    for i, chunk in enumerate(chunks):
        script.send(chunk).step(1 + (seed >> (i % 16)) % 300)
    trace = script.step(dp.FAILSAFE_TIMEOUT_MS).run()
    since_boot = True  # the failsafe throttle is held from boot until the first sequence
    for c in trace.changes:
        since_boot = since_boot and c["state"] == "disarmed"
        for name in fw.STICKS:
            lim = dp.CHANNELS[name]
            ok = lim.minimum <= c[name] <= lim.maximum
            below = since_boot or c["state"] == "failsafe"
            assert ok or (name == "throttle" and c[name] == dp.FAILSAFE_THROTTLE_US and below), c
        for servo in ("pan", "tilt"):
            assert dp.SERVOS[servo].minimum <= c[servo] <= dp.SERVOS[servo].maximum
        assert c["mode"] in (dp.MODE_STABILIZE_US, dp.MODE_ALT_HOLD_US)
    assert trace.changes[-1]["state"] == "failsafe"  # silence at the end always ends in failsafe


def test_virtual_drone_over_a_pty_with_the_stepped_clock() -> None:
    """The pilot's simulator interface: JSON pty line, `step` lines on stdin, replies on the pty; opening the
    port reboots the virtual board as DTR reboots an Uno (ready line again, outputs back to boot state)."""
    proc = subprocess.Popen(
        [str(fw.VIRTUAL_DRONE), "--clock", "stepped"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert proc.stdin is not None and proc.stdout is not None
    stdin, stdout = proc.stdin, proc.stdout

    def step(ms: int) -> list[dict[str, Any]]:
        stdin.write(f"step {ms}\n")
        stdin.flush()
        lines = []
        while "tick" not in (line := json.loads(stdout.readline())):
            lines.append(line)
        return [*lines, line]

    def read_until(fd: int, end: bytes) -> bytes:
        received = b""
        while not received.endswith(end):
            ready, _, _ = select.select([fd], [], [], 5)
            assert ready, f"no reply on the pty, got {received!r}"
            received += os.read(fd, 256)
        return received

    try:
        pty = json.loads(stdout.readline())["pty"]
        boot = json.loads(stdout.readline())
        assert boot["state"] == "disarmed" and boot["t_ms"] == 0
        assert step(5) == [{"tick": 5}]
        fd = os.open(pty, os.O_RDWR | os.O_NOCTTY)
        try:
            assert not select.select([fd], [], [], 0.05)[0]  # the boot banner went nowhere: the port was closed
            os.write(fd, dp.laser_toggle())
            lines = step(10)
            assert lines[-1] == {"tick": 15}
            (change,) = lines[:-1]
            assert change["laser"] is True and change["t_ms"] == 6
            toggled = fw.R.line(fw.R.accepted(dp.laser_toggle()), "disarmed", True)
            ready = fw.R.ready().encode() + b"\n"
            assert read_until(fd, toggled.encode() + b"\n") == ready + toggled.encode() + b"\n"
        finally:
            os.close(fd)
        fd = os.open(pty, os.O_RDWR | os.O_NOCTTY)  # reopening resets the board
        try:
            lines = step(10)
            assert [c["laser"] for c in lines[:-1]] == [False]
            assert read_until(fd, b"\n") == ready
        finally:
            os.close(fd)
    finally:
        stdin.close()
        assert proc.wait(timeout=10) == 0
