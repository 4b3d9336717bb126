"""One exception root for the pilot; each subclass also inherits the built-in it resembles."""

from __future__ import annotations


class PilotError(Exception):
    """Root of every error the pilot raises on purpose."""


class ConfigError(PilotError, ValueError):
    """A bad option value or an unknown option in a config file or on the command line."""


class FrameSourceError(PilotError, OSError):
    """A frame source could not be opened or stopped delivering frames (a lost camera)."""


class LinkError(PilotError, ConnectionError):
    """The serial link to the drone failed."""


class PortLost(LinkError):
    """The serial port vanished (or failed) and could not be reopened: nothing more can reach the drone."""


class ReadyTimeout(LinkError, TimeoutError):
    """The firmware's ready line did not arrive in time."""


class FingerprintMismatch(LinkError):
    """The firmware was built from another protocol spec than this pilot."""

    def __init__(self, ours: str, theirs: str) -> None:
        super().__init__(
            f"spec fingerprint mismatch: the firmware reports {theirs!r} but this pilot was generated "
            f"from {ours!r}; rebuild the firmware and the pilot from the same spec/drone.yaml "
            "(refusing to fly)"
        )
        self.ours = ours
        self.theirs = theirs


class SimulatorError(PilotError, RuntimeError):
    """The simulated room or the virtual drone process misbehaved."""
