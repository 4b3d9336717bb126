"""``--serve HOST:PORT``: a live view of the flight in a browser, with an emergency Stop.

Served by ``liveserver.py`` under a random token printed at start-up (``http://127.0.0.1:8080/<token>/``), so the
page and its Stop need the URL. The pilot loop only stores a reference to the newest tick under a short lock; the
server's thread draws the overlay and encodes each frame once, off the control loop.
"""
from __future__ import annotations

import json
import secrets
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from http import HTTPStatus
from importlib import resources
from typing import Any

import cv2
import drone_protocol as dp

from ..common.errors import PilotError
from .liveserver import DEFAULT_LIMITS, Limits, Response, Server, Stream
from .observers import StopSwitch
from .overlay import annotate
from .runner import Tick

BOUNDARY = "liveviewframe"
HISTORY = 12  # commands shown on the page
JPEG_QUALITY = 80
MAX_FPS = 25.0  # per viewer: the camera's rate is 20 Hz; an unpaced (simulated) loop need not be encoded faster


def parse_address(text: str) -> tuple[str, int]:
    """``PORT``, ``:PORT`` or ``HOST:PORT``; the host defaults to 127.0.0.1 (this machine only)."""
    host, sep, port_text = text.rpartition(":")
    host = host.strip("[]") if sep else ""
    try:
        port = int(port_text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise PilotError(f"option --serve: expected PORT or HOST:PORT (e.g. 8080 or 0.0.0.0:8080), got {text!r}")
    return host or "127.0.0.1", port


class _Shared:
    """What the loop thread hands to the server threads, under one lock."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.tick: Tick | None = None
        self.t = 0.0
        self.capture_ms = 0.0
        self.seq = 0
        self.last_command = ""
        self.commands: deque[dict[str, Any]] = deque(maxlen=HISTORY)
        self.reply_times: deque[float] = deque()
        self.send_times: deque[float] = deque()
        self.rejected: deque[float] = deque()
        self.last_reply_t: float | None = None
        self.ended = ""


class LiveView:
    """An observer of the pilot loop that serves it; ``close()`` stops the server."""

    def __init__(
        self,
        host: str,
        port: int,
        stop: StopSwitch,
        *,
        token: str | None = None,
        wall_time: Callable[[], float] = time.time,
        limits: Limits = DEFAULT_LIMITS,
        log: Callable[[str], None] | None = None,
    ) -> None:
        self.stop = stop
        self.token = token or secrets.token_urlsafe(16)
        self._wall_time = wall_time
        self._shared = _Shared()
        self._t0: float | None = None
        self._encoded: tuple[int, bytes] | None = None  # (seq, MJPEG part): the newest frame, encoded once
        self._page = resources.files(__package__).joinpath("liveview.html").read_bytes()
        self.server = Server(host, port, self._handle, self._part, limits=limits, fps=MAX_FPS,
                             log=log or (lambda line: print(line, file=sys.stderr, flush=True)))
        self._closed = False

    @property
    def url(self) -> str:
        host, port = self.server.address
        shown = f"[{host}]" if ":" in host else host
        return f"http://{shown}:{port}/{self.token}/"

    @property
    def viewers(self) -> int:
        return self.server.viewers

    # -- the loop's side: cheap, never waits for a browser ------------------------------------------
    def on_tick(self, tick: Tick) -> None:
        sh = self._shared
        if self._t0 is None:
            self._t0 = tick.t
        now = tick.t
        with sh.lock:
            if tick.command is not None:
                sh.last_command = tick.command.decode("ascii", "replace")
                sh.send_times.append(now)
            for reply in tick.replies:
                sh.reply_times.append(now)
                sh.last_reply_t = now
                if reply.kind.name == "REJECTED":
                    sh.rejected.append(now)
            for times, span in ((sh.send_times, 1.0), (sh.reply_times, 1.0), (sh.rejected, 5.0)):
                while times and times[0] <= now - span:
                    times.popleft()
            if tick.command is not None or tick.replies:
                sh.commands.appendleft({
                    "t": round(now - self._t0, 2),
                    "command": sh.last_command if tick.command is not None else "",
                    "replies": [_reply_text(r) for r in tick.replies],
                })
            if tick.frame is not None:
                sh.tick, sh.t, sh.seq = tick, now - self._t0, sh.seq + 1
                # the frame's arrival on the wall clock, comparable with the browser's Date.now()
                sh.capture_ms = self._wall_time() * 1000.0 - (time.perf_counter() - tick.frame_t) * 1000.0

    def end(self, summary: str) -> None:
        """The flight is over: the page shows `summary`; streams end."""
        with self._shared.lock:
            self._shared.ended = summary
        self.server.end_streams()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if not self._shared.ended:
            self.end("the pilot has stopped")
        self.server.close()

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the server's side (its one thread) ------------------------------------------------------------------
    def _part(self) -> tuple[int, bytes] | None:
        """The newest frame as one MJPEG part, drawn and encoded once per frame."""
        sh = self._shared
        with sh.lock:
            tick, t, seq, last, capture_ms = sh.tick, sh.t, sh.seq, sh.last_command, sh.capture_ms
        if tick is None:
            return None
        if self._encoded is not None and self._encoded[0] == seq:
            return self._encoded
        ok, buf = cv2.imencode(".jpg", annotate(tick, t, last), [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            return None
        data = buf.tobytes()
        head = (f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(data)}\r\n"
                f"X-Capture-Ms: {capture_ms:.1f}\r\nX-Frame: {seq}\r\n\r\n")
        self._encoded = (seq, head.encode("ascii") + data + b"\r\n")
        return self._encoded

    def _handle(self, method: str, target: str, client: str) -> Response | Stream:
        """The routes; any other path is 404.

        * ``/<token>/``             the page (``liveview.html``)
        * ``/<token>/stream.mjpg``  the annotated frames, MJPEG (``multipart/x-mixed-replace``); each part carries
                                    ``X-Capture-Ms``, the frame's arrival (Unix ms), so the page shows its latency
        * ``/<token>/state.json``   state, detection and confidence, laser, the last commands and replies, link health
        * ``POST /<token>/stop``    the loop's next tick raises ``StopRequested`` and the pilot runs its safe
                                    sequence (laser off, land, disarm), as after Ctrl-C"""
        prefix = f"/{self.token}/"
        path = target.split("?", 1)[0]
        route = "" if path == prefix.rstrip("/") else (path[len(prefix):] if path.startswith(prefix) else None)
        if method == "POST" and route == "stop":
            self.stop.request(f"Stop from the live view ({client})")
            return Response(HTTPStatus.OK, json.dumps({"stop_requested": True}).encode())
        if method != "GET" or route not in ("", "state.json", "stream.mjpg"):
            return Response(HTTPStatus.NOT_FOUND, b"not found\n", "text/plain")
        if route == "":
            return Response(HTTPStatus.OK, self._page, "text/html; charset=utf-8")
        if route == "state.json":
            return Response(HTTPStatus.OK, json.dumps(self.state()).encode())
        return Stream(f"multipart/x-mixed-replace; boundary={BOUNDARY}")

    def state(self) -> dict[str, Any]:
        sh = self._shared
        with sh.lock:
            tick, now = sh.tick, sh.t
            det = tick.detection if tick is not None else None
            since_reply = None
            if sh.last_reply_t is not None and tick is not None:
                since_reply = round(tick.t - sh.last_reply_t, 2)
            return {
                "t": round(now, 2),
                "frame": sh.seq,
                "state": tick.state.value if tick is not None else "starting",
                "laser": bool(tick.laser_on) if tick is not None else False,
                "detection": None if det is None else {
                    "found": det.found, "cx": round(det.cx, 1), "cy": round(det.cy, 1),
                    "size": round(det.size, 1), "confidence": round(det.confidence, 3),
                },
                "commands": list(sh.commands),
                "link": {
                    "sent_per_s": len(sh.send_times),
                    "replies_per_s": len(sh.reply_times),
                    "rejected_last_5s": len(sh.rejected),
                    "last_reply_s_ago": since_reply,
                },
                "stop_requested": self.stop.requested,
                "ended": sh.ended,
            }


def _reply_text(reply: dp.Reply) -> str:
    text = f"{reply.kind.name.lower()}"
    detail = "".join(x for x in (reply.category, reply.direction) if x)
    if detail:
        text += f" {detail}"
    if reply.error:
        text += f" ({reply.error})"
    return text
