"""Safety: an exception in each stage, SIGINT/SIGTERM and a lost camera all end with the laser off, the
firmware's landing routine on the wire and the drone confirming it disarmed — checked on the frames written to
the port and on the real virtual drone's outputs (laser pin low, disarmed, landed without a crash)."""

from __future__ import annotations

import dataclasses
import signal
from pathlib import Path

import drone_protocol as dp
import numpy as np
import pytest
import serial

from pilot.app.runner import RunResult, Tick, run
from pilot.app.sim_flight import sim_link
from pilot.common.config import PilotConfig
from pilot.control.controller import Controller, State
from pilot.link.serial_link import Link, keepalive_ms
from pilot.sim.room import make_scenario
from pilot.sim.virtual import VirtualDrone
from pilot.sim.world import SimWorld
from pilot.vision.detect import Detection, HsvBlobDetector
from pilot.vision.sources import Frame

REPO = Path(__file__).resolve().parents[3]
STAGES = ["source", "detector", "controller", "link", "observer", "sigint", "sigterm"]


class Boom(RuntimeError):
    pass


@dataclasses.dataclass
class Flight:
    result: RunResult
    link: Link
    world: SimWorld
    controller: Controller
    fired_before_fault: bool


def fly_and_fault(stage: str, exe: Path) -> Flight:
    """Fly the simulated room with the real virtual drone; once the laser is on (FIRE), make
    ``stage`` fail (or deliver the signal)."""
    cfg = PilotConfig()
    scenario = make_scenario("ahead", 1, ideal=True)  # the loop's safety, not flying the randomised world
    vd = VirtualDrone(exe)
    world = SimWorld(scenario, vd)
    link = sim_link(world, vd, cfg.link).open()
    controller = Controller(cfg.controller, clock=world.now)
    detector = HsvBlobDetector(cfg.hsv)
    camera = world.camera()
    armed = {"fired": False}

    def firing() -> bool:
        if controller.state is State.FIRE and controller.laser_on is True:
            armed["fired"] = True
            return True
        return False

    def fault() -> None:
        if stage == "sigint":
            signal.raise_signal(signal.SIGINT)
        elif stage == "sigterm":
            signal.raise_signal(signal.SIGTERM)
        else:
            raise Boom(f"injected failure in the {stage} stage")

    class Source:
        def read(self) -> Frame | None:
            if stage == "source" and firing():
                fault()
            return camera.read()

        def close(self) -> None:
            camera.close()

        def __enter__(self) -> Source:
            return self

        def __exit__(self, *exc: object) -> None:
            self.close()

    class Det:
        name = "hsv"

        def detect(self, image: np.ndarray) -> Detection:
            if stage in ("detector", "sigint", "sigterm") and firing():
                fault()
            return detector.detect(image)

    class Ctl(Controller):
        def update(self, det: Detection | None) -> bytes | None:
            if stage == "controller" and firing():
                fault()
            return super().update(det)

    class Sink:
        def send(self, frame: bytes) -> bool:
            if stage == "link" and firing() and frame == dp.hold_altitude():
                fault()
            return link.send(frame)

        def poll(self) -> list[dp.Reply]:
            return link.poll()

    class Obs:
        def on_tick(self, tick: Tick) -> None:
            if stage == "observer" and firing():
                fault()

    if stage == "controller":
        controller = Ctl(cfg.controller, clock=world.now)

    def on_sigterm(signum: int, frame: object) -> None:
        raise KeyboardInterrupt("SIGTERM")

    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        result = run(
            Source(),
            Det(),
            controller,
            Sink(),
            world,
            max_seconds=60,
            keepalive_ms=keepalive_ms(cfg.link.keepalive_fraction),
            observers=[Obs()],
        )
    finally:
        signal.signal(signal.SIGTERM, previous)
        link.close()
        vd.close()
    return Flight(result, link, world, controller, armed["fired"])


def names(frames: list[bytes]) -> list[str]:
    return [dp.decode(f).name for f in frames]


