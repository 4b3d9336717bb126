"""The serial link to the drone's Arduino, over any pyserial URL or port.

* ``open()`` opens the port (``serial_for_url``: ``/dev/ttyACM0``, ``loop://``, ``socket://``, a pty)
  and waits for the firmware's ready line (opening the port resets an Arduino); a ready line whose
  spec fingerprint differs from ``drone_protocol.SPEC_FINGERPRINT`` raises ``FingerprintMismatch``.
* ``send(frame)`` writes one frame (from a ``drone_protocol`` function) and flushes it.
* ``poll()`` reads whatever replies have arrived, parses each line with ``parse_reply`` and logs it;
  lines are bounded, garbage is logged and dropped.
* A failed read or write closes the port and reopens it within ``reconnect_s``, waiting for the ready
  line again. Meanwhile nothing is sent: the firmware's own failsafe keeps the drone safe. If the port
  is not back in time, ``PortLost`` is raised, and every later ``send`` raises it at once: nothing more
  can reach the drone, so nothing pretends to.

The link is a context manager; ``close()`` is safe to call twice.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import drone_protocol as dp
import serial

from ..common.closing import Closing
from ..common.errors import FingerprintMismatch, LinkError, PortLost, ReadyTimeout

if TYPE_CHECKING:
    from typing_extensions import Self

MAX_LINE = 128
LOG_HISTORY = 2000  # the link's own log: the latest entries (about 50 s of traffic at 20 Hz)


@dataclass(frozen=True)
class LogEntry:
    t: float
    kind: str  # "tx", "rx", "rx-garbage", "link"
    data: str


def _open_keeping_input(url: str, baud: int) -> Any:
    """Open a port or URL without pyserial's input flush on open.

    pyserial discards waiting input when it opens a port (``socket://`` even reads it away). A real
    Arduino resets on open and prints its ready line afterwards, but a board, a serial bridge or the
    virtual drone's pseudo-terminal that was already running may have printed it just before:
    discarding it would make the ready-line wait fail. Nothing is lost by keeping stale input:
    ``await_ready`` skips every line before the ready line.
    """
    port = serial.serial_for_url(url, baudrate=baud, timeout=0, write_timeout=1.0, do_not_open=True)
    names = ("reset_input_buffer", "_reset_input_buffer")
    for name in names:
        setattr(port, name, lambda: None)  # instance overrides, for open() only
    try:
        port.open()
    finally:
        for name in names:
            delattr(port, name)
    return port


def keepalive_ms(fraction: float) -> int:
    """The keep-alive period: a fraction of the firmware's command timeout, so it never lapses."""
    return max(1, int(dp.COMMAND_TIMEOUT_MS * fraction))


class Link(Closing):
    def __init__(
        self,
        port: str | Any,
        baud: int = dp.BAUD,
        *,
        ready_timeout_s: float = dp.READY_TIMEOUT_MS / 1000.0,
        reconnect_s: float = 3.0,
        wait_ready: bool = True,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
        log: Callable[[LogEntry], None] | None = None,
        ready_clock: Callable[[], float] | None = None,
        ready_sleep: Callable[[float], None] | None = None,
        on_open: Callable[[], None] | None = None,
        history: int = 100_000,
    ) -> None:
        self._url = port if isinstance(port, str) else None
        self._port: Any = None if isinstance(port, str) else port
        self.baud = baud
        self.ready_timeout_s = ready_timeout_s
        self.reconnect_s = reconnect_s
        self.wait_ready = wait_ready
        self._clock = clock  # time stamps of the log
        # waiting for the ready line and reopening a lost port may use their own clock: the simulator
        # waits for the kernel there, not for simulated time
        self._ready_clock = ready_clock or clock
        self._ready_sleep = ready_sleep or sleep
        self._log = log  # a subscriber (the recorder): its failure never reaches the link's caller
        self.log: deque[LogEntry] = deque(maxlen=LOG_HISTORY)  # the link's own log, bounded
        # called after every (re)opening of the port, before the ready-line wait: the simulator runs
        # the virtual board's reboot there (opening the port resets it, as DTR resets an Uno)
        self._on_open = on_open
        self._buffer = bytearray()
        # bytes written to and read from the port since it was (re)opened: the simulator's step barrier
        self.bytes_written = 0
        self.bytes_read = 0
        self._closed = False
        self._opened = False
        self.sent: deque[bytes] = deque(maxlen=history)  # the latest frames written, in order
        self.replies: deque[dp.Reply] = deque(maxlen=history)
        self.ready: dp.Reply | None = None
        self.reconnects = 0
        self.last_send_t: float | None = None
        self.last_write_done_t: float | None = None

    @property
    def name(self) -> str:
        if self._url is not None:
            return self._url
        return str(getattr(self._port, "port", None) or self._port)

    def _note(self, kind: str, data: str) -> None:
        entry = LogEntry(self._clock(), kind, data)
        self.log.append(entry)
        if self._log is not None:
            try:
                self._log(entry)
            except Exception as exc:  # the link carries on; its own log keeps the traffic
                self._log = None
                print(f"pilot: the link's log subscriber failed ({type(exc).__name__}: {exc}); "
                      "the link goes on without it", file=sys.stderr, flush=True)

    # -- opening ----------------------------------------------------------------------------------
    def _open_port(self) -> None:
        if self._url is None:
            if self._port is None:
                raise LinkError("link: no port to open")
            return
        try:
            self._port = _open_keeping_input(self._url, self.baud)
            self.bytes_written = self.bytes_read = 0
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkError(f"link {self._url!r}: cannot open: {exc}") from exc

    def open(self) -> Self:
        self._closed = False
        self._open_port()
        self._opened = True
        self._note("link", f"opened {self.name}")
        if self._on_open is not None:
            self._on_open()
        if self.wait_ready:
            self.await_ready()
        return self

    def await_ready(self, timeout_s: float | None = None) -> dp.Reply:
        """Read lines until the ready line; refuse another spec's fingerprint."""
        limit = self.ready_timeout_s if timeout_s is None else timeout_s
        deadline = self._ready_clock() + limit
        while True:
            for line in self._read_lines():
                reply = self._parse(line)
                if reply is None:
                    continue
                if reply.kind is dp.ReplyKind.READY:
                    if reply.fingerprint != dp.SPEC_FINGERPRINT or reply.protocol != dp.PROTOCOL_NAME:
                        theirs = f"{reply.protocol} {reply.fingerprint}"
                        raise FingerprintMismatch(f"{dp.PROTOCOL_NAME} {dp.SPEC_FINGERPRINT}", theirs)
                    self.ready = reply
                    return reply
            if self._ready_clock() >= deadline:
                raise ReadyTimeout(
                    f"link {self.name!r}: no ready line ('{dp.ReplyKind.READY.value} {dp.PROTOCOL_NAME} ...') "
                    f"within {limit:.1f} s; is the drone firmware running on this port?"
                )
            self._ready_sleep(0.005)

    # -- I/O ----------------------------------------------------------------------------------------
    def _read_lines(self) -> list[bytes]:
        if self._port is None:
            return []
        waiting = self._port.in_waiting  # some handlers (socket://) only say 0 or 1
        chunk = self._port.read(max(waiting, 256)) if waiting else b""
        if not chunk:
            return []
        self.bytes_read += len(chunk)
        self._buffer.extend(chunk)
        lines: list[bytes] = []
        while True:
            nl = self._buffer.find(b"\n")
            if nl < 0:
                break
            lines.append(bytes(self._buffer[: nl + 1]))
            del self._buffer[: nl + 1]
        if len(self._buffer) > MAX_LINE:  # no newline in sight: garbage, drop it
            self._note("rx-garbage", self._buffer.decode("ascii", "replace"))
            self._buffer.clear()
        return lines

    def unread(self) -> int | None:
        """Bytes waiting on the port, not yet read; None when the port cannot say (closed or failed)."""
        try:
            return None if self._port is None else int(self._port.in_waiting)
        except (serial.SerialException, OSError):
            return None

    def send(self, frame: bytes) -> bool:
        """Write one frame. Returns False when the port failed and could not be reopened in time."""
        if self._closed:
            raise LinkError(f"link {self.name!r}: send after close")
        if self._port is None:
            raise PortLost(f"serial port {self.name!r} is gone (lost earlier and not reopened)")
        self.last_send_t = self._clock()
        try:
            self._port.write(frame)
            self._port.flush()
            self.bytes_written += len(frame)
        except (serial.SerialException, OSError) as exc:
            self._note("link", f"write failed: {exc}")
            return self._recover() and self.send(frame)
        self.last_write_done_t = self._clock()
        self.sent.append(frame)
        self._note("tx", frame.decode("ascii", "replace"))
        return True

    def poll(self) -> list[dp.Reply]:
        """Replies that have arrived since the last poll."""
        try:
            lines = self._read_lines()
        except (serial.SerialException, OSError) as exc:
            self._note("link", f"read failed: {exc}")
            self._recover()
            return []
        out: list[dp.Reply] = []
        for line in lines:
            reply = self._parse(line)
            if reply is not None:
                out.append(reply)
        self.replies.extend(out)
        return out

    def _parse(self, line: bytes) -> dp.Reply | None:
        """A reply line, logged; None (logged as garbage) when it is not one of the spec's replies."""
        try:
            reply = dp.parse_reply(line)
        except dp.ProtocolError:
            self._note("rx-garbage", line.decode("ascii", "replace"))
            return None
        self._note("rx", line.decode("ascii", "replace").rstrip())
        return reply

    def _recover(self) -> bool:
        """Close and reopen the port within ``reconnect_s``; wait for the ready line again."""
        if self._url is None:
            self._close_port()
            raise PortLost(f"serial port {self.name!r} failed and this link cannot reopen it")
        self._close_port()
        deadline = self._ready_clock() + self.reconnect_s
        delay = 0.05
        while self._ready_clock() < deadline:
            try:
                self._open_port()
                if self._on_open is not None:
                    self._on_open()
                if self.wait_ready:
                    self.await_ready(timeout_s=max(0.1, deadline - self._ready_clock()))
                self.reconnects += 1
                self._note("link", f"reopened {self.name} (reconnect {self.reconnects})")
                return True
            except FingerprintMismatch:
                raise
            except LinkError as exc:
                self._note("link", f"reopen failed: {exc}")
                self._close_port()
                self._ready_sleep(delay)
                delay = min(0.5, delay * 2)
        raise PortLost(f"serial port {self.name!r} lost and not back within {self.reconnect_s:.1f} s")

    # -- closing ----------------------------------------------------------------------------------
    def _close_port(self) -> None:
        port, self._port = self._port, None
        if port is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                port.close()
        self._buffer.clear()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._close_port()
        self._note("link", "closed")

    def __enter__(self) -> Self:  # opens the port, unlike Closing's
        return self if self._opened else self.open()
