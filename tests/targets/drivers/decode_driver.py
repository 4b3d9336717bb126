"""Decode driver of the generated Python codec: stdin one frame per line in hex (an empty line is a 0-byte frame);
stdout "ok <command> <value>" or "err <error name>" per line, the format every language's decode driver shares."""

from __future__ import annotations

import sys

import drone_protocol as p


def describe(frame: bytes) -> str:
    try:
        command = p.decode(frame)
    except p.ProtocolError as exc:
        return f"err {exc.kind.name.lower() if exc.kind else '?'}"
    return f"ok {command.name} {command.value}"


if __name__ == "__main__":
    sys.stdout.write("".join(describe(bytes.fromhex(line.strip())) + "\n" for line in sys.stdin))
