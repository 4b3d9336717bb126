"""Host tests of the firmware logic on the link: the failsafe, garbage and split frames, malformed frames, a full
transmit buffer, random bytes, and the virtual drone over a pseudo-terminal (stepped clock, no real time)."""

from __future__ import annotations

import json
import math
import os
import select
import subprocess
from typing import Any

import drone_protocol as dp
import fwsupport as fw
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


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
    assert trace.replies(since_ms=dp.FAILSAFE_TIMEOUT_MS + 10) == [fw.rejected(dp.ErrorKind.NOT_ARMED)]
    recovered = trace.changes[-1]
    assert recovered["state"] == "disarmed" and fw.sticks(recovered) == fw.on_ground()
    assert recovered["t_ms"] == dp.FAILSAFE_TIMEOUT_MS + 11


def test_an_armed_drone_leaving_failsafe_is_disarmed_and_must_arm_again() -> None:
    script = fw.Script().arm()
    script.step(dp.FAILSAFE_TIMEOUT_MS + 10)
    t0 = script.t_ms
    trace = script.send(dp.servo_reset()).step(5).send(dp.move_forward()).step(5).run()
    assert trace.state_at(t0 - 1)["state"] == "failsafe" and trace.state_at(t0 - 1)["armed"] is False
    after = trace.state_at(t0 + 1)
    assert after["state"] == "disarmed" and after["armed"] is False
    assert fw.sticks(after) == fw.on_ground()
    assert trace.lines(since_ms=t0) == [fw.R.line(fw.accepted(dp.servo_reset()), "disarmed", False),
                                        fw.R.line(fw.rejected(dp.ErrorKind.NOT_ARMED), "disarmed", False)]


def test_a_frame_split_by_a_long_pause_is_dropped() -> None:
    frame = dp.move_forward(1600)
    script = fw.Script().arm()
    t0 = script.t_ms
    script.send(frame[:3]).step(dp.INTER_BYTE_TIMEOUT_MS + 5).send(frame[3:]).step(5)
    trace = script.send(dp.turn_right(1624)).step(5).run()
    replies = trace.replies(since_ms=t0)
    assert replies[0] == fw.rejected(dp.ErrorKind.TIMEOUT)
    assert fw.accepted(frame) not in replies
    assert replies[-1] == fw.accepted(dp.turn_right(1624))  # the parser resynchronised
    assert all(c["pitch"] == fw.neutral()["pitch"] for c in trace.changes if c["t_ms"] >= t0)


def test_a_partial_frame_does_not_survive_a_silence_of_65536_ms() -> None:
    """A silence of 2^16 ms (where a 16-bit gap would read 0): the partial frame is dropped, not completed."""
    frame = dp.arm()
    script = fw.Script()
    script.step(dp.FAILSAFE_TIMEOUT_MS + 10)  # boot's failsafe is over: the next valid frame is honoured
    script.send(dp.servo_reset()).step(5)
    t0 = script.t_ms
    script.send(frame[:4]).step(65536).send(frame[4:]).step(5)
    trace = script.run()
    assert "arming" not in {c["state"] for c in trace.changes if c["t_ms"] >= t0}
    assert fw.accepted(frame) not in trace.replies(since_ms=t0)


def test_a_frame_with_a_short_pause_is_accepted() -> None:
    frame = dp.move_forward(1600)
    script = fw.Script().arm()
    t0 = script.t_ms
    trace = script.send(frame[:3]).step(dp.INTER_BYTE_TIMEOUT_MS - 2).send(frame[3:]).step(5).run()
    assert trace.replies(since_ms=t0) == [fw.accepted(frame)]
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
    assert trace.replies(since_ms=t0)[0] == fw.rejected(kind)
    assert not any(r.startswith("A") for r in trace.replies(since_ms=t0))
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
    assert trace.replies(since_ms=t0) == [fw.rejected(dp.ErrorKind.BAD_CATEGORY), fw.accepted(dp.move_up(1621))]
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
    # the silence counts from the last byte off the wire: bytes sent faster than the line carries them (10 bits each)
    # are still arriving, at most all of them
    on_wire_ms = math.ceil(sum(len(c) for c in chunks) * 10_000 / dp.BAUD)
    trace = script.step(on_wire_ms + dp.FAILSAFE_TIMEOUT_MS).run()
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

    def step(ms: int, sent: int | None = None) -> list[dict[str, Any]]:
        stdin.write(f"step {ms}\n" if sent is None else f"step {ms} {sent}\n")
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
        assert step(5) == [{"tick": 5, "wrote": 0}]
        fd = os.open(pty, os.O_RDWR | os.O_NOCTTY)
        try:
            assert not select.select([fd], [], [], 0.05)[0]  # the boot banner went nowhere: the port was closed
            # the step waits for the bytes the client says it wrote, and counts the bytes it wrote back
            os.write(fd, dp.laser_toggle())
            lines = step(10, sent=len(dp.laser_toggle()))
            toggled = fw.R.line(fw.R.accepted(dp.laser_toggle()), "disarmed", True)
            ready = fw.R.ready().encode() + b"\n"
            assert lines[-1] == {"tick": 15, "wrote": len(ready) + len(toggled) + 1}
            (change,) = lines[:-1]
            assert change["laser"] is True and change["t_ms"] == 6
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
