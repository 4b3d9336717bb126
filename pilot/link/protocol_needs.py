"""What the pilot needs of the generated protocol module, checked before it starts.

A spec edit that renames or removes a command, state or constant the pilot uses (``land``, ``laser_off``,
``TURN_LEFT``...) is a mypy --strict error in the repository, but a user who regenerates and flies without running
it would meet an AttributeError in flight, or in the safe shutdown itself (a spec without ``land``). The pilot
reads every such name once at start-up instead and refuses to start, naming the first one missing. The list is
kept whole by tests/pilot/test_pilot_protocol_needs.py, which reads every ``dp.`` name of the pilot's code.
"""

from __future__ import annotations

import drone_protocol as dp


def _read_every_name() -> None:
    """Read every name of ``drone_protocol`` the pilot uses (an enum member's ``.value`` always exists)."""
    _ = (
        dp.ARMED_STATES, dp.ARMING_HOLD_MS, dp.BAUD, dp.CHANNELS, dp.COMMANDS, dp.COMMAND_TIMEOUT_MS,
        dp.ChannelName.PITCH, dp.ChannelName.ROLL, dp.ChannelName.THROTTLE, dp.ChannelName.YAW, dp.Command,
        dp.CommandName.HOLD_ALTITUDE, dp.CommandName.MOVE_BACKWARD, dp.CommandName.MOVE_DOWN,
        dp.CommandName.MOVE_FORWARD, dp.CommandName.MOVE_UP, dp.CommandName.TURN_LEFT, dp.CommandName.TURN_RIGHT,
        dp.DroneState.ARMED, dp.DroneState.DISARMED, dp.DroneState.DISARMING, dp.DroneState.FAILSAFE,
        dp.DroneState.LANDING, dp.ErrorKind.AIRBORNE, dp.ErrorKind.NOT_ARMED, dp.FAILSAFE_TIMEOUT_MS, dp.LANDING_MS,
        dp.PROTOCOL_NAME, dp.PROTOCOL_VERSION, dp.ProtocolError, dp.READY_TIMEOUT_MS, dp.Reply,
        dp.ReplyKind.FAILSAFE, dp.ReplyKind.READY, dp.ReplyKind.REJECTED, dp.SERVOS, dp.SPEC_FINGERPRINT,
        dp.FLIGHT_CONTROLLER_PARAMETERS, dp.ServoName.PAN, dp.ServoName.TILT, dp.arm, dp.decode, dp.disarm,
        dp.hold_altitude,
        dp.land, dp.laser_off, dp.laser_on, dp.move_backward, dp.move_down, dp.move_forward, dp.move_up,
        dp.parse_reply, dp.query_status, dp.servo_down, dp.servo_left, dp.servo_reset, dp.servo_right, dp.servo_up,
        dp.turn_left, dp.turn_right, dp.COMMANDS.values, dp.CommandSpec, dp.FAILSAFE_THROTTLE_US,
        dp.ReplyKind.ACCEPTED, dp.SERVOS.values, dp.encode,
        dp.CommandName.MOVE_LEFT, dp.CommandName.MOVE_RIGHT, dp.CommandName.SERVO_LEFT, dp.CommandName.SERVO_RIGHT,
        dp.CommandName.SERVO_RESET, dp.command_frame, dp.DroneState.HOLD_ALTITUDE, dp.DroneState.MOVING,
    )


def protocol_problem() -> str | None:
    """Why the pilot cannot start with this ``drone_protocol``, or None when it has every name the pilot uses."""
    try:
        _read_every_name()
    except AttributeError as exc:
        return (f"the generated module drone_protocol ({dp.__file__}) has no {exc.name!r}, which the pilot uses: the "
                "spec it was generated from renamed or removed it. Put it back in the spec and regenerate (python -m "
                "generator), or change the pilot to match (refusing to start)")
    return None
