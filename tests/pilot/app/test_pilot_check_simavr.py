"""``pilot check`` against the real AVR firmware in simavr: the checklist's conversation (with an injected clock)
runs on the real Uno binary: every frame is answered and accepted, the states pass through arming, armed,
disarming and moving, the failsafe is reported after the spec's silence, the drone ends disarmed with the laser
off, and the pulses on the RC pins show every channel at each speed the check commanded.

simavr takes its input as a script of timed bytes, so the conversation is first held with the fake drone, then
its frames go to the real binary at the same times, and the binary's answers are judged by the steps' criteria.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import drone_protocol as dp
import pytest
from fake_drone import FakeDrone

from pilot.app.check_steps import Bench, checklist

REPO = Path(__file__).resolve().parents[3]
BOOT_MS = 300.0  # the conversation starts after the firmware's ready line
START = 100.0  # the injected clock's origin, seconds


def _fwsupport() -> ModuleType:
    spec = importlib.util.spec_from_file_location("fwsupport", REPO / "tests" / "firmware" / "fwsupport.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("fwsupport", module)
    spec.loader.exec_module(module)
    return module


FW = _fwsupport()


class Clock:
    def __init__(self) -> None:
        self.t = START

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        # a real wait overshoots a little: no query lands on the very millisecond a firmware timer ends, where the
        # fake drone (timed from the frame) and the firmware (from its last byte, 0.5 ms later) could differ
        self.t += max(seconds, 0.001) + 0.0007


def ms(t: float) -> float:
    return BOOT_MS + (t - START) * 1000.0


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The Uno firmware and the simavr bench, built in this run's own folder."""
    build = tmp_path_factory.mktemp("firmware-sim")
    proc = subprocess.run(["make", "-s", "firmware-uno", "firmware-sim", f"FW_BUILD={build}"], cwd=REPO,
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return build


def test_the_checklist_passes_on_the_real_firmware_in_simavr(built: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    clock = Clock()
    bench = Bench(FakeDrone(clock.now), clock.now, clock.sleep)
    assert all(step.ok for step in checklist(bench))
    events = [(ms(t), frame) for t, frame in bench.sent]
    monkeypatch.setattr(FW, "SIM", built / "sim" / "drone_sim")
    # 12 simulated seconds take about 3 s; the timeout leaves room for a machine shared by many test runs
    # and one status query once a disarm sequence sent last could have ended: where the check left the drone (the
    # fake drone takes a disarm while disarmed at once; the firmware runs the disarm sticks again)
    waiting = range(250, dp.ARMING_HOLD_MS + 350, 250)
    asked = [*events, *((events[-1][0] + k, dp.query_status()) for k in waiting)]
    result = FW.simulate(asked, asked[-1][0] + 100.0, elf=built / "uno" / "uno.elf", timeout_s=900.0)
    lines = [(t / 16000.0, line) for t, text in result.tx for line in text.splitlines() if t / 16000.0 > BOOT_MS / 2]

    replies = [dp.parse_reply((line + "\n").encode()) for _, line in lines]
    answers = [r for r in replies if r.kind in (dp.ReplyKind.ACCEPTED, dp.ReplyKind.REJECTED)]
    assert len(answers) == len(asked)  # one answer to every frame of the check, and every one accepted
    assert all(r.kind is dp.ReplyKind.ACCEPTED for r in answers), [r for r in answers if r.error]
    states = [r.state for r in answers]
    S = dp.DroneState
    assert {S.ARMING, S.ARMED, S.DISARMING, S.MOVING} <= set(states) and states[0] is S.DISARMED
    failsafe = [(t, r) for (t, _), r in zip(lines, replies, strict=True) if r.kind is dp.ReplyKind.FAILSAFE]
    assert len(failsafe) == 1 and failsafe[0][1].state is S.FAILSAFE and failsafe[0][1].laser is False
    silent_from = max(t for t, _ in events if t < failsafe[0][0])
    assert abs(failsafe[0][0] - silent_from - dp.FAILSAFE_TIMEOUT_MS) <= 5.0  # reported after the spec's silence
    assert (answers[-1].state, answers[-1].laser) == (S.DISARMED, False)
    for spec in dp.COMMANDS.values():  # each commanded speed reached its RC pin
        if spec.target in {c.value for c in dp.ChannelName}:
            widths = result.widths_us(FW.PINS[spec.target], 0, events[-1][0])
            assert any(abs(w - spec.default) <= 2.0 for w in widths), spec.name
    assert result.laser_at(events[-1][0] + 100.0) == 0
