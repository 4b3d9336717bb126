"""Safety by design against one corrupted byte: every pair of commands whose valid frames lie one byte apart and
whose effects on safety differ (spec `directions.*.safety`: arm, disarm, land, laser on...; routine otherwise).

Two frames are one byte apart when they share the value digits and differ only in the category byte (the same
direction code in two categories) or only in the direction byte (two directions of one category); the value must
be valid for both. The docs list every such pair, `--check` prints them, and in crc8 mode each is caught by the
check (CRC-8 detects every single-byte error), so none can pass as the other."""

from __future__ import annotations

import functools

from .model import Command, Direction, Spec, check_text
from .records import record

# What a command does to safety; a command without `safety:` is routine (moves, turns, servos, holding).
SAFETY_EFFECTS = ("arm", "disarm", "land", "laser_on", "laser_off", "laser_toggle", "self_test")
ROUTINE = "routine"


@record
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


@functools.lru_cache(maxsize=4)
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
    by_codes = _by_codes(spec)  # looked up once: hashing the spec for the cache costs more than the search
    own = _command_of(by_codes, frame)
    for pos in range(len(frame)):
        for code in range(256):
            other = frame[:pos] + chr(code) + frame[pos + 1:]
            if other != frame and _command_of(by_codes, other) not in (None, own):
                return False
    return True


def _command_of(by_codes: dict[str, Direction], frame: str) -> str | None:
    d = by_codes.get(frame[:2])
    if d is not None and frame[2:].isdigit() and frame[2:].isascii():
        return d.command if d.minimum <= int(frame[2:]) <= d.maximum else None
    return None


@functools.lru_cache(maxsize=4)
def _by_codes(spec: Spec) -> dict[str, Direction]:
    """The first direction of each two code bytes, in spec order (built once: `spec.commands` is rebuilt on
    every access)."""
    out: dict[str, Direction] = {}
    for c in spec.commands:
        out.setdefault(c.category.code + c.direction.code, c.direction)
    return out


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
    return list(_safe_defaults(spec))


@functools.lru_cache(maxsize=4)
def _safe_defaults(spec: Spec) -> tuple[tuple[Command, str], ...]:
    exposed = {c.direction.command for n in one_byte_neighbours(spec) for c in (n.a, n.b)}
    out = []
    for c in spec.commands:
        d = c.direction
        frame = d.frame(c.category.code, d.default_frame_value)
        if d.command in exposed and d.default is not None and free_of_neighbours(spec, frame):
            out.append((c, frame))
    return tuple(out)


@record
class _Group:
    """The valid wire frames of the commands of one safety effect, stored by column (byte j of every frame) so
    that distances are counted in C, and where each command's frames lie within the group."""

    effect: str
    columns: tuple[bytes, ...]
    spans: dict[int, tuple[int, int]]


@functools.lru_cache(maxsize=4)
def _targets(spec: Spec, crc8: bool) -> tuple[_Group, ...]:
    """Every valid frame of the spec on the wire (with its check in crc8 mode), grouped by safety effect."""
    table = [int(check_text(bytes([b])), 16) for b in range(256)]
    by_effect: dict[str, tuple[list[bytes], dict[int, tuple[int, int]]]] = {}
    for c in spec.commands:
        d = c.direction
        wires, spans = by_effect.setdefault(d.safety or ROUTINE, ([], {}))
        first = len(wires)
        prefix, width = d.frame(c.category.code, 0)[:-d.field.width].encode(), d.field.width
        if not crc8:
            wires += [prefix + b"%0*d" % (width, value) for value in range(d.minimum, d.maximum + 1)]  # d.frame()
        head, state = b"", 0
        for value in range(d.minimum, d.maximum + 1) if crc8 else ():
            frame = prefix + b"%0*d" % (width, value)
            if frame[:-1] != head:  # the check of all but the last digit: once per ten values
                head, state = frame[:-1], 0
                for byte in head:
                    state = table[state ^ byte]
            wires.append(frame + b"%02X" % table[state ^ frame[-1]])
        spans[c.index] = (first, len(wires))
    lengths = {len(w) for wires, _ in by_effect.values() for w in wires}
    if len(lengths) > 1:
        raise ValueError(f"wire frames of different lengths {sorted(lengths)}: no Hamming distance between them")
    return tuple(_Group(effect, tuple(b"".join(wires)[j::len(wires[0])] for j in range(len(wires[0]))), spans)
                 for effect, (wires, spans) in by_effect.items())


def _sent(spec: Spec, frame: bytes, crc8: bool) -> tuple[bytes, int, str]:
    """The valid frame `frame` (with or without its check in crc8 mode) as sent, its command's index and effect;
    KeyError if no command sends it."""
    for c in spec.commands:
        d = c.direction
        width = d.field.width
        prefix = d.frame(c.category.code, 0)[:-width].encode()
        digits = frame[len(prefix):len(prefix) + width]
        if not frame.startswith(prefix) or not digits.lstrip(b"-").isdigit():
            continue
        value = int(digits)
        plain = d.frame(c.category.code, value).encode()
        wire = plain + check_text(plain).encode() if crc8 else plain
        if d.minimum <= value <= d.maximum and frame in (plain, wire):
            return wire, c.index, d.safety or ROUTINE
    raise KeyError(frame)


@functools.cache
def _equal_to(byte: int) -> bytes:
    """A translation table: 1 for `byte`, 0 for every other byte."""
    return bytes(int(b == byte) for b in range(256))


def substitution_rates(spec: Spec, frame: bytes, crc8: bool, q: float) -> tuple[float, float]:
    """Exact probabilities that `frame`, each of its wire bytes replaced with probability q by one of the 255
    others, arrives as another valid command, and as one with another safety effect: the sum, over every valid
    wire frame of another command at Hamming distance d, of q^d (1-q)^(n-d) / 255^d."""
    groups = _targets(spec, crc8)
    sent, index, effect = _sent(spec, frame, crc8)
    n = len(sent)
    other = hazard = 0.0
    for group in groups:
        # each column's equal bytes as 0/1 bytes of one integer: the sum counts each frame's equal bytes (<= n)
        equal = sum(int.from_bytes(col.translate(_equal_to(b)), "big")
                    for b, col in zip(sent, group.columns))
        counts = equal.to_bytes(len(group.columns[0]), "big")
        first, end = group.spans.get(index, (0, 0))
        own = counts[first:end]
        for k in range(1, n + 1):
            p = (counts.count(n - k) - own.count(n - k)) * (q ** k * (1 - q) ** (n - k) / 255 ** k)
            other += p
            hazard += p * (group.effect != effect)
    return other, hazard


def form_figures(spec: Spec, q: float) -> list[tuple[Command, str, str, float, float, float]]:
    """For each command of safe_defaults: its other form's frame and its default frame, and the chance at `q`
    that they arrive with another safety effect: the other form with no check, the default with no check and
    with crc8. What the docs print (the bench prints more)."""
    out = []
    for c, frame in safe_defaults(spec):
        other = c.direction.frame(c.category.code, c.direction.minimum)
        out.append((c, other, frame, substitution_rates(spec, other.encode(), False, q)[1],
                    substitution_rates(spec, frame.encode(), False, q)[1],
                    substitution_rates(spec, frame.encode(), True, q)[1]))
    return out
