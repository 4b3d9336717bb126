"""`make demo` (protocol part): show a few commands encoded and decoded by the generated module."""

from __future__ import annotations

from pathlib import Path

import drone_protocol as proto


def main() -> None:
    print(f"drone_protocol {proto.PROTOCOL_VERSION}, spec fingerprint {proto.SPEC_FINGERPRINT}, "
          f"{proto.BAUD} baud, {proto.FRAME_LENGTH}-byte frames\n")
    frames = [proto.arm(), proto.move_forward(), proto.move_up(1700), proto.turn_left(), proto.servo_right(45),
              proto.servo_reset(), proto.laser_toggle(), proto.hold_altitude(), proto.disarm()]
    for frame in frames:
        command = proto.decode(frame)
        print(f"  {frame.decode():8} -> {command.name:14} value {command.value}")
    print("\nRejected frames:")
    for bad in (b"100000", b"mf0005", b"mf00-5", b"sz0010", b"mf16"):
        try:
            proto.decode(bad)
        except proto.ProtocolError as exc:
            print(f"  {bad.decode():8} -> {type(exc).__name__}: {exc}")
    root = Path("generated")
    print("\nGenerated from spec/drone.yaml:")
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        print(f"  {path}")


if __name__ == "__main__":
    main()
