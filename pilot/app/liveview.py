"""``--serve HOST:PORT``: a live view of the flight in a browser, with an emergency Stop.

Served by ``liveserver.py`` under a random token printed at start-up (``http://127.0.0.1:8080/<token>/``), so the
page and its Stop need the URL. The pilot loop publishes an immutable snapshot (the newest tick, the link's counts)
by one assignment, with no lock; the server's thread draws the overlay and encodes each frame once, off the control
loop, and only when a viewer is ready for it.
"""
from __future__ import annotations

import dataclasses
import json
import secrets
import sys
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from http import HTTPStatus
from importlib import resources
from typing import Any

import cv2
import drone_protocol as dp
import numpy as np

from ..common.errors import PilotError
from .liveserver import DEFAULT_LIMITS, Limits, Response, Server, Stream
from .observers import StopSwitch
from .overlay import annotate, outlined_text
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


@dataclass(frozen=True)
class _Snapshot:
    """What the loop hands to the server thread: made by the loop, never changed, published by one assignment
    (no lock: the loop never waits for the server, even one the scheduler paused in the middle of a request)."""

    tick: Tick | None = None
    t: float = 0.0
    capture_ms: float = 0.0
    seq: int = 0
    last_command: str = ""
    commands: tuple[dict[str, Any], ...] = ()
    sent_per_s: int = 0
    replies_per_s: int = 0
    rejected_last_5s: int = 0
    since_reply: float | None = None
    ended: str = ""


class _History:
    """The loop's own record of the link (touched by the loop thread only)."""

    def __init__(self) -> None:
        self.last_command = ""
        self.commands: deque[dict[str, Any]] = deque(maxlen=HISTORY)
        self.reply_times: deque[float] = deque()
        self.send_times: deque[float] = deque()
        self.rejected: deque[float] = deque()
        self.last_reply_t: float | None = None


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
        self._history = _History()
        self._snap = _Snapshot()
        self._t0: float | None = None
        self._encoded: tuple[int, bytes] | None = None  # (seq, MJPEG part): the newest frame, encoded once
        self._page = resources.files(__package__).joinpath("liveview.html").read_bytes()
        self.encoded = 0  # frames drawn and encoded (at most one per frame, and only for a viewer ready for it)
        self.server = Server(host, port, self._handle, self._part, self._newest, limits=limits, fps=MAX_FPS,
                             log=log or (lambda line: print(line, file=sys.stderr, flush=True)), warm_up=_warm_up)
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
        h, snap = self._history, self._snap
        if self._t0 is None:
            self._t0 = tick.t
        now = tick.t
        if tick.command is not None:
            h.last_command = tick.command.decode("ascii", "replace")
            h.send_times.append(now)
        for reply in tick.replies:
            h.reply_times.append(now)
            h.last_reply_t = now
            if reply.kind.name == "REJECTED":
                h.rejected.append(now)
        for times, span in ((h.send_times, 1.0), (h.reply_times, 1.0), (h.rejected, 5.0)):
            while times and times[0] <= now - span:
                times.popleft()
        commands = snap.commands
        if tick.command is not None or tick.replies:
            h.commands.appendleft({
                "t": round(now - self._t0, 2),
                "command": h.last_command if tick.command is not None else "",
                "replies": [_reply_text(r) for r in tick.replies],
            })
            commands = tuple(h.commands)
        shown, t, seq, capture_ms = snap.tick, snap.t, snap.seq, snap.capture_ms
        if tick.frame is not None:
            shown, t, seq = tick, now - self._t0, seq + 1
            # the frame's arrival on the wall clock, comparable with the browser's Date.now()
            capture_ms = self._wall_time() * 1000.0 - (time.perf_counter() - tick.frame_t) * 1000.0
        since = None if h.last_reply_t is None or shown is None else round(shown.t - h.last_reply_t, 2)
        self._snap = _Snapshot(shown, t, capture_ms, seq, h.last_command, commands, len(h.send_times),
                               len(h.reply_times), len(h.rejected), since, snap.ended)

    def end(self, summary: str) -> None:
        """The flight is over: the page shows `summary`; streams end."""
        self._snap = dataclasses.replace(self._snap, ended=summary)
        self.server.end_streams()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if not self._snap.ended:
            self.end("the pilot has stopped")
        self.server.close()

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the server's side (its one thread) ------------------------------------------------------------------
    def _newest(self) -> int:
        return self._snap.seq

    def _part(self) -> tuple[int, bytes] | None:
        """The newest frame as one MJPEG part, drawn and encoded once per frame."""
        snap = self._snap
        tick, seq = snap.tick, snap.seq
        if tick is None:
            return None
        if self._encoded is not None and self._encoded[0] == seq:
            return self._encoded
        image = annotate(tick, snap.t, snap.last_command)
        ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            return None
        data = buf.tobytes()
        self.encoded += 1
        head = (f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(data)}\r\n"
                f"X-Capture-Ms: {snap.capture_ms:.1f}\r\nX-Frame: {seq}\r\n\r\n")
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
        snap = self._snap
        tick = snap.tick
        det = tick.detection if tick is not None else None
        return {
            "t": round(snap.t, 2),
            "frame": snap.seq,
            "state": tick.state.value if tick is not None else "starting",
            "laser": bool(tick.laser_on) if tick is not None else False,
            "detection": None if det is None else {
                "found": det.found, "cx": round(det.cx, 1), "cy": round(det.cy, 1),
                "size": round(det.size, 1), "confidence": round(det.confidence, 3),
            },
            "commands": list(snap.commands),
            "link": {
                "sent_per_s": snap.sent_per_s,
                "replies_per_s": snap.replies_per_s,
                "rejected_last_5s": snap.rejected_last_5s,
                "last_reply_s_ago": snap.since_reply,
            },
            "stop_requested": self.stop.requested,
            "ended": snap.ended,
        }


def _warm_up() -> None:
    """OpenCV sets up its Hershey font in each thread at its first putText (30 ms of processor time): the server's
    thread does it as it starts, before the flight, not when the first viewer comes."""
    outlined_text(np.zeros((24, 48, 3), np.uint8), "0", (2, 18), 0.45)


def _reply_text(reply: dp.Reply) -> str:
    text = f"{reply.kind.name.lower()}"
    detail = "".join(x for x in (reply.category, reply.direction) if x)
    if detail:
        text += f" {detail}"
    if reply.error:
        text += f" ({reply.error})"
    return text
