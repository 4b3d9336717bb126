"""Helpers for the firmware tests: building, driving the virtual drone, running the simavr bench.

Every expected number comes from the generated `drone_protocol` module (that is, from the spec), never
from a constant typed here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import drone_protocol as dp
import yaml

from generator.build import load_spec
from generator.model import Spec, check_text

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


def at_boot() -> dict[str, int]:
    """Sticks neutral with the failsafe throttle: from boot until the first sequence (a reset may be in flight)."""
    return {**neutral(), "throttle": dp.FAILSAFE_THROTTLE_US}


# --- reply lines, from the spec's model ----------------------------------------------------------------------------


class Replies:
    """Reply lines as the spec defines them (prefixes, error codes, status codes, integrity check).

    Built from the generator's model of a spec file, so the tests need nothing of the Python codec's reply API and
    work for a copy of the spec (another integrity mode, new commands) as well."""

    def __init__(self, spec: Spec) -> None:
        self.spec = spec

    def ready(self) -> str:
        s = self.spec
        return self._checked(f"{s.reply('ready').prefix} {s.name} {s.short_fingerprint} {s.integrity}")

    def accepted(self, frame: bytes) -> str:
        """The body of the accepted reply to `frame` (no status)."""
        return self.spec.reply("accepted").prefix + frame[:2].decode("ascii")

    def rejected(self, error: str) -> str:
        return self.spec.reply("rejected").prefix + self.spec.error(error).code

    def failsafe(self) -> str:
        return self.spec.reply("failsafe").prefix

    def line(self, body: str, state: str, laser: bool) -> str:
        """A whole reply line (no newline): body, status of state `state` (a name) and the laser, check."""
        st = self.spec.status
        code = st.state(state).code
        return self._checked(f"{body}{st.separator}{code}{st.laser_on if laser else st.laser_off}")

    def parse(self, line: str) -> tuple[str, str | None, bool | None]:
        """(body, state name, laser) of a reply line; the check is verified (crc8) and the status split off."""
        if self.spec.integrity == "crc8":
            text, star, check = line.rpartition("*")
            assert star and check == check_text(text.encode("ascii")), f"bad reply check: {line!r}"
            line = text
        if line.startswith(self.spec.reply("ready").prefix):
            return line, None, None
        st = self.spec.status
        body, sep, status = line[:-3], line[-3], line[-2:]
        assert sep == st.separator and len(status) == 2, f"no status in {line!r}"
        names = {s.code: s.name for s in st.states}
        assert status[0] in names and status[1] in (st.laser_on, st.laser_off), f"bad status in {line!r}"
        return body, names[status[0]], status[1] == st.laser_on

    def body(self, line: str) -> str:
        return self.parse(line)[0]

    def _checked(self, text: str) -> str:
        return text + ("*" + check_text(text.encode("ascii")) if self.spec.integrity == "crc8" else "")


SPEC = load_spec(ROOT / "spec" / "drone.yaml")
R = Replies(SPEC)


def sticks(change: dict[str, Any]) -> dict[str, int]:
    """The stick channels of a recorded output change."""
    return {name: change[name] for name in STICKS}


def accepted(frame: bytes) -> str:
    return R.accepted(frame)


def rejected(kind: dp.ErrorKind) -> str:
    return R.rejected(kind.name.lower())


# --- firmware built from a copy of the spec ------------------------------------------------------------------------


def python_env() -> dict[str, str]:
    """The environment for `python -m generator` run from the repository root."""
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def spec_copy() -> dict[str, Any]:
    """The shipped spec as data, to edit: tests never edit the live spec."""
    data: dict[str, Any] = yaml.safe_load((ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    return data


@dataclass(frozen=True)
class Built:
    """The AVR firmware and the virtual drone built from a regenerated copy of the spec."""

    spec: Spec
    library: Path
    uno_elf: Path
    virtual_drone: Path

    @property
    def replies(self) -> Replies:
        return Replies(self.spec)

    def wire(self, frame: bytes) -> bytes:
        """A frame as it goes on the wire: with its check in crc8 mode."""
        return frame + (check_text(frame).encode("ascii") if self.spec.integrity == "crc8" else b"")

    def frame(self, command: str, value: int) -> bytes:
        """The wire bytes of `command` (its name in this spec) with `value`."""
        (cmd,) = [c for c in self.spec.commands if c.direction.command == command]
        return self.wire(cmd.direction.frame(cmd.category.code, value).encode("ascii"))


def build_from_spec(data: dict[str, Any], tmp: Path) -> Built:
    """Write `data` as a spec in `tmp`, regenerate into `tmp/generated` and build the Uno firmware and the virtual
    drone against it (`make` with DRONE_PROTOCOL_DIR and FW_BUILD; the Arduino cores are shared)."""
    spec_path = tmp / "drone.yaml"
    spec_path.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True), encoding="utf-8")
    out = tmp / "generated"
    result = subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec_path), "--out", str(out)],
                            cwd=ROOT, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    library = out / "arduino" / "DroneProtocol"
    build = tmp / "build"
    make("firmware-sim")
    elf, host = build / "uno" / "uno.elf", build / "host" / "virtual_drone"
    make(str(elf), str(host), DRONE_PROTOCOL_DIR=str(library), FW_BUILD=str(build), FW_CORE_BUILD=str(BUILD))
    return Built(load_spec(spec_path), library, elf, host)


# --- the virtual drone, driven with a stepped clock ------------------------------------------------------------


@dataclass
class Trace:
    """What the virtual drone printed for one script."""

    changes: list[dict[str, Any]] = field(default_factory=list)
    tx: list[tuple[int, str]] = field(default_factory=list)
    stats: list[dict[str, Any]] = field(default_factory=list)
    end_ms: int = 0

    def lines(self, since_ms: int = 0) -> list[str]:
        """Reply lines (without newline) sent at or after `since_ms`."""
        return [line for t, text in self.tx if t >= since_ms for line in text.splitlines()]

    def replies(self, since_ms: int = 0, replies: Replies | None = None) -> list[str]:
        """Reply bodies (no status, no check) sent at or after `since_ms`; the ready line whole."""
        return [(replies or R).body(line) for line in self.lines(since_ms)]

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

    def run(self, binary: Path = VIRTUAL_DRONE) -> Trace:
        result = subprocess.run(
            [str(binary), "--stdin", "--clock", "stepped"],
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

    def lines(self) -> list[str]:
        """Reply lines (without newline)."""
        return [line for _, text in self.tx for line in text.splitlines()]

    def lines_between(self, start_ms: float, end_ms: float) -> list[str]:
        lo, hi = start_ms * 16000, end_ms * 16000
        return [line for t, text in self.tx if lo <= t < hi for line in text.splitlines()]

    def replies(self, replies: Replies | None = None) -> list[str]:
        """Reply bodies (no status, no check); the ready line whole."""
        return [(replies or R).body(line) for line in self.lines()]

    def replies_between(self, start_ms: float, end_ms: float, replies: Replies | None = None) -> list[str]:
        return [(replies or R).body(line) for line in self.lines_between(start_ms, end_ms)]

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
    timeout_s: float = 120.0,
) -> SimResult:
    """Run the real firmware in simavr; `events` are (time in ms, bytes injected then)."""
    script = "".join(f"{t:.3f} {data.hex()}\n" for t, data in events)
    result = subprocess.run(
        [str(SIM), "--elf", str(elf), "--mcu", mcu, "--until", str(until_ms)],
        input=script,
        capture_output=True,
        text=True,
        timeout=timeout_s,
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
