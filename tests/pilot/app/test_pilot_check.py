"""``pilot check --port PORT``: the whole checklist against the virtual drone (the firmware's host build on a
pseudo-terminal, real time), whose reported outputs show that every channel, servo and the laser really moved; and
the bad benches: a board that does not answer, another spec's firmware, a channel that does not move (the failing
step named, exit 1, the drone left disarmed with the laser off)."""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import time
import tty
from pathlib import Path
from typing import Any

import drone_protocol as dp
from fake_drone import FakeDrone, PtyDrone

from pilot.app.check import main
from pilot.app.check_steps import Bench, checklist

REPO = Path(__file__).resolve().parents[3]


class Clock:
    t = 100.0

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        self.t += max(seconds, 0.001)


class NoYaw(FakeDrone):
    """A drone whose firmware has no handler for the turns: the yaw channel never moves."""

    def _handle(self, name: dp.CommandName) -> dp.ErrorKind | None:
        if dp.COMMANDS[name].target == dp.ChannelName.YAW.value:
            return dp.ErrorKind.UNSUPPORTED
        return super()._handle(name)


def check(*args: str) -> tuple[int, list[str]]:
    lines: list[str] = []
    code = main(list(args), out=lines.append)
    return code, lines


def outputs(text: str) -> list[dict[str, Any]]:
    return [r for r in map(json.loads, text.splitlines()) if "state" in r]


def test_the_checklist_passes_on_the_virtual_drone_and_every_output_really_moved(virtual_drone: Path) -> None:
    proc = subprocess.Popen([str(virtual_drone), "--clock", "realtime"], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        pty = json.loads(proc.stdout.readline())["pty"]
        code, lines = check("--port", pty, "--props-off")
    finally:
        proc.terminate()
        text, _ = proc.communicate(timeout=10)
    assert code == 0, "\n".join(lines)
    names = [line.split()[1] for line in lines if line.startswith("[PASS]")]
    assert names == ["ready", "status", "laser", "servos", "arming", "channel", "channel", "channel", "channel",
                     "failsafe", "safe"]
    assert lines[-1] == "pilot check: all 11 steps passed"
    seen = outputs(text)
    for spec in dp.COMMANDS.values():
        if spec.target in {c.value for c in dp.ChannelName}:
            assert any(o[spec.target] == spec.default and o["state"] == "moving" for o in seen), spec.name
    for servo in dp.SERVOS.values():
        assert {servo.minimum, servo.maximum} <= {o[servo.name.value] for o in seen}
    lit = [o["laser"] for o in seen]
    assert True in lit and lit[-1] is False
    states = [o["state"] for o in seen]
    assert {"arming", "armed", "disarming", "moving", "failsafe"} <= set(states)
    # what the check left before it closed the port: disarmed, laser off (the failsafe follows the silence)
    last = [o for o in seen if o["state"] != "failsafe"][-1]
    assert last["state"] == "disarmed" and last["laser"] is False and last["armed"] is False


def check_on_pty(board_says: bytes) -> tuple[int, list[str], bytes]:
    """The check against a pseudo-terminal whose board prints ``board_says`` and nothing more; what it was sent."""
    master, slave = os.openpty()
    tty.setraw(slave)  # no echo: what the master reads is what the check sent
    try:
        if board_says:
            os.write(master, board_says)
        code, lines = check("--port", os.ttyname(slave), "--props-off")
        sent = os.read(master, 4096) if select.select([master], [], [], 0)[0] else b""
    finally:
        os.close(master)
        os.close(slave)
    return code, lines, sent


def test_a_board_that_does_not_answer_fails_the_ready_step_and_sends_nothing() -> None:
    code, lines, sent = check_on_pty(b"")
    assert code == 1
    assert lines[1].startswith("[FAIL] ready") and "no ready line within" in lines[1] and "USB cable" in lines[1]
    assert "nothing was sent" in lines[1] and sent == b""
    assert len(lines) == 2  # the checklist stops there


def test_another_specs_firmware_is_named_and_gets_nothing() -> None:
    code, lines, sent = check_on_pty(b"#READY drone_protocol 0123456789abcdef none\n")
    assert code == 1
    assert lines[1].startswith("[FAIL] ready") and "another spec" in lines[1] and "0123456789abcdef" in lines[1]
    assert "make upload" in lines[1] and sent == b""


def test_a_channel_that_does_not_move_is_named_and_the_drone_is_left_safe() -> None:
    clock = Clock()
    drone = NoYaw(clock.now)
    steps = checklist(Bench(drone, clock.now, clock.sleep))
    assert [s.name for s in steps if s.ok] == ["status", "laser", "servos", "arming", "safe"]
    failed = [s for s in steps if not s.ok]
    assert len(failed) == 1 and failed[0].name == "channel yaw"
    assert "yaw did not move" in failed[0].detail and "unsupported" in failed[0].detail
    assert drone.state is dp.DroneState.DISARMED and drone.laser is False
    assert dp.disarm() in drone.frames[drone.frames.index(dp.turn_left()):]  # the disarm sticks, after it


def test_the_cli_exits_1_on_a_channel_that_does_not_move() -> None:
    pty = PtyDrone()
    pty.drone = NoYaw(time.monotonic)
    try:
        code, lines = check("--port", pty.path, "--props-off")
    finally:
        pty.close()
    assert code == 1
    assert any(line.startswith("[FAIL] channel yaw") for line in lines), lines
    assert lines[-1].endswith("failed: channel yaw")
    assert pty.drone.state is dp.DroneState.DISARMED and pty.drone.laser is False


def test_propellers_off_must_be_confirmed_without_a_terminal() -> None:
    proc = subprocess.run([sys.executable, "-m", "pilot", "check", "--port", "/dev/null"], cwd=REPO,
                          capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "pilot check: error: pilot check arms the motors: remove the propellers and pass --props-off"]
    assert proc.stdout == ""
