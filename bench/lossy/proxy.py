"""A lossy serial cable: a pseudo-terminal pair between the pilot and the virtual drone's pty that drops,
inserts and flips bytes, each with a third of the given per-byte probability, in both directions.

The virtual drone runs on a stepped clock, so the proxy moves bytes at step boundaries: what the pilot wrote
goes to the drone just before a step, what the drone answered comes back to the pilot just after it (the same
timing as a direct link: a frame sent at one tick is answered by the next). Every damage is logged with the
simulated time, so the bench can allow one reply round trip per damage.
"""

from __future__ import annotations

import contextlib
import os
import random
import select
import time
import tty
from dataclasses import dataclass, field


@dataclass
class Damage:
    t_ms: int
    direction: str  # "up" (pilot to drone) or "down"
    kind: str  # "drop", "insert", "flip"


@dataclass
class LossyProxy:
    drone_pty: str
    rate: float
    seed: int = 0
    enabled: bool = False  # the ready line goes through clean: the bench measures the flight, not the boot
    damages: list[Damage] = field(default_factory=list)
    bytes_up: int = 0
    bytes_down: int = 0

    def __post_init__(self) -> None:
        self._rng = random.Random(self.seed)
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self.drone = os.open(self.drone_pty, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.drone)

    def _drain(self, fd: int, quiet_s: float = 0.0005, limit_s: float = 0.02) -> bytes:
        """What is waiting on ``fd``, waiting briefly for the kernel's pty work queue to deliver it."""
        data = bytearray()
        deadline = time.monotonic() + limit_s
        while time.monotonic() < deadline:
            ready, _, _ = select.select([fd], [], [], quiet_s)
            if not ready:
                break
            try:
                chunk = os.read(fd, 4096)
            except (BlockingIOError, OSError):
                break
            if not chunk:
                break
            data += chunk
        return bytes(data)

    def _damage(self, data: bytes, direction: str, t_ms: int) -> bytes:
        if not self.enabled or self.rate <= 0.0:
            return data
        out = bytearray()
        for byte in data:
            if self._rng.random() >= self.rate:
                out.append(byte)
                continue
            kind = self._rng.choice(("drop", "insert", "flip"))
            self.damages.append(Damage(t_ms, direction, kind))
            if kind == "insert":
                out.append(self._rng.randrange(256))
                out.append(byte)
            elif kind == "flip":
                out.append(byte ^ (1 << self._rng.randrange(8)))
        return bytes(out)

    def up(self, t_ms: int) -> None:
        """Pilot to drone, before a step."""
        data = self._drain(self.master)
        self.bytes_up += len(data)
        if data:
            os.write(self.drone, self._damage(data, "up", t_ms))

    def down(self, t_ms: int) -> None:
        """Drone to pilot, after a step."""
        data = self._drain(self.drone)
        self.bytes_down += len(data)
        if data:
            os.write(self.master, self._damage(data, "down", t_ms))
            time.sleep(0.0005)  # let the kernel hand them to the pilot's end before it polls

    def close(self) -> None:
        for fd in (self.master, self._slave, self.drone):
            with contextlib.suppress(OSError):
                os.close(fd)
