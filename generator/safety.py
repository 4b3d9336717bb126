"""Safety by design against one corrupted byte: every pair of commands whose valid frames lie one byte apart and
whose effects on safety differ (spec `directions.*.safety`: arm, disarm, land, laser on...; routine otherwise).

Two frames are one byte apart when they share the value digits and differ only in the category byte (the same
direction code in two categories) or only in the direction byte (two directions of one category); the value must
be valid for both. The docs list every such pair, `--check` prints them, and in crc8 mode each is caught by the
check (CRC-8 detects every single-byte error), so none can pass as the other."""

from __future__ import annotations

from dataclasses import dataclass

from .model import Command, Spec

# What a command does to safety; a command without `safety:` is routine (moves, turns, servos, holding).
SAFETY_EFFECTS = ("arm", "disarm", "land", "laser_on", "laser_off", "laser_toggle", "self_test")
ROUTINE = "routine"


@dataclass(frozen=True)
class Neighbours:
    """Commands `a` and `b` (in spec order) and how many valid frames of `a` are one byte from one of `b`."""

    a: Command
    b: Command
    frames: int
    example_a: str
    example_b: str

    @staticmethod
    def effect(command: Command) -> str:
        return command.direction.safety or ROUTINE

    @classmethod
    def label(cls, command: Command) -> str:
        name, effect = command.direction.command, cls.effect(command)
        return name if name == effect else f"{name}, {effect}"

    def text(self, spec: Spec) -> str:
        caught = "; crc8 catches it" if spec.integrity == "crc8" else ""
        many = f" (and {self.frames - 1} more frame{'s' if self.frames > 2 else ''})" if self.frames > 1 else ""
        return (f"{self.example_a} ({self.label(self.a)}) is one byte from {self.example_b} ({self.label(self.b)})"
                f"{many}{caught}")


def one_byte_neighbours(spec: Spec) -> tuple[Neighbours, ...]:
    """Every pair of commands one byte apart whose safety effects differ, in spec order."""
    out = []
    commands = spec.commands
    for i, a in enumerate(commands):
        for b in commands[i + 1:]:
            if (a.direction.safety or ROUTINE) == (b.direction.safety or ROUTINE):
                continue
            same_category = a.category.code == b.category.code
            if same_category == (a.direction.code == b.direction.code):
                continue  # both bytes differ (or neither: the same command)
            low = max(a.direction.minimum, b.direction.minimum)
            high = min(a.direction.maximum, b.direction.maximum)
            if low > high or a.direction.field.width != b.direction.field.width:
                continue
            out.append(Neighbours(a, b, high - low + 1, a.direction.frame(a.category.code, low),
                                  b.direction.frame(b.category.code, low)))
    return tuple(out)


def free_of_neighbours(spec: Spec, frame: str) -> bool:
    """Whether no single corrupted byte turns `frame` into a valid frame of another command."""
    for pos in range(len(frame)):
        for code in range(256):
            other = frame[:pos] + chr(code) + frame[pos + 1:]
            if other != frame and _command_of(spec, other) not in (None, _command_of(spec, frame)):
                return False
    return True


def _command_of(spec: Spec, frame: str) -> str | None:
    for c in spec.commands:
        d = c.direction
        if frame[:2] == c.category.code + d.code and frame[2:].isdigit() and frame[2:].isascii():
            return d.command if d.minimum <= int(frame[2:]) <= d.maximum else None
    return None


def report(spec: Spec) -> list[str]:
    """What `--check` prints: one line per pair, and a summary (nothing when there is no pair)."""
    pairs = one_byte_neighbours(spec)
    if not pairs:
        return []
    lines = [f"safety: {p.text(spec)}" for p in pairs]
    state = "each caught by crc8" if spec.integrity == "crc8" else "frame.integrity none: none is caught"
    lines.append(f"safety: {len(pairs)} pair{'s' if len(pairs) != 1 else ''} of commands one corrupted byte apart "
                 f"with different safety effects ({state})")
    return lines


def safe_defaults(spec: Spec) -> list[tuple[Command, str]]:
    """Commands whose default frame no single corrupted byte turns into another command while another of their
    frames is one byte from a command with another safety effect: the choice the routine traffic makes."""
    exposed = {c.direction.command for n in one_byte_neighbours(spec) for c in (n.a, n.b)}
    out = []
    for c in spec.commands:
        d = c.direction
        frame = d.frame(c.category.code, d.default_frame_value)
        if d.command in exposed and d.default is not None and free_of_neighbours(spec, frame):
            out.append((c, frame))
    return out
