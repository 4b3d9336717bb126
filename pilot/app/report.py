"""``pilot report DIR``: one self-contained HTML page from a ``--record DIR`` recording.

It reads ``log.jsonl`` (and ``path.png`` when there is one) and writes ``report.html`` beside them (or
``--out FILE``): the state timeline, the commands, the detection confidence, the laser and the link's health
against time, the path, and the failure reason if any (``report_page``). A folder without a readable log, or a
log line that is not what ``--record`` writes, gets one line naming it, exit 2, and nothing is written.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from ..common.errors import PilotError
from .record import LOG, PATH_PICTURE
from .report_page import Flight, page

REPORT = "report.html"
EXIT_OK, EXIT_USAGE = 0, 2


def read_flight(log: Path) -> Flight:
    """The ticks, link entries and result of a recording's log; PilotError naming the line that is wrong."""
    flight = Flight()
    try:
        lines = log.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise PilotError(f"{log}: cannot read it: {exc}") from exc
    for n, line in enumerate(lines, 1):
        try:
            record = json.loads(line)
        except ValueError:
            raise PilotError(f"{log}:{n}: not a JSON object (is this a --record log?)") from None
        if not isinstance(record, dict):
            raise PilotError(f"{log}:{n}: not a JSON object (is this a --record log?)")
        if "result" in record and isinstance(record["result"], dict):
            flight.result = record["result"]
        elif "tick" in record and _tick_ok(record):
            flight.ticks.append(record)
        elif "link" in record and isinstance(record.get("t"), (int, float)):
            flight.link.append(record)
        else:
            raise PilotError(f"{log}:{n}: neither a tick, a link entry nor the result of a --record log")
    if not flight.ticks:
        raise PilotError(f"{log}: no tick recorded: nothing to report")
    return flight


def _tick_ok(r: dict[str, object]) -> bool:
    det = r.get("detection")
    return (isinstance(r.get("t"), (int, float)) and isinstance(r.get("state"), str)
            and (det is None or isinstance(det, dict)) and isinstance(r.get("replies", []), list))


def main(argv: Sequence[str] | None = None, out: Callable[[str], None] = print) -> int:
    p = argparse.ArgumentParser(prog="pilot report", description="One self-contained HTML page from a --record DIR.")
    p.add_argument("dir", metavar="DIR", help="a folder written by --record (log.jsonl, path.png)")
    p.add_argument("--out", help=f"the page to write (default DIR/{REPORT})")
    args = p.parse_args(argv)
    folder = Path(args.dir)
    try:
        if not (folder / LOG).is_file():
            raise PilotError(f"{folder}: no {LOG} here: name a folder written by --record")
        flight = read_flight(folder / LOG)
        picture = folder / PATH_PICTURE
        text = page(flight, folder.name or str(folder), picture.read_bytes() if picture.is_file() else None)
        target = Path(args.out) if args.out else folder / REPORT
        try:
            target.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise PilotError(f"option --out: cannot write {target}: {exc.strerror or exc}") from exc
    except PilotError as exc:
        print(f"pilot report: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    out(f"pilot report: {target}")
    return EXIT_OK
