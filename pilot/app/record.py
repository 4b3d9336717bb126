"""``--record DIR``: the annotated video, a JSON-lines log, and a top-down picture of the flight.

* ``flight.avi`` (Motion-JPEG): each frame with the detection overlay, the state and the last command.
* ``log.jsonl``: one object per line — ticks (detection, state, command, replies), link traffic, and
  the state transitions and the result at the end.
* ``path.png``: the room from above with the target, the distractors and the drone's path (simulated
  flights; a real flight has no position to draw).

The recording is best effort: a full disk or any I/O error ends it with one line on stderr and the flight
goes on (``record_failure: continue``, the default) or stops as after Stop, laser off, land, disarm
(``record_failure: stop``); it never raises into the pilot's loop or the link.
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import cv2
import drone_protocol as dp
import numpy as np

from ..common.closing import Closing
from ..common.errors import PilotError
from ..link.serial_link import LogEntry
from ..sim.scenario import Scenario
from .overlay import annotate
from .runner import StopRequested, Tick

VIDEO = "flight.avi"
LOG = "log.jsonl"
PATH_PICTURE = "path.png"


RECORDING_FILES = (VIDEO, LOG, PATH_PICTURE)


class RecordingFailed(StopRequested):
    """The recording failed and the config says to stop the flight (``record_failure: stop``)."""


def prepare_directory(directory: str | Path, force: bool = False) -> Path:
    """Check ``--record DIR`` before anything flies: a folder (made if missing) that holds no earlier
    recording, unless ``force`` (then the earlier recording's files are removed first)."""
    path = Path(directory)
    if path.exists() and not path.is_dir():
        raise PilotError(f"option --record: {str(path)!r} is a file, not a folder: name a folder")
    existing = [name for name in RECORDING_FILES if (path / name).exists()]
    if existing and not force:
        raise PilotError(
            f"option --record: {str(path)!r} already holds a recording ({', '.join(existing)}): "
            "pass --force to overwrite it, or name another folder"
        )
    try:
        for name in existing:
            (path / name).unlink()
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):  # an existing folder may still be unwritable (a read-only disk)
            pass
    except OSError as exc:
        raise PilotError(f"option --record: cannot write into {str(path)!r}: {exc.strerror or exc}") from exc
    return path


def summary_lines(directory: str | Path, failed: str, *, simulated: bool, picture: str | None = None) -> list[str]:
    """The flight summary's lines about a recording in ``directory``: its files, or, when it stopped early
    (``failed`` says why), that its files end there; the path picture of a simulated flight, or why there is none.
    Never a path that was not written."""
    video, log = Path(directory) / VIDEO, Path(directory) / LOG
    if failed:
        lines = [f"recording: stopped early ({failed}); {video} and {log} end there"]
    else:
        lines = [f"recording: {video}", f"log:       {log}"]
    if simulated:
        lines.append(f"path:      {picture}" if picture else "path:      not drawn: the recording had stopped")
    return lines


def _reply_text(reply: dp.Reply) -> str:
    return reply.kind.name + (reply.category or "") + (reply.direction or "") + (reply.error or "")


def _open_log(path: Path) -> IO[str]:
    return path.open("w", encoding="utf-8")


