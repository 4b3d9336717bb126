"""Safety: an exception in each stage, SIGINT/SIGTERM and a lost camera all end with the laser off,
the sticks neutral and a disarm on the wire — checked on the frames written to the port and on the
real virtual drone's outputs (laser pin low, disarmed, landed without a crash)."""

from __future__ import annotations

import dataclasses
import os
import select
import signal
import subprocess
import sys
import time
import tty
from pathlib import Path

import cv2
import drone_protocol as dp
import numpy as np
import pytest
import serial
import yaml

from pilot.config import PilotConfig
from pilot.controller import Controller, State
from pilot.detect import Detection, HsvBlobDetector
from pilot.link import Link, keepalive_ms
from pilot.runner import RunResult, Tick, run
from pilot.sim.room import make_scenario
from pilot.sim.virtual import VirtualDrone
from pilot.sim.world import BOOT_MS, SimWorld
from pilot.sources import Frame

REPO = Path(__file__).resolve().parents[2]
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
    scenario = make_scenario("ahead", 1)
    vd = VirtualDrone(exe)
    world = SimWorld(scenario, vd)
    link = Link(
        vd.pty,
        clock=world.now,
        ready_clock=time.monotonic,
        ready_sleep=time.sleep,
        on_open=lambda: world.advance(BOOT_MS),
    ).open()
    controller = Controller(cfg.controller, clock=world.now)
    detector = HsvBlobDetector(cfg.hsv)
    camera = world.camera()
    armed = {"fired": False}

    def firing() -> bool:
        if controller.state is State.FIRE and controller.laser_on:
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


def assert_safe_tail(tail: list[str]) -> None:
    """Laser off, sticks neutral, servos home, down until landed, disarm, then only keep-alives."""
    assert tail[:3] == ["laser_toggle", "hold_altitude", "servo_reset"], tail[:6]
    disarm = tail.index("disarm")
    downs = tail[3:disarm]
    assert downs and set(downs) == {"move_down"}
    assert set(tail[disarm + 1 :]) <= {"hold_altitude"}  # keep-alives while the firmware disarms


@pytest.mark.parametrize("stage", STAGES)
def test_fault_in_any_stage_ends_laser_off_neutral_disarmed(stage: str, virtual_drone: Path) -> None:
    f = fly_and_fault(stage, virtual_drone)
    assert f.fired_before_fault, "the fault was meant to hit while the laser was on"
    if stage in ("sigint", "sigterm"):
        assert isinstance(f.result.error, KeyboardInterrupt)
    else:
        assert isinstance(f.result.error, Boom) and stage in str(f.result.error)
    sent = names(list(f.link.sent))
    # on the wire, after the fault: laser off, sticks neutral, servos home, down, disarm
    last_on = max(i for i, n in enumerate(sent) if n == "laser_toggle")
    assert sent.count("laser_toggle") % 2 == 0, "the laser toggles must leave it off"
    tail = sent[last_on:]
    assert_safe_tail(tail)
    assert not f.result.shutdown_errors
    # and what the firmware actually did about it
    out = f.world.outputs
    assert out.laser is False and out.armed is False
    assert f.world.fw_state == "disarmed"
    assert (out.roll, out.pitch, out.yaw) == (
        dp.CHANNELS[dp.ChannelName.ROLL].median,
        dp.CHANNELS[dp.ChannelName.PITCH].median,
        dp.CHANNELS[dp.ChannelName.YAW].median,
    )
    assert f.world.model.state.z == 0.0 and f.world.model.state.crashes == 0
    assert not f.world.model.state.armed  # the flight controller saw the disarm sticks
    assert f.world.model.state.wall_hits == 0


def test_lost_camera_lands_and_disarms(virtual_drone: Path) -> None:
    from pilot.sim.flight import fly

    r = fly("behind", 2, lose_camera_at_s=9.0, executable=virtual_drone)
    assert r.reason.startswith("camera lost: simulated camera lost at t=9.0")
    assert r.final_state == "done"
    assert not r.final_laser and not r.final_armed and not r.final_fc_armed and r.final_altitude == 0.0
    assert r.crashes == 0 and r.wall_hits == 0


# -- the real program, real signals, a pseudo-terminal as the drone ---------------------------------


