"""The live view's HTTP server: one thread, non-blocking sockets, every resource bounded.

The pilot loop must never wait for a browser (the firmware's failsafe fires after a second without a frame), so
the server runs in a single thread over a selector and each client costs a socket and at most one frame of
output; ``Limits`` holds the bounds, and a client's error is one log line, at most one a second.
"""
from __future__ import annotations

import contextlib
import selectors
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from ..common.errors import PilotError


@dataclass(frozen=True)
class Limits:
    """What the server lets its clients take. At the socket limit a new connection closes the oldest one that is
    not a stream, so idle sockets cannot lock out Stop; a stream is offered a frame only once its previous one is
    fully sent, so a slow viewer misses frames and nothing queues."""

    viewers: int = 4  # MJPEG streams at once: a 20 Hz stream is about 0.5 MB/s
    connections: int = 32  # sockets at once (pages, state polls, Stop, streams)
    request_s: float = 5.0  # to send a whole request
    stall_s: float = 5.0  # a response that accepts no byte for this long is dropped
    max_request: int = 16384  # request line, headers and body
    accepts_per_s: float = 200.0  # new connections taken at most this often; more wait in the kernel's backlog


DEFAULT_LIMITS = Limits()


@dataclass(frozen=True)
class Response:
    status: int
    body: bytes
    kind: str = "application/json"


@dataclass(frozen=True)
class Stream:
    """Start an MJPEG stream: ``head`` goes out first, then the parts of ``Server.frames``."""

    kind: str


Handler = Callable[[str, str, str], "Response | Stream"]  # (method, path, client address) -> answer
Frames = Callable[[], "tuple[int, bytes] | None"]  # the newest (sequence number, part bytes), encoded on demand
Newest = Callable[[], int]  # the newest frame's sequence number (0: none yet), without encoding it

ACCEPT_BURST = 32.0
SEND_BUFFER = 128 * 1024  # the kernel's share of a viewer's backlog: two or three frames
REASONS = {200: "OK", 400: "Bad Request", 404: "Not Found", 405: "Method Not Allowed",
           408: "Request Timeout", 413: "Content Too Large", 503: "Service Unavailable"}


class _Conn:
    __slots__ = ("addr", "answered", "dropped", "inbox", "opened", "out", "progress", "seq", "sock", "stream")

    def __init__(self, sock: socket.socket, addr: str, now: float) -> None:
        self.sock, self.addr = sock, addr
        self.inbox = bytearray()
        self.out = bytearray()
        self.opened = self.progress = now
        self.answered = False  # a response is queued; close once it is sent (unless a stream)
        self.stream = False
        self.seq = 0
        self.dropped = 0


class _RateLimitedLog:
    def __init__(self, emit: Callable[[str], None], clock: Callable[[], float]) -> None:
        self._emit, self._clock = emit, clock
        self._last = -1e9
        self._held = 0

    def __call__(self, line: str) -> None:
        now = self._clock()
        if now - self._last < 1.0:
            self._held += 1
            return
        more = f" ({self._held} more client errors in the last {now - self._last:.0f} s)" if self._held else ""
        self._last, self._held = now, 0
        self._emit(f"live view: {line}{more}")


