"""Whether the drone answers the yaw stick: a drone that turns moves what it sees; one lying on its side after a
crash, or caught on something, does not, and a pilot that goes on turning at it keeps its motors going for
nothing. Judged only while the target is in view (its position in the frame is the evidence) and while every
frame sent is a turn."""

from __future__ import annotations

from dataclasses import dataclass

import drone_protocol as dp

from .pulses import StickModel
from .sticks import deflection_steps

STRONG_STEPS = 0.7  # only turns at least this hard count (control steps): about 20°/s past the yaw dead zone
NO_RESPONSE_MS = 3000  # turning hard this long moves a still target across the whole frame
STILL_SHARE = 0.05  # ... while the target moved less than this share of the frame's width: the turn did nothing
_TURNS = {dp.CommandName.TURN_RIGHT: 1, dp.CommandName.TURN_LEFT: -1}


def turn_sense(frame: bytes | None, pulses: StickModel) -> int:
    """+1 for a hard turn right, -1 for a hard turn left, 0 for any other frame."""
    if frame is None:
        return 0
    try:
        command = dp.decode(frame)
    except dp.ProtocolError:
        return 0
    sense = _TURNS.get(command.name, 0)
    if sense and deflection_steps(command, dp.ChannelName.YAW, pulses) >= STRONG_STEPS:
        return sense
    return 0


@dataclass
class _Episode:
    start_ms: int
    cx: float
    sense: int


class TurnResponse:
    def __init__(self) -> None:
        self._episode: _Episode | None = None

    def reset(self) -> None:
        self._episode = None

    def observe(self, now_ms: int, sense: int, cx: float | None, width: int) -> bool:
        """One frame: ``sense`` the turn sent (+1 right, -1 left, 0 anything else), ``cx`` where the target was
        seen (None: not measured). True when the turn has not moved the target at all for ``NO_RESPONSE_MS``."""
        if sense == 0 or cx is None or width <= 0:
            self._episode = None
            return False
        ep = self._episode
        if ep is None or ep.sense != sense or abs(cx - ep.cx) > STILL_SHARE * width:
            self._episode = _Episode(now_ms, cx, sense)
            return False
        return now_ms - ep.start_ms >= NO_RESPONSE_MS
