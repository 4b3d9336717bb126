"""What the firmware's sticks hold after each frame the pilot sends, for the pilot's dead reckoning (its lean,
its forward speed, its height): a pitch or throttle command holds its stick for the firmware's command timeout,
any other movement or a hold releases it, and a non-movement frame (servo, laser, status) changes nothing."""

from __future__ import annotations

import drone_protocol as dp

from .pulses import StickModel

STICK_CHANNELS = frozenset(c.value for c in dp.ChannelName)  # commands that move a stick


def deflection_steps(command: dp.Command, channel: dp.ChannelName, pulses: StickModel) -> float:
    """A stick command's deflection from its channel's median, in control steps."""
    median = dp.CHANNELS[channel].median
    return abs(pulses.steps(channel, int(command.value or median) - median))


class HeldSticks:
    def __init__(self, pulses: StickModel) -> None:
        self._pulses = pulses
        self._pitch = 0.0  # control steps, forward positive
        self._throttle = 0.0  # control steps, up positive
        self._until_ms = 0

    def pitch(self, now_ms: int) -> float:
        return self._pitch if now_ms <= self._until_ms else 0.0

    def throttle(self, now_ms: int) -> float:
        return self._throttle if now_ms <= self._until_ms else 0.0

    def sent(self, frame: bytes | None, now_ms: int) -> None:
        if frame is None:
            return
        try:
            command = dp.decode(frame)
        except dp.ProtocolError:
            return
        channel = dp.COMMANDS[command.name].target
        if channel not in STICK_CHANNELS and command.name is not dp.CommandName.HOLD_ALTITUDE:
            return
        self._pitch = self._throttle = 0.0
        self._until_ms = now_ms + dp.COMMAND_TIMEOUT_MS
        if channel == dp.ChannelName.PITCH.value:
            sense = 1 if command.name is dp.CommandName.MOVE_FORWARD else -1
            self._pitch = sense * deflection_steps(command, dp.ChannelName.PITCH, self._pulses)
        elif channel == dp.ChannelName.THROTTLE.value:
            sense = 1 if command.name is dp.CommandName.MOVE_UP else -1
            self._throttle = sense * deflection_steps(command, dp.ChannelName.THROTTLE, self._pulses)
