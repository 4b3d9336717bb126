"""The wall-clock pacer (steady 20 Hz, no bursts after a late tick) and the status line."""

from __future__ import annotations

import io

import drone_protocol as dp

from pilot.app.runner import RealPacer, StatusLine, Tick
from pilot.control.controller import State
from pilot.vision.detect import Detection


class FakeTime:
    def __init__(self) -> None:
        self.t = 0.0
        self.sleeps: list[float] = []

    def clock(self) -> float:
        return self.t

    def sleep(self, s: float) -> None:
        self.sleeps.append(s)
        self.t += s


def test_real_pacer_keeps_a_steady_grid() -> None:
    ft = FakeTime()
    pacer = RealPacer(20.0, clock=ft.clock, sleep=ft.sleep)
    ticks = []
    for work in (0.01, 0.02, 0.0, 0.045):
        ft.t += work  # the tick's own work
        pacer.wait_tick()
        ticks.append(round(ft.t, 6))
    assert ticks == [0.05, 0.1, 0.15, 0.2]


def test_real_pacer_resynchronises_when_late_instead_of_bursting() -> None:
    ft = FakeTime()
    pacer = RealPacer(20.0, clock=ft.clock, sleep=ft.sleep)
    ft.t += 0.3  # a long stall (six periods)
    pacer.wait_tick()
    assert ft.sleeps == []  # late: no sleep...
    start = ft.t
    pacer.wait_tick()
    assert round(ft.t - start, 6) == 0.05  # ...and the next tick a full period later, not six at once


def test_status_line_off_a_terminal_prints_one_line_per_state() -> None:
    out = io.StringIO()
    status = StatusLine(out, live=False)
    seen = Detection(True, 160, 120, 20, 1.0, 320, 240)
    for i in range(40):
        state = State.SEARCH if i < 20 else State.TRACK
        status.on_tick(Tick(i, i * 0.05, None, seen, state, dp.hold_altitude(), (), 0.0, None))
    lines = out.getvalue().splitlines()
    assert len(lines) == 2
    assert "state search" in lines[0] and "state track" in lines[1]
    assert "target yes" in lines[1] and "20 cmd/s" in lines[1] and f"last {dp.hold_altitude().decode()}" in lines[1]
