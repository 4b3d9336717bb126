"""`make demo` (protocol part): every command of the spec encoded and decoded by the generated module, and one
rejected frame per parser error, each built from the spec's tables (a byte that is not a category, a value just
outside a command's range, ...), so that any spec edit flows through with no frame written here by hand."""

from __future__ import annotations

import string
from collections.abc import Iterator
from pathlib import Path

import drone_protocol as proto

from .model import check_text

PRINTABLE = (string.digits + string.ascii_lowercase + string.ascii_uppercase).encode("ascii")


def example_value(spec: proto.CommandSpec) -> int:
    """The spec's default, else the middle of the command's range."""
    return spec.default if spec.default is not None else (spec.minimum + spec.maximum) // 2


def wire(body: bytes) -> bytes:
    """The frame as it goes on the wire: with the integrity check when the spec has one."""
    return body + check_text(body).encode("ascii") if proto.CHECK_LENGTH else body


def rejected_frames() -> Iterator[tuple[str, bytes]]:
    """One bad frame per kind of parser error, derived from the spec's tables."""
    specs = list(proto.COMMANDS.values())
    first = specs[0]
    good = first.prefix + b"%0*d" % (proto.VALUE_WIDTH, example_value(first))
    categories = {c.value.encode("ascii")[0] for c in proto.Category}
    not_category = next(b for b in PRINTABLE if b not in categories)
    yield "a byte that is not a category", wire(bytes([not_category]) + good[1:])
    directions = {s.prefix[1] for s in specs if s.category is first.category}
    not_direction = next(b for b in PRINTABLE if b not in directions)
    yield "a byte that is not a direction of the category", wire(good[:1] + bytes([not_direction]) + good[2:])
    yield "a value byte that is not a digit", wire(good[:-2] + b"-" + good[-1:])
    widest = 10**proto.VALUE_WIDTH - 1
    ranged = next((s for s in specs if s.maximum < widest or s.minimum > 0), None)
    if ranged is not None:
        beyond = ranged.maximum + 1 if ranged.maximum < widest else ranged.minimum - 1
        yield f"{ranged.name} {beyond}, outside {ranged.minimum}..{ranged.maximum}", wire(
            ranged.prefix + b"%0*d" % (proto.VALUE_WIDTH, beyond))
    yield "too short", good[: proto.FRAME_LENGTH - 2]
    yield "too long", wire(good) + good[:1]


def main() -> None:
    print(f"drone_protocol {proto.PROTOCOL_VERSION}, spec fingerprint {proto.SPEC_FINGERPRINT}, "
          f"{proto.BAUD} baud, {proto.WIRE_LENGTH}-byte frames (integrity {proto.INTEGRITY})\n")
    for spec in proto.COMMANDS.values():
        frame = proto.command_frame(spec.name, example_value(spec))
        command = proto.decode(frame)
        print(f"  {frame.decode():10} -> {command.name:14} value {command.value}")
    print("\nRejected frames:")
    for why, bad in rejected_frames():
        try:
            proto.decode(bad)
        except proto.ProtocolError as exc:
            print(f"  {bad.decode('ascii', 'replace'):10} -> {type(exc).__name__}: {exc}  ({why})")
        else:
            raise SystemExit(f"demo: {bad!r} ({why}) was accepted by the generated decoder")
    root = Path("generated")
    print("\nGenerated from spec/drone.yaml:")
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        print(f"  {path}")


if __name__ == "__main__":
    main()
