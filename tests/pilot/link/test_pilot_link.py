"""The serial link over loop://, a pseudo-terminal and socket://: exact frames, the ready wait, a
refused fingerprint, a disconnect and reconnect."""

from __future__ import annotations

import os
import select
import socket
import threading
import time
import tty
from collections.abc import Iterator

import drone_protocol as dp
import pytest
import serial

from pilot.common.errors import FingerprintMismatch, LinkError, PortLost, ReadyTimeout
from pilot.link.serial_link import Link, LogEntry, keepalive_ms

FRAMES = [
    dp.arm(),
    dp.hold_altitude(),
    dp.move_forward(1650),
    dp.turn_left(),
    dp.servo_right(12),
    dp.servo_reset(),
    dp.laser_toggle(),
    dp.move_down(1400),
    dp.disarm(),
]

# The drone state the fake peer reports in its replies.
ST = dp.DroneState.ARMED
OTHER_FINGERPRINT = "f" * len(dp.SPEC_FINGERPRINT)


def other_ready_line() -> bytes:
    """The generated ready line with another spec's fingerprint in it."""
    return dp.ready_line().replace(dp.SPEC_FINGERPRINT.encode(), OTHER_FINGERPRINT.encode())


class FakeClock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t

    def sleep(self, s: float) -> None:
        self.t += s


def test_keepalive_is_shorter_than_the_command_timeout() -> None:
    assert keepalive_ms(0.4) < dp.COMMAND_TIMEOUT_MS
    assert keepalive_ms(0.4) == int(dp.COMMAND_TIMEOUT_MS * 0.4)


def test_loop_frames_on_the_wire_are_exactly_the_encoder_output() -> None:
    port = serial.serial_for_url("loop://", timeout=0)
    port.write(b"noise before boot\n" + dp.ready_line())
    log: list[LogEntry] = []
    with Link(port, log=log.append) as link:
        assert link.ready is not None and link.ready.fingerprint == dp.SPEC_FINGERPRINT
        for frame in FRAMES:
            assert link.send(frame)
        wire = port.read(1000)
    assert wire == b"".join(FRAMES)
    assert list(link.sent) == FRAMES
    assert [e.data for e in log if e.kind == "tx"] == [f.decode() for f in FRAMES]
    assert any(e.kind == "rx-garbage" and "noise" in e.data for e in log)


def test_ready_wait_times_out_with_a_clear_message() -> None:
    clock = FakeClock()
    port = serial.serial_for_url("loop://", timeout=0)
    port.write(dp.accepted_line(dp.decode(dp.arm()), ST, False))  # a valid reply, but not the ready line
    link = Link(port, ready_timeout_s=2.0, clock=clock, sleep=clock.sleep)
    with pytest.raises(ReadyTimeout, match=r"no ready line .* within 2\.0 s"):
        link.open()
    assert 2.0 <= clock.t < 2.1  # waited on the injected clock, not in real time


def test_fingerprint_mismatch_is_refused() -> None:
    port = serial.serial_for_url("loop://", timeout=0)
    port.write(other_ready_line())
    link = Link(port)
    with pytest.raises(FingerprintMismatch) as info:
        link.open()
    message = str(info.value)
    assert dp.SPEC_FINGERPRINT in message and OTHER_FINGERPRINT in message and "refusing" in message
    assert isinstance(info.value, LinkError)


def test_replies_are_parsed_bounded_and_garbage_is_logged() -> None:
    port = serial.serial_for_url("loop://", timeout=0)
    port.write(dp.ready_line())
    log: list[LogEntry] = []
    link = Link(port, log=log.append).open()
    port.write(dp.accepted_line(dp.decode(dp.turn_left()), ST, False))
    port.write(dp.rejected_line(dp.ErrorKind.NOT_ARMED, ST, False))
    port.write(b"?? what\n")
    port.write(dp.failsafe_line(dp.DroneState.FAILSAFE, False))
    replies = link.poll()
    assert [r.kind for r in replies] == [dp.ReplyKind.ACCEPTED, dp.ReplyKind.REJECTED, dp.ReplyKind.FAILSAFE]
    assert replies[0].category is dp.Category.TURN and replies[1].error is dp.ErrorKind.NOT_ARMED
    assert any(e.kind == "rx-garbage" for e in log)
    port.write(b"x" * 500)  # no newline ever: dropped, not buffered without bound
    assert link.poll() == []
    assert len(link._buffer) <= 128
    link.close()
    link.close()  # safe twice
    with pytest.raises(LinkError):
        link.send(dp.arm())


