"""Helpers for the firmware tests: building, driving the virtual drone, running the simavr bench.

Every expected number comes from the generated `drone_protocol` module (that is, from the spec), never
from a constant typed here.
"""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import drone_protocol as dp

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "firmware" / "build"
VIRTUAL_DRONE = BUILD / "host" / "virtual_drone"
SIM = BUILD / "sim" / "drone_sim"
UNO_ELF = BUILD / "uno" / "uno.elf"
CYCLES_PER_US = 16  # the simulated ATmega runs at 16 MHz

# Arduino pins of the default wiring (firmware/drone/pins.h): the test checks the wiring too.
PINS = {"roll": 2, "pitch": 3, "throttle": 4, "yaw": 5, "mode": 6, "pan": 9, "tilt": 10}
LASER_PIN = 13
# Servo calibration of firmware/drone/pins.h (hardware, not protocol): 0..180 deg -> 544..2400 us.
SERVO_MIN_US, SERVO_MAX_US, SERVO_FULL_SCALE = 544, 2400, 180
STICKS = ("roll", "pitch", "throttle", "yaw")


def make(*targets: str, **variables: str) -> None:
    """Run the top-level make for these targets (quietly; output shown only on failure)."""
    cmd = ["make", "-s", "-C", str(ROOT), *targets, *(f"{k}={v}" for k, v in variables.items())]
    result = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert result.returncode == 0, f"{' '.join(cmd)} failed:\n{result.stdout}\n{result.stderr}"


def servo_us(degrees: int) -> int:
    return SERVO_MIN_US + (degrees * (SERVO_MAX_US - SERVO_MIN_US) + SERVO_FULL_SCALE // 2) // SERVO_FULL_SCALE


def neutral() -> dict[str, int]:
    """Sticks at their medians (Table 4)."""
    return {name: dp.CHANNELS[name].median for name in STICKS}


def on_ground() -> dict[str, int]:
    """Sticks neutral with the throttle at its minimum: disarmed or armed on the ground."""
    return {**neutral(), "throttle": dp.CHANNELS[dp.ChannelName.THROTTLE].minimum}


# --- the virtual drone, driven with a stepped clock ------------------------------------------------------------


@dataclass
class Trace:
    """What the virtual drone printed for one script."""

    changes: list[dict[str, Any]] = field(default_factory=list)
    tx: list[tuple[int, str]] = field(default_factory=list)
    stats: list[dict[str, Any]] = field(default_factory=list)
    end_ms: int = 0

    def replies(self, since_ms: int = 0) -> list[str]:
        """Reply lines (without newline) sent at or after `since_ms`."""
        return [line for t, text in self.tx if t >= since_ms for line in text.splitlines()]

    def state_at(self, t_ms: int) -> dict[str, Any]:
        """The outputs in force at time t_ms (the last change at or before it)."""
        current = self.changes[0]
        for change in self.changes:
            if change["t_ms"] > t_ms:
                break
            current = change
        return current

    def first_change(self, since_ms: int = 0, **match: Any) -> dict[str, Any]:
        for change in self.changes:
            if change["t_ms"] >= since_ms and all(change[k] == v for k, v in match.items()):
                return change
        raise AssertionError(f"no change with {match} since {since_ms} ms in {self.changes}")


class Script:
    """A stepped-clock script for `virtual_drone --stdin --clock stepped`; the clock starts at 0 ms."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.t_ms = 0

    def send(self, data: bytes) -> Script:
        """Bytes arrive on the serial line now (at 115200 baud, 11-12 bytes per ms)."""
        self.lines.append("rx " + data.hex())
        return self

    def step(self, ms: int) -> Script:
        assert ms >= 0
        if ms:
            self.lines.append(f"step {ms}")
            self.t_ms += ms
        return self

    def stats(self) -> Script:
        self.lines.append("stats")
        return self

    def arm(self, period_ms: int = 200) -> Script:
        """Arm and wait out the arming hold, sending keep-alive frames so that the failsafe stays away.

        The keep-alive is servo_reset, which leaves everything as it is (servos are at their defaults).
        """
        keepalive = dp.servo_reset()
        self.send(dp.arm()).step(1)
        waited = 1
        while waited < dp.ARMING_HOLD_MS + 5:
            self.step(period_ms).send(keepalive)
            waited += period_ms
        return self.step(5)  # the last keep-alive is read and answered before the caller goes on

    def run(self) -> Trace:
        result = subprocess.run(
            [str(VIRTUAL_DRONE), "--stdin", "--clock", "stepped"],
            input="\n".join(self.lines) + "\n",
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert result.returncode == 0, result.stderr
        trace = Trace()
        for line in result.stdout.splitlines():
            record = json.loads(line)
            if "tx" in record:
                trace.tx.append((record["t_ms"], record["tx"]))
            elif "tick" in record:
                trace.end_ms = record["tick"]
            elif "replies_dropped" in record:
                trace.stats.append(record)
            else:
                trace.changes.append(record)
        return trace


# --- the simavr bench ---------------------------------------------------------------------------------------------


@dataclass
class SimResult:
    pulses: dict[int, list[tuple[int, int]]]  # pin -> [(rise cycle, width cycles)]
    levels: list[tuple[int, int]]  # laser pin: [(cycle, level)]
    tx: list[tuple[int, str]]  # [(cycle, line)]
    end: dict[str, Any]

    def widths_us(self, pin: int, start_ms: float, end_ms: float) -> list[float]:
        lo, hi = start_ms * 16000, end_ms * 16000
        return [w / CYCLES_PER_US for rise, w in self.pulses.get(pin, []) if lo <= rise < hi]

    def replies(self) -> list[str]:
        return [line for _, text in self.tx for line in text.splitlines()]

    def replies_between(self, start_ms: float, end_ms: float) -> list[str]:
        lo, hi = start_ms * 16000, end_ms * 16000
        return [line for t, text in self.tx if lo <= t < hi for line in text.splitlines()]

    def laser_at(self, t_ms: float) -> int:
        level = 0
        for t, v in self.levels:
            if t > t_ms * 16000:
                break
            level = v
        return level


def simulate(
    events: Iterable[tuple[float, bytes]],
    until_ms: float,
    elf: Path = UNO_ELF,
    mcu: str = "atmega328p",
) -> SimResult:
    """Run the real firmware in simavr; `events` are (time in ms, bytes injected then)."""
    script = "".join(f"{t:.3f} {data.hex()}\n" for t, data in events)
    result = subprocess.run(
        [str(SIM), "--elf", str(elf), "--mcu", mcu, "--until", str(until_ms)],
        input=script,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    pulses: dict[int, list[tuple[int, int]]] = {}
    levels: list[tuple[int, int]] = []
    tx: list[tuple[int, str]] = []
    end: dict[str, Any] = {}
    for line in result.stdout.splitlines():
        if not line.startswith("{"):
            continue  # simavr's own "Loaded ..." messages
        record = json.loads(line)
        kind = record["ev"]
        if kind == "pulse":
            pulses.setdefault(record["pin"], []).append((record["rise"], record["width"]))
        elif kind == "level":
            levels.append((record["t"], record["v"]))
        elif kind == "tx":
            tx.append((record["t"], record["text"]))
        elif kind == "end":
            end = record
    assert end, "the simulation did not finish"
    return SimResult(pulses, levels, tx, end)