def _warn(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


class Recorder(Closing):
    def __init__(
        self,
        directory: str | Path,
        fps: float = 20.0,
        *,
        on_failure: str = "continue",
        open_log: Callable[[Path], IO[str]] | None = None,
        warn: Callable[[str], None] = _warn,
    ) -> None:
        self.dir = Path(directory)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.fps = fps
        self.on_failure = on_failure
        self._warn = warn
        self.failed = ""  # why the recording ended early, if it did
        self._writer: cv2.VideoWriter | None = None
        self._log = (open_log or _open_log)(self.dir / LOG)
        self._last_command = ""
        self._t0: float | None = None
        self._closed = False

    def _fail(self, what: str, exc: BaseException) -> None:
        """End the recording with one line; the files written so far stay."""
        if self.failed:
            return
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc) or type(exc).__name__
        self.failed = f"{what}: {reason}"
        then = "landing (record_failure: stop)" if self.on_failure == "stop" else "the flight goes on"
        self._warn(f"pilot: recording stopped: {self.failed}; {then}")
        self.close()

    @property
    def video_path(self) -> Path:
        return self.dir / VIDEO

    @property
    def log_path(self) -> Path:
        return self.dir / LOG

    @property
    def path_picture(self) -> Path:
        return self.dir / PATH_PICTURE

    def write(self, record: dict[str, Any]) -> None:
        if self._closed:
            return
        try:
            self._log.write(json.dumps(record, sort_keys=True) + "\n")
            self._log.flush()  # a crash loses no line: the log is what is left to read afterwards
        except (OSError, ValueError) as exc:
            self._fail(str(self.log_path), exc)

    def _since_start(self, t: float) -> float:
        """Seconds from the first event recorded (the link opening or the first tick), whatever the clock's
        origin (a real run's monotonic clock counts from the machine's boot)."""
        if self._t0 is None:
            self._t0 = t
        return t - self._t0

    def on_link(self, entry: LogEntry) -> None:
        self.write({"t": round(self._since_start(entry.t), 3), "link": entry.kind, "data": entry.data})

    def on_tick(self, tick: Tick) -> None:
        if self.failed and self.on_failure == "stop":
            raise RecordingFailed(f"the recording failed ({self.failed})")
        if self._closed:
            return
        det = tick.detection
        if tick.command is not None:
            self._last_command = tick.command.decode("ascii", "replace")
        self.write(
            {
                "t": round(self._since_start(tick.t), 3),
                "tick": tick.index,
                "state": tick.state.value,
                "laser": tick.laser_on,
                "detection": None
                if det is None
                else {
                    "found": det.found,
                    "cx": round(det.cx, 2),
                    "cy": round(det.cy, 2),
                    "size": round(det.size, 2),
                    "confidence": round(det.confidence, 3),
                    "cut_short": det.cut_short,
                },
                "command": tick.command.decode("ascii", "replace") if tick.command else None,
                "replies": [_reply_text(r) for r in tick.replies],
            }
        )
        if tick.frame is not None and not self._closed:
            try:
                self._video(tick)
            except (OSError, cv2.error) as exc:
                self._fail(str(self.video_path), exc)

    def _video(self, tick: Tick) -> None:
        img = annotate(tick, self._since_start(tick.t), self._last_command)
        if self._writer is None:
            h, w = img.shape[:2]
            self._writer = cv2.VideoWriter(str(self.video_path), cv2.VideoWriter.fourcc(*"MJPG"), self.fps, (w, h))
            if not self._writer.isOpened():
                raise OSError(0, "cannot open the video for writing")
        self._writer.write(img)

    def path_png(
        self, scenario: Scenario, path: list[tuple[float, float, float, float]], scale: int = 60
    ) -> Path | None:
        """The room from above: walls, target (red), distractors, start (green) and the path (blue)."""
        room = scenario.room
        margin = 20
        w, h = int(room.width * scale) + 2 * margin, int(room.depth * scale) + 2 * margin
        img = np.full((h, w, 3), 255, np.uint8)

        def px(x: float, y: float) -> tuple[int, int]:
            return int(margin + x * scale), int(h - margin - y * scale)

        cv2.rectangle(img, px(0, 0), px(room.width, room.depth), (60, 60, 60), 2)
        for ball in scenario.distractors:
            cv2.circle(img, px(ball.position[0], ball.position[1]), max(3, int(ball.radius * scale)), ball.colour, -1)
        t = scenario.target.position
        cv2.circle(img, px(t[0], t[1]), max(4, int(scenario.target.radius * scale)), (0, 0, 220), -1)
        sx, sy, heading = scenario.start
        cv2.circle(img, px(sx, sy), 6, (0, 160, 0), 2)
        tip = px(sx + 0.5 * math.cos(heading), sy + 0.5 * math.sin(heading))
        cv2.line(img, px(sx, sy), tip, (0, 160, 0), 2)
        points = np.array([px(x, y) for _, x, y, _ in path], np.int32)
        if len(points) >= 2:
            cv2.polylines(img, [points], False, (200, 80, 0), 2)
            cv2.circle(img, (int(points[-1][0]), int(points[-1][1])), 5, (200, 80, 0), -1)
        label = f"{scenario.name} seed {scenario.seed}: start (green), path (blue), target (red), distractors"
        cv2.putText(img, label, (margin, margin - 5), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 0, 0), 1)
        cv2.putText(
            img, f"{room.width:g} x {room.depth:g} m", (margin, h - 5), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (90, 90, 90), 1
        )
        if self.failed:
            return None
        try:
            if not cv2.imwrite(str(self.path_picture), img):
                raise OSError(0, "cannot write the picture")
        except (OSError, cv2.error) as exc:
            self._fail(str(self.path_picture), exc)
            return None
        return self.path_picture

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            if self._writer is not None:
                self._writer.release()
        finally:
            try:
                self._log.close()
            except (OSError, ValueError) as exc:  # the last flush: the disk filled since
                self._fail(str(self.log_path), exc)