def make_video(path: Path, frames: int = 600) -> None:
    """A red disc in the middle of the picture: the pilot locks on and fires. Sensor noise in every frame
    (identical frames are a frozen camera, which the pilot refuses)."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 20.0, (320, 240))
    img = np.full((240, 320, 3), (150, 160, 170), np.uint8)
    cv2.circle(img, (160, 120), 40, (30, 30, 210), -1)
    rng = np.random.default_rng(1)
    for _ in range(frames):
        writer.write(cv2.add(img, rng.integers(0, 6, img.shape, np.uint8)))
    writer.release()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_cli_signal_with_laser_on(sig: signal.Signals, tmp_path: Path) -> None:
    video = tmp_path / "target.avi"
    make_video(video)
    config = tmp_path / "pilot.yaml"
    config.write_text(yaml.safe_dump({"controller": {"takeoff_ms": 200, "settle_ms": 100, "fire_ms": 60000}}))
    master, slave = os.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    os.write(master, dp.ready_line())
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), str(REPO / "generated" / "python")]))
    proc = subprocess.Popen(
        [sys.executable, "-m", "pilot", "--port", path, "--arm", "--video", str(video), "--config", str(config),
         "--no-status", "--max-seconds", "30"],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    wire = b""
    signalled_at = None
    deadline = time.monotonic() + 25
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.05)
            if ready:
                try:
                    wire += os.read(master, 4096)
                except OSError:
                    break
            if signalled_at is None and dp.laser_toggle() in wire:
                signalled_at = len(wire)
                proc.send_signal(sig)
            if proc.poll() is not None:
                # drain what is left
                while select.select([master], [], [], 0.1)[0]:
                    try:
                        chunk = os.read(master, 4096)
                    except OSError:
                        break
                    if not chunk:
                        break
                    wire += chunk
                break
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(master)
        os.close(slave)
    assert signalled_at is not None, f"the pilot never fired: {err.decode()}"
    assert proc.returncode == 130, err.decode()
    frames = [wire[i : i + dp.FRAME_LENGTH] for i in range(0, len(wire), dp.FRAME_LENGTH)]
    sent = names(frames)
    assert sent[0] == "arm"
    assert sent.count("laser_toggle") == 2  # on, then off after the signal
    after = sent[sent.index("laser_toggle") + 1 :]
    assert_safe_tail(after[after.index("laser_toggle") :])
    assert b"interrupted" in out


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
    """The link reopens the pty; opening it reboots the virtual board (as DTR resets an Uno), which
    now refuses movements as not armed: the pilot lands and disarms, nothing hits anything."""
    from pilot.sim import flight

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
    r = flight.fly("ahead", 1, observers=[Puller()], executable=virtual_drone)
    assert r.reconnects == 1 and r.error is None
    assert r.reason == "landed" and r.final_state == "done"
    assert not r.final_laser and not r.final_armed and not r.final_fc_armed and r.final_altitude == 0.0
    assert r.crashes == 0 and r.wall_hits == 0
    assert not r.fired  # it did not go on to fire at the target with a rebooted board


def test_second_interrupt_while_landing_disarms_at_once() -> None:
    """Ctrl-C, then Ctrl-C again during the landing: laser off and neutral were sent, then disarm, and out."""
    from pilot.config import ControllerConfig

    class Clock:
        t = 0.0

        def now(self) -> float:
            return self.t

        def wait_tick(self) -> None:
            self.t += 0.05

    clock = Clock()
    wire: list[bytes] = []

    class Sink:
        def send(self, frame: bytes) -> bool:
            wire.append(frame)
            if dp.decode(frame).name == "move_down" and sum(dp.decode(f).name == "move_down" for f in wire) == 3:
                raise KeyboardInterrupt  # the second Ctrl-C, after three frames of the landing
            return True

        def poll(self) -> list[dp.Reply]:
            return []

    class Frames:
        def read(self) -> Frame:
            if clock.t > 8.0:
                raise KeyboardInterrupt  # the first Ctrl-C, in flight
            return Frame(np.zeros((240, 320, 3), np.uint8), clock.t, 0)

        def close(self) -> None:
            pass

        def __enter__(self) -> Frames:
            return self

        def __exit__(self, *exc: object) -> None:
            pass

    class Seen:
        name = "fake"

        def detect(self, image: np.ndarray) -> Detection:
            return Detection(True, 200.0, 120.0, 10.0, 1.0, 320, 240)  # seen off to the right: it keeps turning

    controller = Controller(ControllerConfig(), clock=clock.now)
    result = run(Frames(), Seen(), controller, Sink(), clock, max_seconds=60, keepalive_ms=200)
    assert isinstance(result.error, KeyboardInterrupt)
    sent = names(wire)
    tail = sent[sent.index("servo_reset") - 1 :]
    assert tail == ["hold_altitude", "servo_reset", "move_down", "move_down", "move_down", "disarm"]
    assert any("interrupted again" in e for e in result.shutdown_errors)
