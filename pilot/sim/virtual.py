"""The virtual drone (the firmware's host build) as a child process with a stepped clock.

``virtual_drone --clock stepped`` opens a pseudo-terminal and prints ``{"pty": PATH}``; the pilot
opens PATH with pyserial like any serial port. Each ``step <ms>`` line on its stdin makes the
firmware read the bytes waiting on the pty and run that many milliseconds; it prints one JSON line
per change of its outputs (``t_ms``, the RC pulses, servo angles, laser, armed, state) and then
``{"tick": t_ms, "wrote": n}``. Nothing depends on the wall clock, so a flight is deterministic and runs as
fast as the two processes can exchange lines. The pty is the one place the kernel could make it depend on
the machine's load (its buffer is moved by a work queue), so each step is a barrier both ways: it names the
bytes the pilot has written since it opened the port and the firmware waits for them all (``step <ms>
<sent>``), and the world waits until the pilot's port holds all ``n`` bytes the firmware wrote back.
"""

from __future__ import annotations

import json
import os
import subprocess
from dataclasses import dataclass, fields
from pathlib import Path
from typing import IO, Any

from ..common.closing import Closing
from ..common.errors import SimulatorError
from . import drone_build

_TYPES: dict[Any, Any] = {"int": int, "float": float, "bool": bool, int: int, float: float, bool: bool}
REPO = Path(__file__).resolve().parents[2]
DEFAULT_EXE = REPO / "firmware" / "build" / "host" / "virtual_drone"
ENV_VAR = "PILOT_VIRTUAL_DRONE"


def find_executable(explicit: str | Path | None = None) -> Path:
    """The virtual drone: the explicit path, else $PILOT_VIRTUAL_DRONE, else the firmware's host build; installed
    from a wheel (no repository), the one built from the sources the package carries."""
    if not explicit and not os.environ.get(ENV_VAR) and not DEFAULT_EXE.is_file() and drone_build.PACKAGED.is_dir():
        return drone_build.build()
    candidate = Path(explicit) if explicit else Path(os.environ.get(ENV_VAR) or DEFAULT_EXE)
    if not (candidate.is_file() and os.access(candidate, os.X_OK)):
        raise SimulatorError(
            f"virtual drone {str(candidate)!r} not found; build it with `make firmware-host` "
            f"(or point {ENV_VAR} at it)"
        )
    return candidate


@dataclass(frozen=True)
class Outputs:
    """What the virtual drone's pins say at one moment."""

    roll: int
    pitch: int
    throttle: int
    yaw: int
    mode: int
    pan: float
    tilt: float
    laser: bool
    armed: bool

    @property
    def pulses(self) -> tuple[float, float, float, float, float]:
        """The RC pulses in the flight controller's order: roll, pitch, throttle, yaw, flight mode."""
        return (self.roll, self.pitch, self.throttle, self.yaw, self.mode)


@dataclass(frozen=True)
class Change:
    t_ms: int
    outputs: Outputs
    state: str


def _outputs(d: dict[str, Any]) -> Outputs:
    """The output line's fields are named as Outputs' fields (the pins the firmware drives)."""
    try:
        values = {f.name: _TYPES[f.type](d[f.name]) for f in fields(Outputs)}
    except (KeyError, TypeError, ValueError) as exc:
        raise SimulatorError(f"virtual drone: unexpected output line {d!r} ({exc})") from exc
    return Outputs(**values)


class VirtualDrone(Closing):
    def __init__(self, executable: str | Path | None = None) -> None:
        exe = find_executable(executable)
        self._proc = subprocess.Popen(
            [str(exe), "--clock", "stepped"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            bufsize=1,
        )
        self._stdin: IO[str] = self._proc.stdin  # type: ignore[assignment]
        self._stdout: IO[str] = self._proc.stdout  # type: ignore[assignment]
        first = self._line()
        if "pty" not in first:
            self.close()
            raise SimulatorError(f"virtual drone: expected its pty path first, got {first!r}")
        self.pty = str(first["pty"])
        self.t_ms = 0
        self.tx_total = 0  # bytes the firmware wrote to the pty since it was last opened
        self.outputs: Outputs | None = None
        self.state = ""
        self._closed = False

    def _line(self) -> dict[str, Any]:
        line = self._stdout.readline()
        if not line:
            err = self._proc.stderr.read() if self._proc.stderr is not None else ""
            raise SimulatorError(f"virtual drone exited (code {self._proc.poll()}): {err.strip()}")
        try:
            data = json.loads(line)
        except json.JSONDecodeError as exc:
            raise SimulatorError(f"virtual drone: not a JSON line: {line!r}") from exc
        if not isinstance(data, dict):
            raise SimulatorError(f"virtual drone: not a JSON object: {line!r}")
        return data

    def step(self, ms: int, sent: int | None = None) -> list[Change]:
        """Advance the firmware's clock by ``ms``; the output changes, in time order. ``sent``: the bytes the
        client has written to the port since it opened it; the firmware waits until they all arrived."""
        try:
            self._stdin.write(f"step {ms}\n" if sent is None else f"step {ms} {sent}\n")
            self._stdin.flush()
        except (BrokenPipeError, OSError) as exc:
            raise SimulatorError(f"virtual drone: cannot step ({exc})") from exc
        changes: list[Change] = []
        while True:
            data = self._line()
            if "tick" in data:
                self.t_ms = int(data["tick"])
                self.tx_total = int(data.get("wrote", 0))
                return changes
            out = _outputs(data)
            self.outputs = out
            self.state = str(data.get("state", ""))
            changes.append(Change(int(data["t_ms"]), out, self.state))

    def close(self) -> None:
        if getattr(self, "_closed", False):
            return
        self._closed = True
        try:
            if self._proc.poll() is None:
                try:
                    self._stdin.write("quit\n")
                    self._stdin.flush()
                except (BrokenPipeError, OSError):
                    pass
                try:
                    self._proc.wait(timeout=2.0)
                except subprocess.TimeoutExpired:
                    self._proc.kill()
                    self._proc.wait()
        finally:
            for stream in (self._proc.stdin, self._proc.stdout, self._proc.stderr):
                if stream is not None:
                    stream.close()