def assert_safe_tail(sent: list[str]) -> None:
    """Never the toggle; after the last laser-on: flight frames, then laser off before the firmware's landing
    routine, then only servos home, keep-alives and the landing routine again until the drone confirmed it."""
    assert "laser_toggle" not in sent  # (a move down while tracking a low target is flying; landing is below)
    tail = sent[len(sent) - sent[::-1].index("laser_on") :]
    off = tail.index("laser_off")
    assert "land" not in tail[:off], tail
    allowed = {"laser_off", "servo_reset", "land", "hold_altitude", "query_status"}
    assert "land" in tail and set(tail[off:]) <= allowed, tail


@pytest.mark.parametrize("stage", STAGES)
def test_fault_in_any_stage_ends_laser_off_neutral_disarmed(stage: str, virtual_drone: Path) -> None:
    f = fly_and_fault(stage, virtual_drone)
    assert f.fired_before_fault, "the fault was meant to hit while the laser was on"
    if stage in ("sigint", "sigterm"):
        assert isinstance(f.result.error, KeyboardInterrupt)
    else:
        assert isinstance(f.result.error, Boom) and stage in str(f.result.error)
    # on the wire, after the fault: laser off, servos home, the landing routine, keep-alives
    assert_safe_tail(names(list(f.link.sent)))
    assert not f.result.shutdown_errors
    assert f.result.safe and f.result.confirmed == "disarmed (not armed), laser off"
    # and what the firmware actually did about it
    out = f.world.outputs
    assert out.laser is False and out.armed is False
    assert f.world.fw_state == "disarmed"
    assert (out.roll, out.pitch, out.yaw) == (
        dp.CHANNELS[dp.ChannelName.ROLL].median,
        dp.CHANNELS[dp.ChannelName.PITCH].median,
        dp.CHANNELS[dp.ChannelName.YAW].median,
    )
    assert f.world.state.z == 0.0 and f.world.state.crashes == 0
    assert not f.world.state.armed  # the flight controller saw the disarm sticks
    assert f.world.state.wall_hits == 0


def test_lost_camera_lands_and_disarms(virtual_drone: Path) -> None:
    from pilot.app.sim_flight import fly

    r = fly("behind", 2, lose_camera_at_s=9.0, executable=virtual_drone, ideal=True)
    assert r.reason.startswith("camera lost: simulated camera lost at t=9.0")
    assert r.final_state == "done"
    assert not r.final_laser and not r.final_armed and not r.final_fc_armed and r.final_altitude == 0.0
    assert r.crashes == 0 and r.wall_hits == 0


class _Unplugged:
    """A serial port whose cable was pulled: every read and write fails, close still works."""

    def __init__(self, real: object) -> None:
        self.real = real

    def __getattr__(self, name: str) -> object:
        return getattr(self.real, name)

    @property
    def in_waiting(self) -> int:
        raise serial.SerialException("device reports readiness to read but returned no data (device disconnected?)")

    def write(self, data: bytes) -> int:
        raise serial.SerialException("write failed: [Errno 5] Input/output error")

    def close(self) -> None:
        self.real.close()  # type: ignore[attr-defined]


def test_pulled_cable_mid_flight_reconnects_and_lands(virtual_drone: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The link reopens the pty; opening it reboots the virtual board (as DTR resets an Uno), which now
    reports itself disarmed: the pilot lands, and sends the disarm it still owes the flight controller (the
    board was never seen disarming), nothing hits anything."""
    from pilot.app import sim_flight as flight

    links: list[Link] = []

    class RecordingLink(Link):
        def __init__(self, *args: object, **kwargs: object) -> None:
            super().__init__(*args, **kwargs)  # type: ignore[arg-type]
            links.append(self)

    class Puller:
        done = False

        def on_tick(self, tick: Tick) -> None:
            if not self.done and tick.state is State.TRACK and tick.t > 7.0:
                self.done = True
                links[-1]._port = _Unplugged(links[-1]._port)

    monkeypatch.setattr(flight, "Link", RecordingLink)
    r = flight.fly("ahead", 1, observers=[Puller()], executable=virtual_drone, ideal=True)
    assert r.reconnects == 1 and r.error is None
    assert "confirmed disarmed" in r.reason and r.final_state == "done"
    assert not r.final_laser and not r.final_armed and not r.final_fc_armed and r.final_altitude == 0.0
    assert r.crashes == 0 and r.wall_hits == 0
    assert not r.fired  # it did not go on to fire at the target with a rebooted board
