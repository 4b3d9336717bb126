"""The generated Python codec as a reference for the TypeScript target's tests (run by them, reads stdin).

    python_reference.py decode   stdin: one frame per line in hex; stdout: "ok <command> <value>" or
                                 "err <error name> <position>"
    python_reference.py stream   stdin: "<now_ms> <hex bytes>" per line, fed at that time; stdout: "<command>
                                 <value>" per frame found, then "errors <name>=<n> ..." over every error kind (the
                                 format of tests/targets/typescript/stream_driver.mjs)
    python_reference.py info     stdout: one JSON object: fingerprint, errors, commands and accepted lines
"""

from __future__ import annotations

import json
import sys

import drone_protocol as p


def decode_lines() -> None:
    out: list[str] = []
    for line in sys.stdin:
        try:
            cmd = p.decode(bytes.fromhex(line.strip()))
        except p.ProtocolError as exc:
            assert exc.kind is not None
            out.append(f"err {exc.kind.name.lower()} {exc.position}")
        else:
            out.append(f"ok {cmd.name} {cmd.value}")
    sys.stdout.write("".join(f"{line}\n" for line in out))


def stream_lines() -> None:
    decoder = p.StreamDecoder(time_fn=lambda: 0.0)
    out: list[str] = []
    for line in sys.stdin:
        parts = line.split()
        if not parts:
            continue
        now_ms = int(parts[0])
        data = bytes.fromhex(parts[1]) if len(parts) > 1 else b""
        out.extend(f"{cmd.name} {cmd.value}" for cmd in decoder.feed(data, now_ms / 1000.0))
    counts = {kind.name.lower(): n for kind, n in decoder.errors.items()}
    out.append("errors " + " ".join(f"{name}={n}" for name, n in counts.items()))
    sys.stdout.write("".join(f"{line}\n" for line in out))


def info() -> None:
    commands = [p.decode(p.encode(s.category, s.direction, s.minimum)) for s in p.COMMANDS.values()]
    print(json.dumps({
        "fingerprint": p.SPEC_FINGERPRINT,
        "sha256": p.SPEC_SHA256,
        "errors": {kind.value: kind.code for kind in p.ErrorKind},
        "commands": {s.name: [s.category.value, s.direction.value, s.minimum, s.maximum, s.default]
                     for s in p.COMMANDS.values()},
        "accepted": [p.accepted_line(c, p.DroneState.MOVING, False).decode() for c in commands],
    }))


if __name__ == "__main__":
    {"decode": decode_lines, "stream": stream_lines, "info": info}[sys.argv[1]]()
