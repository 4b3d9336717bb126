"""A status poll goes out ``POLL_COPIES`` times in its tick, each copy with its own reply, so that a lossy link
confirms a change of state sooner (bench/lossy); every other frame, the in-flight hold and the keep-alive included,
goes out once. The runner against the fake drone (injected clock)."""

from __future__ import annotations

from collections import Counter

import drone_protocol as dp
import numpy as np
from fake_drone import FakeDrone
from runner_rig import Clock, Frames

from pilot.app.runner import POLL_COPIES, Tick, run
from pilot.common.config import ControllerConfig
from pilot.control.controller import Controller, State
from pilot.vision.detect import Detection


class Blind:
    name = "fake"

    def detect(self, image: np.ndarray) -> Detection:
        return Detection(False, width=320, height=240)


class Wire:
    """The fake drone as the sink, each frame noted with its tick's time; ``keep_every``: of its replies, only
    every n-th reaches the pilot (the others are lost on the way)."""

    def __init__(self, drone: FakeDrone, clock: Clock, keep_every: int = 1) -> None:
        self.drone, self.clock, self.keep_every = drone, clock, keep_every
        self.sent = list[tuple[float, str]]()
        self._replies = 0

    def send(self, frame: bytes) -> bool:
        self.sent.append((self.clock.t, dp.decode(frame).name))
        return self.drone.send(frame)

    def poll(self) -> list[dp.Reply]:
        kept = []
        for reply in self.drone.poll():
            self._replies += 1
            if self._replies % self.keep_every == 0:
                kept.append(reply)
        return kept


class Seen:
    """The controller's state and the drone's armed state as the pilot saw them, by tick."""

    def __init__(self) -> None:
        self.state: dict[float, State] = {}
        self.armed: dict[float, bool | None] = {}

    def on_tick(self, tick: Tick) -> None:
        self.state[tick.t] = tick.state
        self.armed[tick.t] = tick.armed


def fly(keep_every: int = 1, seconds: float = 12.0) -> tuple[Wire, Seen, FakeDrone]:
    clock = Clock()
    drone = FakeDrone(clock.now)
    wire, seen = Wire(drone, clock, keep_every), Seen()
    run(Frames(clock), Blind(), Controller(ControllerConfig(), clock=clock.now), wire, clock,
        max_seconds=seconds, keepalive_ms=200, observers=[seen])
    return wire, seen, drone


def test_a_status_poll_goes_out_poll_copies_times_and_every_other_frame_once() -> None:
    wire, seen, _ = fly()
    per_tick = Counter(wire.sent)
    polls = {n for (t, name), n in per_tick.items() if name == "query_status" and seen.state.get(t) is State.ARM}
    # the time limit ends the run searching: the landing after it is the runner's (no tick observed)
    landing = {n for (t, name), n in per_tick.items() if name == "query_status" and t not in seen.state}
    flying = {n for (t, name), n in per_tick.items()
              if name == "hold_altitude" and seen.state.get(t) not in (State.LAND, None)}
    others = {n for (t, name), n in per_tick.items() if name not in ("hold_altitude", "query_status")}
    assert POLL_COPIES > 1 and polls == {POLL_COPIES}  # waiting for the drone to confirm it armed
    assert landing == {POLL_COPIES}  # and, once landing, that it disarmed
    # AltHold once armed, the hold (and any keep-alive) in flight, and every other frame: once
    assert flying == {1} and others == {1}
    assert not {name for (t, name) in per_tick if name == "query_status" and seen.state.get(t) not in (State.ARM,
                                                                                                          None)}
    assert {State.ARM, State.HOLD, State.SEARCH} <= set(seen.state.values())  # it flew through both


def armed_seen_after_ms(keep_every: int) -> float:
    """How long after the drone armed the pilot saw it armed."""
    _, seen, drone = fly(keep_every, seconds=6.0)
    armed_ms = next(ms for ms, state, _ in drone.log if state in dp.ARMED_STATES)
    first = min(t for t, armed in seen.armed.items() if armed)
    return first * 1000.0 - armed_ms


def test_the_copies_confirm_a_change_as_soon_as_a_lossless_link_does_with_two_replies_in_three_lost() -> None:
    lossless = armed_seen_after_ms(1)
    assert 0.0 < lossless <= 100.0  # the next tick's poll, answered, read the tick after
    assert POLL_COPIES >= 3 and armed_seen_after_ms(3) == lossless