class Server:
    """Serves ``handler`` and, to streams, ``frames`` at up to ``fps``; ``close()`` stops it. ``frames`` is asked
    only when a viewer is behind ``newest`` and ready to take a frame."""

    def __init__(self, host: str, port: int, handler: Handler, frames: Frames, newest: Newest, *,
                 limits: Limits = DEFAULT_LIMITS,
                 fps: float = 25.0, log: Callable[[str], None] = print,
                 clock: Callable[[], float] = time.monotonic, warm_up: Callable[[], None] | None = None) -> None:
        if limits.viewers < 1 or limits.connections <= limits.viewers:
            raise PilotError(f"live view: {limits.connections} connections must exceed {limits.viewers} viewers")
        self.limits, self._handler, self._frames, self._period = limits, handler, frames, 1.0 / fps
        self._newest, self._warm_up = newest, warm_up
        self._clock = clock
        self.log = _RateLimitedLog(log, clock)
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        try:
            self._listener = socket.create_server((host, port), family=family, backlog=128)
        except OSError as exc:
            raise PilotError(f"option --serve: cannot listen on {host}:{port}: {exc.strerror or exc}") from exc
        self._listener.setblocking(False)
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._listener, selectors.EVENT_READ, None)
        self._sel.register(self._wake_r, selectors.EVENT_READ, None)
        self._conns: dict[int, _Conn] = {}
        self._tokens, self._refilled, self._listening = ACCEPT_BURST, self._clock(), True
        self._stopping = False
        self._ending = False
        self.refused = 0  # streams refused at the viewer limit
        self.evicted = 0  # connections closed to make room
        self.timed_out = 0  # connections closed for silence or a stall
        self.cpu_s = 0.0  # the server thread's own processor time
        self.longest_busy_s = 0.0  # the most processor time between two waits: the longest it can hold the GIL
        self.dropped = 0  # frames not sent to a viewer that was still taking the previous one
        self._thread = threading.Thread(target=self._serve, name="liveview", daemon=True)
        self._thread.start()

    @property
    def address(self) -> tuple[str, int]:
        host, port = self._listener.getsockname()[:2]
        return str(host), int(port)

    @property
    def viewers(self) -> int:
        return sum(1 for c in list(self._conns.values()) if c.stream)

    @property
    def connections(self) -> int:
        return len(self._conns)

    def end_streams(self) -> None:
        """Streams end once their current frame is out (the flight is over)."""
        self._ending = True
        self._wake()

    def close(self) -> None:
        if self._stopping:
            return
        self._stopping = True
        self._wake()
        self._thread.join(timeout=5)
        for conn in list(self._conns.values()):
            self._drop(conn)
        self._sel.close()
        for sock in (self._listener, self._wake_r, self._wake_w):
            sock.close()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):  # the pair is full (already woken) or closed
            self._wake_w.send(b"x")

    # -- the server thread -------------------------------------------------------------------------------------
    def _serve(self) -> None:
        if self._warm_up is not None:  # whatever the thread's first frame would otherwise pay for
            self._warm_up()
        next_frame = self._clock()
        while not self._stopping:
            now = self._clock()
            self._refill(now)
            timeout = max(0.0, min(next_frame - now, 0.25)) if self.viewers else 0.25
            if not self._listening:
                timeout = min(timeout, 1.0 / self.limits.accepts_per_s)
            ready = self._sel.select(timeout)
            busy_from = time.thread_time()
            for key, events in ready:
                if key.fileobj is self._listener:
                    self._accept()
                elif key.fileobj is self._wake_r:
                    with contextlib.suppress(OSError):
                        self._wake_r.recv(4096)
                else:
                    conn = key.data
                    if events & selectors.EVENT_READ:
                        self._read(conn)
                    if events & selectors.EVENT_WRITE and conn.sock.fileno() in self._conns:
                        self._send(conn)
            now = self._clock()
            if now >= next_frame:
                next_frame = now + self._period
                self._offer_frame()
            self._expire(now)
            self.cpu_s = time.thread_time()
            self.longest_busy_s = max(self.longest_busy_s, self.cpu_s - busy_from)

    def _refill(self, now: float) -> None:
        self._tokens = min(ACCEPT_BURST, self._tokens + (now - self._refilled) * self.limits.accepts_per_s)
        self._refilled = now
        if self._tokens >= 1.0 and not self._listening:
            self._sel.register(self._listener, selectors.EVENT_READ, None)
            self._listening = True

    def _accept(self) -> None:
        while True:
            if self._tokens < 1.0:  # until the bucket refills, the backlog waits
                self._sel.unregister(self._listener)
                self._listening = False
                return
            try:
                sock, addr = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:  # out of descriptors: the backlog waits
                self.log(f"cannot accept a connection: {exc.strerror or exc}")
                return
            self._tokens -= 1.0
            if len(self._conns) >= self.limits.connections and not self._evict():
                sock.close()
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER)  # no megabytes queued in the kernel
            conn = _Conn(sock, str(addr[0]), self._clock())
            self._conns[sock.fileno()] = conn
            self._sel.register(sock, selectors.EVENT_READ, conn)

    def _evict(self) -> bool:
        """Close the oldest connection that is not a stream, preferring those still silent."""
        waiting = [c for c in self._conns.values() if not c.stream]
        if not waiting:
            return False
        victim = min(waiting, key=lambda c: (c.answered, c.opened))
        self.evicted += 1
        self.log(f"{victim.addr}: closed to make room ({self.limits.connections} connections open)")
        self._drop(victim)
        return True

    def _read(self, conn: _Conn) -> None:
        try:
            data = conn.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._fail(conn, exc.strerror or str(exc))
            return
        if not data:  # the client left
            self._drop(conn)
            return
        if conn.answered:
            return  # nothing more is read from a client once it is answered
        conn.inbox += data
        if len(conn.inbox) > self.limits.max_request:
            self._answer(conn, Response(413, b"request too large\n", "text/plain"))
            return
        end = conn.inbox.find(b"\r\n\r\n")
        if end < 0:
            return
        head = bytes(conn.inbox[:end]).decode("latin-1")
        lines = head.split("\r\n")
        parts = lines[0].split(" ")
        length = 0
        for line in lines[1:]:
            name, _, value = line.partition(":")
            if name.strip().lower() == "content-length":
                length = int(value.strip()) if value.strip().isdigit() else -1
        if len(parts) != 3 or not parts[2].startswith("HTTP/") or length < 0:
            self.log(f"{conn.addr}: bad request {lines[0][:60]!r}")
            self._answer(conn, Response(400, b"bad request\n", "text/plain"))
            return
        if len(conn.inbox) < end + 4 + length:
            return  # the body is still coming (bounded by max_request)
        try:
            answer = self._handler(parts[0], parts[1], conn.addr)
        except Exception as exc:  # a page error never takes the server (or the flight) down
            self.log(f"{conn.addr}: {parts[0]} {parts[1][:60]!r} failed: {type(exc).__name__}: {exc}")
            answer = Response(500, b"internal error\n", "text/plain")
        if isinstance(answer, Stream):
            if self.viewers >= self.limits.viewers:
                self.refused += 1
                self.log(f"{conn.addr}: stream refused, {self.limits.viewers} viewers already (--serve-viewers)")
                answer = Response(503, b"too many viewers\n", "text/plain")
            else:
                conn.stream = True
                self._queue(conn, self._head(200, answer.kind, None))
                conn.answered = True
                return
        self._answer(conn, answer)

    @staticmethod
    def _head(status: int, kind: str, length: int | None) -> bytes:
        lines = [f"HTTP/1.1 {status} {REASONS.get(status, 'Error')}", f"Content-Type: {kind}",
                 "Cache-Control: no-store", "Connection: close", "Server: pilot-liveview"]
        if length is not None:
            lines.append(f"Content-Length: {length}")
        if status == 503:
            lines.append("Retry-After: 5")
        return ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1")

    def _answer(self, conn: _Conn, answer: Response) -> None:
        conn.answered = True
        self._queue(conn, self._head(answer.status, answer.kind, len(answer.body)) + answer.body)

    def _queue(self, conn: _Conn, data: bytes) -> None:
        if not conn.out:
            conn.progress = self._clock()  # the stall clock starts when there is something to send
        conn.out += data
        self._send(conn)

    def _send(self, conn: _Conn) -> None:
        try:
            n = conn.sock.send(conn.out)
        except (BlockingIOError, InterruptedError):
            n = 0
        except OSError as exc:
            self._fail(conn, exc.strerror or str(exc))
            return
        if n:
            del conn.out[:n]
            conn.progress = self._clock()
        if conn.out:
            self._sel.modify(conn.sock, selectors.EVENT_READ | selectors.EVENT_WRITE, conn)
        elif conn.answered and (not conn.stream or self._ending):
            self._drop(conn)
        else:
            self._sel.modify(conn.sock, selectors.EVENT_READ, conn)

    def _offer_frame(self) -> None:
        streams = [c for c in self._conns.values() if c.stream]
        if not streams:
            return
        if self._ending:
            for conn in streams:
                if not conn.out:
                    self._drop(conn)
            return
        newest = self._newest()
        ready = []
        for conn in streams:
            if conn.seq >= newest:
                continue
            if conn.out:  # still taking an earlier frame: this one is skipped, never queued
                conn.dropped += 1
                self.dropped += 1
            else:
                ready.append(conn)
        if not ready:  # nobody can take it: it is not even encoded
            return
        frame = self._frames()
        if frame is None:
            return
        seq, part = frame
        for conn in ready:
            conn.seq = seq
            self._queue(conn, part)

    def _expire(self, now: float) -> None:
        for conn in list(self._conns.values()):
            if not conn.answered and now - conn.opened > self.limits.request_s:
                self.log(f"{conn.addr}: no request within {self.limits.request_s:g} s, closed")
                self.timed_out += 1
                self._drop(conn)
            elif conn.out and now - conn.progress > self.limits.stall_s:
                self.log(f"{conn.addr}: took no data for {self.limits.stall_s:g} s, closed")
                self.timed_out += 1
                self._drop(conn)

    def _fail(self, conn: _Conn, why: str) -> None:
        self.log(f"{conn.addr}: {why}")
        self._drop(conn)

    def _drop(self, conn: _Conn) -> None:
        fd = conn.sock.fileno()
        if fd >= 0 and self._conns.get(fd) is conn:
            del self._conns[fd]
            with contextlib.suppress(KeyError, ValueError):
                self._sel.unregister(conn.sock)
        conn.sock.close()
