"""``pilot check --port PORT``: the guided bring-up of the bench, propellers off.

It opens the link (the ready line and this spec's fingerprint), then walks the steps of ``check_steps`` (status,
laser, servo sweep, arming and disarming, each RC channel, the failsafe) and prints a pass/fail checklist with, for
each step, what the user must watch where the protocol cannot read a thing back. It stops at the first failure,
naming what to check, and always ends with the drone confirmed disarmed with the laser off. Exit 0 when every step
passed, 1 when one failed, 2 on bad options, 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence

import drone_protocol as dp

from ..common.errors import FingerprintMismatch, LinkError, PilotError, ReadyTimeout
from ..link.protocol_needs import protocol_problem
from ..link.serial_link import Link
from .check_steps import Bench, Step, checklist

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130
NOTHING_SENT = "nothing was sent: the drone is as it was"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="pilot check", description="Guided bring-up of the bench, PROPELLERS OFF: "
                                "ready line, laser, servos, arming, each RC channel, the failsafe.")
    p.add_argument("--port", required=True, help="serial port or pyserial URL of the drone's Arduino")
    p.add_argument("--baud", type=int, default=dp.BAUD, help=f"baud rate (default {dp.BAUD}, from the spec)")
    p.add_argument("--props-off", action="store_true",
                   help="confirm the propellers are off (else asked on a terminal; refused without one)")
    return p


def _props_off(args: argparse.Namespace, ask: Callable[[str], str]) -> bool:
    if args.props_off:
        return True
    if not sys.stdin.isatty():
        raise PilotError("pilot check arms the motors: remove the propellers and pass --props-off")
    return ask("pilot check arms the motors and spins them. Propellers removed? [yes/no] ").strip().lower() == "yes"


def _print(step: Step, out: Callable[[str], None]) -> None:
    out(f"[{'PASS' if step.ok else 'FAIL'}] {step.name:16} {step.detail}")
    if step.ok and step.look:
        out(f"{'':23}look: {step.look}")


def _open(args: argparse.Namespace, out: Callable[[str], None]) -> Link | None:
    """The link, after the ready line; None (the step printed) when the board does not answer as this spec."""
    link = Link(args.port, args.baud)
    try:
        link.open()
    except FingerprintMismatch as exc:
        link.close()
        _print(Step("ready", False, f"the board runs firmware of another spec ({exc.theirs}; this pilot: "
                    f"{exc.ours}): flash the firmware built from this spec (make upload PORT={args.port}); "
                    f"{NOTHING_SENT}"), out)
        return None
    except ReadyTimeout:
        link.close()
        _print(Step("ready", False, f"no ready line within {link.ready_timeout_s:g} s on {args.port}: check the "
                    "USB cable, that the board is powered and flashed with the drone firmware, and that no other "
                    f"program holds the port; {NOTHING_SENT}"), out)
        return None
    except LinkError as exc:
        link.close()
        raise PilotError(f"option --port: {exc}") from exc
    assert link.ready is not None
    _print(Step("ready", True, f"{link.ready.protocol} {link.ready.fingerprint} {link.ready.integrity}: this "
                "spec's fingerprint"), out)
    return link


def main(argv: Sequence[str] | None = None, out: Callable[[str], None] = print,
         ask: Callable[[str], str] = input) -> int:
    try:
        args = build_parser().parse_args(argv)
        if (problem := protocol_problem()) is not None:
            raise PilotError(problem)
        if not _props_off(args, ask):
            raise PilotError("pilot check needs the propellers off: nothing was sent")
        out(f"pilot check on {args.port} (props off): {dp.PROTOCOL_NAME} {dp.SPEC_FINGERPRINT}")
        link = _open(args, out)
        if link is None:
            return EXIT_FAILED
        with link:
            steps = checklist(Bench(link, time.monotonic, time.sleep), lambda step: _print(step, out))
    except PilotError as exc:
        print(f"pilot check: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("pilot check: interrupted (the drone was sent laser off and disarm)", file=sys.stderr)
        return EXIT_INTERRUPTED
    passed, total = 1 + sum(step.ok for step in steps), 1 + len(steps)  # the ready line passed
    failed = [step.name for step in steps if not step.ok]
    out(f"pilot check: all {total} steps passed" if not failed else
        f"pilot check: {passed} of {total} steps passed; failed: {', '.join(failed)}")
    return EXIT_OK if not failed else EXIT_FAILED
