"""The controller's test rig: an injected clock (no real time), sightings of the 0.3 m ball, and the runner's tick
against a fake drone that answers with the spec's status (tests/pilot/fake_drone.py)."""

from __future__ import annotations

import drone_protocol as dp
from fake_drone import FakeDrone

from pilot.common.config import ControllerConfig
from pilot.control.controller import Controller, State
from pilot.vision.detect import Detection
from pilot.vision.detection import range_of

W, H = 320, 240
CFG = ControllerConfig()
KEEPALIVE_MS = 200


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t

    def advance_ms(self, ms: float) -> None:
        self.t += ms / 1000.0


def seen(ex: float = 0.0, ey: float = 0.0, size: float = 0.05, confidence: float = 0.95) -> Detection:
    """A measured sighting of the 0.3 m ball, its range from its apparent size."""
    distance = range_of(size * W, 0.3, W, CFG.horizontal_fov_deg)
    return Detection(True, W / 2 + ex * W / 2, H / 2 + ey * H / 2, size * W, confidence, W, H, range_m=distance)


MISS = Detection(False, width=W, height=H)


def size_at(range_m: float) -> float:
    """The relative apparent size of the 0.3 m ball at ``range_m`` (inverse of range_of)."""
    lo, hi = 1.0, 400.0
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if range_of(mid, 0.3, W, CFG.horizontal_fov_deg) > range_m else (lo, mid)
    return lo / W


def name(frame: bytes | None) -> str:
    assert frame is not None, "expected a command"
    return dp.decode(frame).name


def st(c: Controller) -> State:
    """The state, read through a call so that the type checker does not narrow it between updates."""
    return c.state


class Rig:
    """The runner's tick against the fake drone: replies first, then the decision, then the wire (with
    the runner's keep-alive when the controller has nothing to say)."""

    def __init__(self, cfg: ControllerConfig = CFG, drone: FakeDrone | None = None) -> None:
        self.clock = Clock()
        self.drone = drone or FakeDrone(self.clock)
        self.c = Controller(cfg, clock=self.clock)
        self.sent: list[bytes] = []
        self._last_send = -1e9

    def tick(self, det: Detection | None, ms: float = 50.0) -> bytes | None:
        for reply in self.drone.poll():
            self.c.on_reply(reply)
        out = self.c.update(det)
        wire = out
        if wire is None and st(self.c) is not State.DONE and self.clock.t - self._last_send >= KEEPALIVE_MS / 1000:
            wire = dp.hold_altitude()
        if wire is not None:
            self.drone.send(wire)
            self.sent.append(wire)
            self._last_send = self.clock.t
        self.clock.advance_ms(ms)
        return out


def to_state(state: State, cfg: ControllerConfig = CFG) -> tuple[Controller, Rig]:
    """Drive a fresh controller through the real transitions up to ``state``."""
    rig = Rig(cfg)
    c = rig.c
    c.start()
    order = [State.ARM, State.TAKEOFF, State.HOLD, State.SEARCH, State.ACQUIRE, State.TRACK, State.AIM, State.FIRE]
    for _ in range(2000):
        if st(c) is state:
            if state is State.FIRE:  # the drone's reply has confirmed the laser on
                rig.tick(seen(size=0.3))
            return c, rig
        if st(c) in (State.ARM, State.TAKEOFF, State.HOLD):
            rig.tick(MISS)
        elif st(c) in (State.SEARCH, State.ACQUIRE, State.TRACK):
            rig.tick(seen(size=0.3) if order.index(state) > order.index(State.TRACK) else seen())
        elif st(c) is State.AIM:
            rig.tick(seen(size=0.3))
        else:
            break
    raise AssertionError(f"did not reach {state}, stuck in {st(c)}")


def refusal(error: dp.ErrorKind, state: dp.DroneState) -> dp.Reply:
    """A rejected reply with the drone's status (laser off)."""
    return dp.parse_reply(dp.rejected_line(error, state, False))


def land_to_done(rig: Rig, limit_s: float = 30.0) -> list[str]:
    """Tick through LAND (no target) until DONE; the frames the controller chose."""
    out = []
    start = rig.clock.t
    while st(rig.c) is not State.DONE:
        frame = rig.tick(MISS)
        if frame is not None:
            out.append(name(frame))
        assert rig.clock.t - start < limit_s
    return out
