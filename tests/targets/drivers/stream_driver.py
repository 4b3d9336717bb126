"""Stream driver of the generated Python codec, in the format every language's driver shares.

stdin: one line per burst, `<now_ms> <hex bytes>`, fed to one StreamDecoder at that time.
stdout: `<command name> <value>` for every command found, then one line
`errors <name>=<count> ...` with every error kind of the spec, in spec order.
"""

from __future__ import annotations

import sys

import drone_protocol as p


def main() -> None:
    decoder = p.StreamDecoder(time_fn=lambda: 0.0)
    out: list[str] = []
    for line in sys.stdin.buffer:
        parts = line.split()
        if not parts:
            continue
        data = bytes.fromhex(parts[1].decode("ascii")) if len(parts) > 1 else b""
        for command in decoder.feed(data, int(parts[0]) / 1000):
            out.append(f"{command.name} {command.value}")
    out.append("errors " + " ".join(f"{kind.name.lower()}={n}" for kind, n in decoder.errors.items()))
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
