"""Start-up checks and the live-view session of the command line (``--serve``/``--serve-viewers``,
``--record``/``--force``, the frame-source options, the serial port's permission hint), kept apart from the
flight code in cli.py.

Every check runs before anything flies or is written, and fails with one line that names the option."""

from __future__ import annotations

import argparse
import dataclasses
import errno
import sys
from collections.abc import Sequence

from ..common.errors import PilotError
from .liveserver import DEFAULT_LIMITS
from .liveview import LiveView, parse_address
from .observers import StopSwitch, WallClockPacing
from .record import prepare_directory
from .runner import Observer

SOURCE_OPTIONS = ("camera", "video", "images")
MAX_VIEWERS = 64


def check_sources(args: argparse.Namespace) -> None:
    """At most one frame source; --force only with --record. Then the --record folder itself."""
    given = [f"--{name}" for name in SOURCE_OPTIONS if getattr(args, name) is not None]
    if len(given) > 1:
        raise PilotError(f"options {' and '.join(given)} exclude each other: pick one frame source")
    if args.record is not None and not args.record.strip():
        raise PilotError("option --record: expected a folder, got an empty name")
    if args.force and not args.record:
        raise PilotError("option --force only applies to --record DIR")
    if not 1 <= args.serve_viewers <= MAX_VIEWERS:
        raise PilotError(f"option --serve-viewers must be within 1..{MAX_VIEWERS}, got {args.serve_viewers}")
    if args.record:
        prepare_directory(args.record, force=args.force)


def port_error_hint(exc: BaseException, port: str) -> PilotError | None:
    """Permission denied on the serial port -> the dialout hint (one line), else None."""
    cause: BaseException | None = exc
    while cause is not None:
        if isinstance(cause, OSError) and cause.errno == errno.EACCES:
            return PilotError(
                f"option --port: permission denied on {port}: add yourself to the dialout group "
                "(sudo usermod -aG dialout $USER, then log out and in again)"
            )
        cause = cause.__cause__ or cause.__context__
    return None


class LiveSession:
    """``--serve``: the live view, its stop switch and (for a simulated flight) wall-clock pacing."""

    def __init__(self, address: str, *, simulated: bool, viewers: int = DEFAULT_LIMITS.viewers) -> None:
        host, port = parse_address(address)
        self.stop = StopSwitch()
        limits = dataclasses.replace(DEFAULT_LIMITS, viewers=viewers, connections=max(DEFAULT_LIMITS.connections,
                                                                                      2 * viewers + 8))
        self.view = LiveView(host, port, self.stop, limits=limits)
        self.pacing = WallClockPacing() if simulated else None
        print(f"live view: {self.view.url}  (the Stop button lands the drone; the URL is its key)", flush=True)

    def observers(self) -> Sequence[Observer]:
        extra: list[Observer] = [self.stop, self.view]
        if self.pacing is not None:
            extra.append(self.pacing)
        return extra

    def close(self, summary: str) -> None:
        self.view.end(summary)
        self.view.close()


def stop_note(session: LiveSession | None) -> None:
    if session is not None and session.stop.requested:
        print(f"pilot: stopped on request: {session.stop.why}", file=sys.stderr)
