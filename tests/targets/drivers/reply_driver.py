"""Reply driver of the generated Python codec: stdin one line per input line in hex; stdout what parse_reply() made
of it, "ready <protocol> <fingerprint> <integrity>", "ok <kind>", "malformed <prefix>", "unknown" or "bad_check",
the format every language's reply driver shares."""

from __future__ import annotations

import sys

import drone_protocol as p


def judge(line: bytes) -> str:
    try:
        reply = p.parse_reply(line)
    except p.ReplyError as error:
        return f"malformed {error.prefix}" if error.reason == "malformed" else error.reason
    if reply.kind is p.ReplyKind.READY:
        return f"ready {reply.protocol} {reply.fingerprint} {reply.integrity}"
    return f"ok {reply.kind.name.lower()}"


def main() -> None:
    sys.stdout.write("".join(judge(bytes.fromhex(line.strip())) + "\n" for line in sys.stdin))


if __name__ == "__main__":
    main()
