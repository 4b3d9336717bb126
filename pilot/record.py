"""``--record DIR``: the annotated video, a JSON-lines log, and a top-down picture of the flight.

* ``flight.avi`` (Motion-JPEG): each frame with the detection overlay, the state and the last command.
* ``log.jsonl``: one object per line — ticks (detection, state, command, replies), link traffic, and
  the state transitions and the result at the end.
* ``path.png``: the room from above with the target, the distractors and the drone's path (simulated
  flights; a real flight has no position to draw).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import cv2
import drone_protocol as dp
import numpy as np

from .closing import Closing
from .link import LogEntry
from .runner import Tick
from .sim.room import Scenario

VIDEO = "flight.avi"
LOG = "log.jsonl"
PATH_PICTURE = "path.png"


def _reply_text(reply: dp.Reply) -> str:
    return reply.kind.name + (reply.category or "") + (reply.direction or "") + (reply.error or "")


class Recorder(Closing):
    def __init__(self, directory: str | Path, fps: float = 20.0) -> None:
        self.dir = Path(directory)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.fps = fps
        self._writer: cv2.VideoWriter | None = None
        self._log = (self.dir / LOG).open("w", encoding="utf-8")
        self._last_command = ""
        self._closed = False

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
        if not self._closed:
            self._log.write(json.dumps(record, sort_keys=True) + "\n")

    def on_link(self, entry: LogEntry) -> None:
        self.write({"t": round(entry.t, 3), "link": entry.kind, "data": entry.data})

    def on_tick(self, tick: Tick) -> None:
        det = tick.detection
        if tick.command is not None:
            self._last_command = tick.command.decode("ascii", "replace")
        self.write(
            {
                "t": round(tick.t, 3),
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
                },
                "command": tick.command.decode("ascii", "replace") if tick.command else None,
                "replies": [_reply_text(r) for r in tick.replies],
            }
        )
        if tick.frame is not None:
            self._video(tick)

    def _video(self, tick: Tick) -> None:
        assert tick.frame is not None
        img = np.ascontiguousarray(tick.frame.image).copy()
        h, w = img.shape[:2]
        if self._writer is None:
            self._writer = cv2.VideoWriter(str(self.video_path), cv2.VideoWriter.fourcc(*"MJPG"), self.fps, (w, h))
        det = tick.detection
        cv2.drawMarker(img, (w // 2, h // 2), (0, 255, 0), cv2.MARKER_CROSS, 12, 1)
        if det is not None and det.found:
            r = max(2, int(det.size / 2))
            cv2.circle(img, (int(det.cx), int(det.cy)), r, (0, 255, 255), 1)
            cv2.line(img, (w // 2, h // 2), (int(det.cx), int(det.cy)), (0, 255, 255), 1)
        font = cv2.FONT_HERSHEY_SIMPLEX
        scale = max(0.35, w / 900)
        cv2.putText(img, f"{tick.t:6.2f}s {tick.state.value}", (4, int(14 * scale / 0.35)), font, scale, (0, 0, 0), 1)
        cv2.putText(img, f"cmd {self._last_command}", (4, h - 6), font, scale, (0, 0, 0), 1)
        if tick.laser_on:
            cv2.putText(img, "LASER", (w - int(60 * scale / 0.35), int(14 * scale / 0.35)), font, scale, (0, 0, 255), 1)
            cv2.circle(img, (w // 2, h // 2), 3, (0, 0, 255), -1)
        self._writer.write(img)

    def path_png(self, scenario: Scenario, path: list[tuple[float, float, float, float]], scale: int = 60) -> Path:
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
        cv2.imwrite(str(self.path_picture), img)
        return self.path_picture

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if self._writer is not None:
            self._writer.release()
        self._log.close()