@pytest.fixture
def pty_pair() -> Iterator[tuple[int, str]]:
    master, slave = os.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    yield master, path
    os.close(master)
    os.close(slave)


def read_exactly(fd: int, n: int, timeout: float = 5.0) -> bytes:
    data = b""
    deadline = time.monotonic() + timeout
    while len(data) < n and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            data += os.read(fd, n - len(data))
    return data


def test_pty_ready_frames_and_replies(pty_pair: tuple[int, str]) -> None:
    master, path = pty_pair
    os.write(master, b"boot noise\n" + dp.ready_line())  # written before the pilot opens the port
    with Link(path, ready_timeout_s=5.0) as link:
        assert link.ready is not None
        for frame in FRAMES:
            link.send(frame)
        wire = read_exactly(master, sum(len(f) for f in FRAMES))
        assert wire == b"".join(FRAMES)
        os.write(master, dp.accepted_line(dp.decode(FRAMES[0]), ST, False)
                 + dp.rejected_line(dp.ErrorKind.BUSY, ST, False))
        replies: list[dp.Reply] = []
        deadline = time.monotonic() + 5.0
        while len(replies) < 2 and time.monotonic() < deadline:
            replies += link.poll()
            time.sleep(0.005)
        assert [r.kind for r in replies] == [dp.ReplyKind.ACCEPTED, dp.ReplyKind.REJECTED]
        assert replies[0].direction == dp.InitDirection.ARM.value


def test_pty_fingerprint_mismatch_refused(pty_pair: tuple[int, str]) -> None:
    master, path = pty_pair
    os.write(master, other_ready_line())
    with pytest.raises(FingerprintMismatch, match="refusing to fly"):
        Link(path, ready_timeout_s=5.0).open()


class DroppingServer:
    """A socket:// firmware stand-in: each connection gets the ready line, then the server records
    what arrives; ``drop()`` closes the current connection (a pulled cable)."""

    def __init__(self) -> None:
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(4)
        self.port = self.sock.getsockname()[1]
        self.received: list[bytearray] = []
        self.conn: socket.socket | None = None
        self._stop = False
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        self.sock.settimeout(0.05)
        while not self._stop:
            try:
                conn, _ = self.sock.accept()
            except (TimeoutError, OSError):
                continue
            buf = bytearray()
            self.received.append(buf)
            self.conn = conn
            conn.sendall(dp.ready_line())
            conn.settimeout(0.05)
            while not self._stop:
                try:
                    chunk = conn.recv(100)
                except TimeoutError:
                    continue
                except OSError:
                    break
                if not chunk:
                    break
                buf.extend(chunk)

    def drop(self) -> None:
        if self.conn is not None:
            self.conn.shutdown(socket.SHUT_RDWR)
            self.conn.close()

    def close(self) -> None:
        self._stop = True
        self.drop()
        self.sock.close()
        self._thread.join(timeout=2)


def wait_for(cond: object, timeout: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if callable(cond) and cond():
            return True
        time.sleep(0.01)
    return False


def test_socket_disconnect_and_reconnect() -> None:
    server = DroppingServer()
    try:
        log: list[LogEntry] = []
        with Link(f"socket://127.0.0.1:{server.port}", reconnect_s=5.0, log=log.append) as link:
            link.send(dp.arm())
            assert wait_for(lambda: bytes(server.received[0]) == dp.arm())
            server.drop()
            # the pilot keeps ticking: polls and sends notice the loss and reopen the port
            assert wait_for(lambda: (link.poll() is not None and link.reconnects == 1))
            assert link.send(dp.hold_altitude())
            assert wait_for(lambda: len(server.received) == 2 and bytes(server.received[1]) == dp.hold_altitude())
            assert link.ready is not None
        assert any("reopened" in e.data for e in log)
    finally:
        server.close()


def test_reconnect_gives_up_after_its_time_with_a_clear_error() -> None:
    server = DroppingServer()
    clock = FakeClock()
    link = Link(f"socket://127.0.0.1:{server.port}", reconnect_s=1.0, ready_timeout_s=5.0)
    link.open()
    link._ready_clock = clock  # reconnect attempts on the injected clock from here on
    link._ready_sleep = clock.sleep
    server.close()  # gone for good
    with pytest.raises(PortLost, match=r"not back within 1\.0 s"):
        for _ in range(100):
            link.poll()
            link.send(dp.hold_altitude())
            time.sleep(0.01)
    # nothing more can reach the drone: every later send says so at once (never an AttributeError on None)
    with pytest.raises(PortLost, match="is gone"):
        link.send(dp.land())
    assert link.poll() == []
    link.close()
