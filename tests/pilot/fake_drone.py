"""A fake drone that speaks the spec's replies with the status suffix, for unit tests of the pilot.

It follows the firmware's policy as the spec describes it (arming hold, command timeout, the landing
routine then the disarm sequence, disarm refused in the air, laser off on disarm and failsafe, failsafe
after the spec's silence) on an injected clock. It is a ``Sink``: ``send`` takes a frame, ``poll`` returns
the replies (and a failsafe line) due by now. Frames and replies can be dropped to model a lossy link.
"""

from __future__ import annotations

import os
import select
import shutil
import tempfile
import threading
import time
import tty
from collections.abc import Callable

import drone_protocol as dp

S = dp.DroneState
C = dp.CommandName
BUSY = frozenset({S.ARMING, S.LANDING, S.DISARMING, S.SELF_TEST})
MOVES = frozenset(n for n, spec in dp.COMMANDS.items() if spec.target in {c.value for c in dp.ChannelName})


class FakeDrone:
    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self.state = S.DISARMED
        self.laser = False
        self.frames: list[bytes] = []  # every frame that reached it
        self.drop_frames = 0  # the next n frames are lost on the way
        self.drop_replies = 0  # the next n replies are lost on the way
        self.stop_answering = False
        self._until = 0  # when the running sequence (arming, moving, landing, disarming) ends
        self._last_valid = self._now()
        self._out: list[bytes] = []
        self.log: list[tuple[int, S, bool]] = []  # (ms, state, laser) at every change

    def _now(self) -> int:
        return round(self._clock() * 1000.0)

    def _set(self, state: S, until_ms: int = 0) -> None:
        self.state = state
        self._until = self._now() + until_ms
        if state in (S.DISARMED, S.FAILSAFE):
            self.laser = False
        self.log.append((self._now(), self.state, self.laser))

    def _advance(self) -> None:
        now = self._now()
        if self.state is not S.FAILSAFE and now - self._last_valid >= dp.FAILSAFE_TIMEOUT_MS:
            self._set(S.FAILSAFE)
            self._reply(dp.failsafe_line)
            return
        if self._until and now >= self._until:
            nxt = {S.ARMING: S.ARMED, S.MOVING: S.HOLD_ALTITUDE, S.LANDING: S.DISARMING, S.DISARMING: S.DISARMED}
            if self.state in nxt:
                new = nxt[self.state]
                self._set(new, dp.ARMING_HOLD_MS if new is S.DISARMING else 0)

    def _reply(self, line: Callable[[dp.DroneState, bool], bytes]) -> None:
        """A reply line with the status after the frame (``line`` takes the state and the laser)."""
        if self.drop_replies > 0:
            self.drop_replies -= 1
            return
        if not self.stop_answering:
            self._out.append(line(self.state, self.laser))

    # -- the Sink -------------------------------------------------------------------------------------
    def send(self, frame: bytes) -> bool:
        self._advance()
        if self.drop_frames > 0:
            self.drop_frames -= 1
            return True
        self.frames.append(frame)
        try:
            command = dp.decode(frame)
        except dp.ProtocolError as exc:
            kind = exc.kind
            assert kind is not None
            self._reply(lambda state, laser: dp.rejected_line(kind, state, laser))
            return True
        self._last_valid = self._now()
        if self.state is S.FAILSAFE and dp.CommandName(command.name) is not C.QUERY_STATUS:
            self._set(S.DISARMED)  # as the firmware: the failsafe disarmed it; the query only reports it
        error = self._handle(dp.CommandName(command.name))
        if error is not None:
            self._reply(lambda state, laser: dp.rejected_line(error, state, laser))
        else:
            self._reply(lambda state, laser: dp.accepted_line(command, state, laser))
        return True

    def poll(self) -> list[dp.Reply]:
        return [dp.parse_reply(line) for line in self.poll_lines()]

    def poll_lines(self) -> list[bytes]:
        self._advance()
        out, self._out = self._out, []
        return out

    # -- the firmware's policy ----------------------------------------------------------------------
    def _handle(self, name: dp.CommandName) -> dp.ErrorKind | None:
        state, armed = self.state, self.state in dp.ARMED_STATES
        if name is C.QUERY_STATUS:
            return None  # changes nothing, refused never: the reply's status is the answer
        if name in (C.LASER_ON, C.LASER_OFF):
            self.laser = name is C.LASER_ON
            self.log.append((self._now(), self.state, self.laser))
            return None
        if name is C.LASER_TOGGLE:
            self.laser = not self.laser
            return None
        if state in BUSY:
            return dp.ErrorKind.BUSY
        if name is C.ARM:
            if not armed:
                self._set(S.ARMING, dp.ARMING_HOLD_MS)
            return None
        if name is C.DISARM:
            if state is S.ARMED:
                self._set(S.DISARMING, dp.ARMING_HOLD_MS)
            elif armed:
                return dp.ErrorKind.AIRBORNE
            return None
        if name is C.LAND:
            if not armed:
                return dp.ErrorKind.NOT_ARMED
            self._set(S.LANDING, dp.LANDING_MS)
            return None
        if name is C.FIRST_TEST:
            return dp.ErrorKind.ARMED if armed else None
        if name is C.HOLD_ALTITUDE or name in MOVES:
            if not armed:
                return dp.ErrorKind.NOT_ARMED
            if name is C.HOLD_ALTITUDE:
                self._set(S.HOLD_ALTITUDE)
            else:
                self._set(S.MOVING, dp.COMMAND_TIMEOUT_MS)
        return None


class PtyDrone:
    """The fake drone on the master side of a pseudo-terminal, in real time, for the real program: it
    prints the ready line, answers every frame with its status, and can vanish (``close``). The program
    opens it by a name of its own, as a USB device node: the kernel hands a freed /dev/pts number to the next
    pseudo-terminal, and a pilot reopening the old number could find another test's drone there."""

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self._dir = tempfile.mkdtemp(prefix="ptydrone-")
        self.path = os.path.join(self._dir, "ttyACM0")
        os.symlink(os.ttyname(self.slave), self.path)
        self.drone = FakeDrone(time.monotonic)
        self.wire = bytearray()
        self._stop = threading.Event()
        os.write(self.master, dp.ready_line())
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()
        self._open = True

    def _serve(self) -> None:
        pending = bytearray()
        while not self._stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.01)
            if ready:
                try:
                    chunk = os.read(self.master, 4096)
                except OSError:
                    return
                self.wire += chunk
                pending += chunk
                while len(pending) >= dp.FRAME_LENGTH:
                    self.drone.send(bytes(pending[: dp.FRAME_LENGTH]))
                    del pending[: dp.FRAME_LENGTH]
            for line in self.drone.poll_lines():
                try:
                    os.write(self.master, line)
                except OSError:
                    return

    def frames(self) -> list[str]:
        data = bytes(self.wire)
        return [dp.decode(data[i : i + dp.FRAME_LENGTH]).name for i in range(0, len(data), dp.FRAME_LENGTH)]

    def close(self) -> None:
        """Also what a pulled cable does: the device's name and both ends of the pseudo-terminal go away."""
        self._stop.set()
        shutil.rmtree(self._dir, ignore_errors=True)
        self._thread.join(timeout=2)
        if self._open:
            self._open = False
            for fd in (self.master, self.slave):
                os.close(fd)
