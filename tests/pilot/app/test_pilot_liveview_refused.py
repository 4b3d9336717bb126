"""The live view's refused count shows only what the drone refused: a whole mission (arming, the flight, firing,
the landing routine and the disarm sequence, whose confirmations the pilot waits for with status queries) shows
none, while a refusal is still counted. The runner against the fake drone on an injected clock."""

from __future__ import annotations

from typing import Any

import drone_protocol as dp
import numpy as np
from controller_rig import seen
from fake_drone import FakeDrone
from runner_rig import Clock, Frames

from pilot.app.liveview import LiveView
from pilot.app.observers import StopSwitch
from pilot.app.runner import Tick, run
from pilot.common.config import ControllerConfig
from pilot.control.controller import Controller, State
from pilot.vision.detect import Detection


class Ahead:
    """A close ball in the middle of every frame: the mission goes straight to firing, then lands."""

    name = "ahead"

    def detect(self, image: np.ndarray) -> Detection:
        return seen(size=0.25)


class Watch:
    """The live view's link panel after every tick, with the controller's state."""

    def __init__(self, view: LiveView) -> None:
        self.view = view
        self.seen: list[tuple[State, dict[str, Any]]] = []

    def on_tick(self, tick: Tick) -> None:
        self.seen.append((tick.state, self.view.state()["link"]))


def test_a_whole_mission_with_its_landing_shows_no_refusal() -> None:
    clock = Clock()
    drone = FakeDrone(clock.now)
    with LiveView("127.0.0.1", 0, StopSwitch()) as view:
        watch = Watch(view)
        result = run(Frames(clock), Ahead(), Controller(ControllerConfig(), clock=clock.now), drone, clock,
                     max_seconds=60.0, keepalive_ms=200, observers=[view, watch])
    states = [state for state, _ in watch.seen]
    assert State.FIRE in states and State.LAND in states and states[-1] is State.DONE, result
    landing = [link for state, link in watch.seen if state is State.LAND]
    assert len(landing) * 50 >= dp.LANDING_MS  # the landing routine and the disarm sequence were watched
    assert [link["rejected_last_5s"] for _, link in watch.seen] == [0] * len(watch.seen)
    assert drone.state is dp.DroneState.DISARMED and not drone.laser


def test_a_refusal_is_still_counted() -> None:
    frame = Frames(Clock()).read()
    refusal = dp.parse_reply(dp.rejected_line(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED, False))
    answer = dp.parse_reply(dp.accepted_line(dp.decode(dp.query_status()), dp.DroneState.DISARMED, False))
    with LiveView("127.0.0.1", 0, StopSwitch()) as view:
        view.on_tick(Tick(0, 100.0, frame, None, State.ARM, dp.move_up(), (refusal, answer), 0.0, None))
        assert view.state()["link"]["rejected_last_5s"] == 1
