"""The pilot's view of the drone: only what the drone's replies confirmed (the spec's status suffix).

Every accepted, rejected and failsafe reply carries the drone's state and its laser after the frame it
answers. The pilot never infers them from what it sent: a lost frame cannot make it believe the laser
is off or the motors disarmed. ``None`` means no reply has said so yet (before the first reply, or a
dry run that has no drone).
"""

from __future__ import annotations

from dataclasses import dataclass

import drone_protocol as dp


@dataclass
class DroneView:
    state: dp.DroneState | None = None
    laser: bool | None = None
    replies: int = 0  # replies that carried a status
    last_ms: int | None = None  # when the latest status arrived (the controller's clock)
    refused_airborne: bool = False  # the drone refused a disarm as airborne: land instead
    # armed, then disarmed without a disarm sequence in between (a rebooted board): the flight controller may
    # still be armed, so a disarm (its stick sequence, harmless when disarmed) is still owed, once it is down
    disarm_owed_since_ms: int | None = None

    def update(self, reply: dp.Reply, now_ms: int) -> None:
        if reply.kind is dp.ReplyKind.REJECTED and reply.error is dp.ErrorKind.AIRBORNE:
            self.refused_airborne = True
        if reply.state is None or reply.laser is None:
            return
        was = self.state
        self.state, self.laser = reply.state, reply.laser
        if self.state is dp.DroneState.DISARMING:
            self.disarm_owed_since_ms = None
        elif self.state is dp.DroneState.DISARMED and was in dp.ARMED_STATES and was is not dp.DroneState.DISARMING:
            self.disarm_owed_since_ms = now_ms
        self.replies += 1
        self.last_ms = now_ms
        if self.state is not dp.DroneState.ARMED:
            # only "armed on the ground" takes a plain disarm; any other state re-asks the firmware
            self.refused_airborne = self.refused_airborne and self.state in dp.ARMED_STATES

    @property
    def armed(self) -> bool | None:
        return None if self.state is None else self.state in dp.ARMED_STATES

    @property
    def safe(self) -> bool:
        """Confirmed: motors cannot spin and the laser is off."""
        return self.state is not None and not self.armed and self.laser is False

    def describe(self) -> str:
        """What the drone confirmed, for the status line and the run summary."""
        if self.state is None or self.laser is None:
            return "nothing confirmed (no status reply)"
        armed = "armed" if self.armed else "not armed"
        return f"{self.state.name.lower()} ({armed}), laser {'on' if self.laser else 'off'}"
