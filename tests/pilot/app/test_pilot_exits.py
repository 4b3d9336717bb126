"""Honest exits: a second and a third Ctrl-C/SIGTERM, a vanished serial port. The runner against the fake drone
(injected clock), and the real program against the fake drone on a pseudo-terminal (real signals, real time);
what the pilot prints is what the drone confirmed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import drone_protocol as dp
import numpy as np
import yaml
from fake_drone import FakeDrone, PtyDrone
from runner_rig import Clock, Frames

from pilot.app.runner import RunResult, run
from pilot.common.config import ControllerConfig
from pilot.common.errors import PortLost
from pilot.control.controller import Controller, State
from pilot.vision.detect import Detection

REPO = Path(__file__).resolve().parents[3]
N = dp.CommandName


class Seen:
    name = "fake"

    def detect(self, image: np.ndarray) -> Detection:
        return Detection(True, 200.0, 120.0, 10.0, 1.0, 320, 240)  # seen off to the right: it keeps turning


class Wire:
    """The fake drone as the sink, with a hook before each frame goes out."""

    def __init__(self, drone: FakeDrone, before: Callable[[list[str]], None]) -> None:
        self.drone, self.before, self.sent = drone, before, list[str]()

    def send(self, frame: bytes) -> bool:
        self.before(self.sent)
        self.sent.append(dp.decode(frame).name)
        return self.drone.send(frame)

    def poll(self) -> list[dp.Reply]:
        return self.drone.poll()


def fly(before: Callable[[list[str]], None]) -> tuple[RunResult, Wire, Clock]:
    clock = Clock()
    wire = Wire(FakeDrone(clock.now), before)
    controller = Controller(ControllerConfig(), clock=clock.now)
    result = run(Frames(clock, 108.0), Seen(), controller, wire, clock, max_seconds=60, keepalive_ms=200)
    return result, wire, clock


def test_second_interrupt_runs_the_shortest_safe_sequence_until_the_drone_confirms() -> None:
    def second(sent: list[str]) -> None:
        if sent.count("land") == 1 and sent[-1] == "land":
            sent.append("<second Ctrl-C>")
            raise KeyboardInterrupt

    result, wire, _ = fly(second)
    assert isinstance(result.error, KeyboardInterrupt)
    assert any("interrupted again" in e for e in result.shutdown_errors)
    after = wire.sent[wire.sent.index("<second Ctrl-C>") + 1 :]
    assert set(after) <= {"land", "hold_altitude", "query_status", "laser_off"}  # nothing else: the shortest sequence
    # it went on until the drone confirmed it (the landing routine, then the disarm sequence)
    assert wire.drone.state is dp.DroneState.DISARMED and not wire.drone.laser
    assert result.safe and result.confirmed.startswith("disarmed") and result.state is State.DONE


def test_third_interrupt_stops_sending_and_says_when_the_failsafe_fires() -> None:
    def again(sent: list[str]) -> None:
        if "land" in sent and sent.count("<Ctrl-C>") < 2:  # the second and the third, one frame apart
            sent.append("<Ctrl-C>")
            raise KeyboardInterrupt

    result, wire, _ = fly(again)
    third = [e for e in result.shutdown_errors if "third" in e]
    assert third and "will failsafe in" in third[0]
    assert wire.sent[-1] == "<Ctrl-C>" and wire.sent[-3:-1] == ["land", "<Ctrl-C>"]  # nothing after the third
    assert not result.safe and "landing" in result.confirmed


def test_lost_port_ends_the_run_at_once_without_a_pretend_landing() -> None:
    def unplug(sent: list[str]) -> None:
        if "turn_right" in sent:
            raise PortLost("serial port '/dev/ttyACM0' lost and not back within 1.0 s")

    result, wire, _ = fly(unplug)
    assert isinstance(result.error, PortLost) and result.reason.startswith("serial port lost")
    assert wire.sent[-1] == "turn_right" and not result.safe_frames  # not one frame after it
    assert "will failsafe in" in result.port_lost and "no landing was sent" in result.port_lost


# -- the real program, real signals, the fake drone on a pseudo-terminal -------------------------------------


def make_video(path: Path, frames: int = 1200) -> None:
    """A red disc in the middle of the picture, with sensor noise (identical frames are a frozen camera)."""
    import cv2

    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 20.0, (320, 240))
    img = np.full((240, 320, 3), (150, 160, 170), np.uint8)
    cv2.circle(img, (160, 120), 40, (30, 30, 210), -1)
    rng = np.random.default_rng(1)
    for _ in range(frames):
        writer.write(cv2.add(img, rng.integers(0, 6, img.shape, np.uint8)))
    writer.release()


def start(tmp_path: Path, drone: PtyDrone, link: dict[str, float] | None = None) -> subprocess.Popen[bytes]:
    video = tmp_path / "target.avi"
    make_video(video)
    config = tmp_path / "pilot.yaml"
    options: dict[str, object] = {"controller": {"takeoff_ms": 200, "settle_ms": 100, "fire_ms": 60000}}
    if link:
        options["link"] = link
    config.write_text(yaml.safe_dump(options))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), str(REPO / "generated" / "python")]))
    return subprocess.Popen(
        [sys.executable, "-m", "pilot", "--port", drone.path, "--arm", "--video", str(video), "--config",
         str(config), "--no-status", "--max-seconds", "40"],
        cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )


def wait_until(cond: Callable[[], bool], proc: subprocess.Popen[bytes], timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if proc.poll() is not None or time.monotonic() > deadline:
            out, err = proc.communicate(timeout=10)
            raise AssertionError(f"condition not met (rc {proc.returncode}):\n{out.decode()}\n{err.decode()}")
        time.sleep(0.02)


def signalled(tmp_path: Path, act: Callable[[PtyDrone, subprocess.Popen[bytes]], None]) -> tuple[PtyDrone, str, str]:
    """The pilot against the fake drone until its laser is on, then ``act``; its exit status 130 checked, and what
    it printed."""
    drone = PtyDrone()
    proc = start(tmp_path, drone)
    try:
        wait_until(lambda: drone.drone.laser, proc)
        act(drone, proc)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
        drone.close()
    assert proc.returncode == 130, err.decode()
    return drone, out.decode(), err.decode()


def test_cli_signal_with_laser_on_lands_and_prints_what_the_drone_confirmed(tmp_path: Path) -> None:
    drone, out, _ = signalled(tmp_path, lambda _, proc: proc.send_signal(signal.SIGTERM))
    sent = drone.frames()
    assert sent[0] == "arm" and "laser_toggle" not in sent and "move_down" not in sent
    after = sent[len(sent) - sent[::-1].index("laser_on") :]
    assert after[0] == "laser_off" and "land" in after
    assert set(after) <= {"laser_off", "servo_reset", "land", "hold_altitude", "query_status"}
    assert drone.drone.state is dp.DroneState.DISARMED and not drone.drone.laser
    assert "the drone confirmed: disarmed (not armed), laser off" in out


def test_cli_second_signal_while_landing(tmp_path: Path) -> None:
    def twice(drone: PtyDrone, proc: subprocess.Popen[bytes]) -> None:
        proc.send_signal(signal.SIGINT)
        wait_until(lambda: drone.drone.state is dp.DroneState.LANDING, proc)
        proc.send_signal(signal.SIGINT)

    drone, out, err = signalled(tmp_path, twice)
    assert "interrupted again while landing" in err
    assert drone.drone.state is dp.DroneState.DISARMED and not drone.drone.laser
    assert "the drone confirmed: disarmed (not armed), laser off" in out


def test_cli_vanished_port_one_line_no_traceback(tmp_path: Path) -> None:
    drone = PtyDrone()
    proc = start(tmp_path, drone, {"reconnect_s": 0.2})
    try:
        wait_until(lambda: drone.drone.laser, proc)
        drone.close()  # the cable is pulled: the pseudo-terminal is gone
        pulled = time.monotonic()
        out, err = proc.communicate(timeout=30)
        took = time.monotonic() - pulled
    finally:
        if proc.poll() is None:
            proc.kill()
    text = err.decode()
    assert proc.returncode == 1, text
    assert "Traceback" not in text and "Error:" not in text
    lost = [line for line in text.splitlines() if "serial port" in line]
    assert len(lost) == 1 and "no landing was sent" in lost[0]
    assert "will failsafe in" in lost[0] or "has failsafed" in lost[0]
    assert took < 3.0, f"the run should end at once, took {took:.1f} s"
    assert "the drone confirmed: " in out.decode() and "serial port lost" in out.decode()
