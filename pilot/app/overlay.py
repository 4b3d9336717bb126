"""The annotated frame shared by the recording and the live view: the detection, the aim point, the state,
the last command and the laser, in outlined text that stays readable on dark and bright frames alike."""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

from .runner import Tick

FONT = cv2.FONT_HERSHEY_SIMPLEX
OUTLINE = (0, 0, 0)
TEXT = (255, 255, 255)
OUTLINE_SHIFTS = tuple((dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy)


def outlined_text(
    img: MatLike, text: str, org: tuple[int, int], scale: float, colour: tuple[int, int, int] = TEXT
) -> None:
    """Text with a dark outline under it: light letters on a dark rim read on any background.

    The rim is the same text at the same thickness, shifted a pixel each way: a thicker stroke would also space
    the letters wider (Hershey advances grow with the thickness), so its last letters would stick out beside the
    light ones ("land" read "landd")."""
    thickness = max(1, round(scale * 1.5))
    x, y = org
    for dx, dy in OUTLINE_SHIFTS:
        cv2.putText(img, text, (x + dx, y + dy), FONT, scale, OUTLINE, thickness, cv2.LINE_AA)
    cv2.putText(img, text, org, FONT, scale, colour, thickness, cv2.LINE_AA)


def annotate(tick: Tick, t: float, last_command: str) -> MatLike:
    """A copy of the tick's frame with the overlay; `t` is the time to print (from the start of the run)."""
    assert tick.frame is not None
    img = np.ascontiguousarray(tick.frame.image).copy()
    h, w = img.shape[:2]
    det = tick.detection
    cv2.drawMarker(img, (w // 2, h // 2), (0, 255, 0), cv2.MARKER_CROSS, 12, 1)
    if det is not None and det.found:
        r = max(2, int(det.size / 2))
        cv2.circle(img, (int(det.cx), int(det.cy)), r, (0, 255, 255), 1)
        cv2.line(img, (w // 2, h // 2), (int(det.cx), int(det.cy)), (0, 255, 255), 1)
    scale = max(0.45, w / 700)  # smaller Hershey letters fill in under their own outline
    line = int(18 * scale / 0.45)
    outlined_text(img, f"{t:6.2f}s {tick.state.value}", (4, line), scale)
    outlined_text(img, f"cmd {last_command}", (4, h - 6), scale)
    if tick.laser_on:
        outlined_text(img, "LASER", (w - int(62 * scale / 0.45), line), scale, (80, 80, 255))
        cv2.circle(img, (w // 2, h // 2), 3, (0, 0, 255), -1)
    return img
