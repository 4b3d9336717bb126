"""One differential test across every generated stream parser (targets_harness.STREAM_DRIVERS).

The same seeded byte streams (valid frames, out-of-range values, wrong directions, garbage, partial frames,
pauses around the inter-byte timeout) go to each language's driver, which must print the same commands and the
same error counts."""

from __future__ import annotations

import collections
import random

import drone_protocol as p
import pytest
import targets_harness as t

STREAM_BYTES = 120_000
SATURATION = 0xFFFF  # the MCU parsers' counters saturate: a meaningful comparison stays below it


def burst(rng: random.Random) -> bytes:
    """One burst of bytes arriving together."""
    spec = rng.choice(list(p.COMMANDS.values()))
    head = spec.prefix
    style = rng.randrange(10)
    if style <= 3:  # valid frames, back to back
        return b"".join(p.encode(spec.category, spec.direction, rng.randint(spec.minimum, spec.maximum))
                        for _ in range(rng.randint(1, 4)))
    if style == 4:  # a value just outside (or at) the range
        edge = rng.choice((spec.minimum - 1, spec.minimum, spec.maximum, spec.maximum + 1))
        return head + b"%0*d" % (p.VALUE_WIDTH, max(0, min(10 ** p.VALUE_WIDTH - 1, edge)))
    if style == 5:  # garbage, biased toward the protocol's alphabet
        alphabet = bytes(set(b"".join(s.prefix for s in p.COMMANDS.values()) + b"0123456789 \n\x00\xff-"))
        return bytes(rng.choice(alphabet) if rng.random() < 0.7 else rng.randrange(256)
                     for _ in range(rng.randint(1, 9)))
    if style == 6:  # a partial frame (the rest lost)
        frame = p.encode(spec.category, spec.direction, rng.randint(spec.minimum, spec.maximum))
        return frame[:rng.randrange(1, p.FRAME_LENGTH)]
    if style == 7:  # another category's direction
        other = rng.choice(list(p.COMMANDS.values()))
        return head[:1] + other.prefix[1:] + b"%0*d" % (p.VALUE_WIDTH, rng.randint(spec.minimum, spec.maximum))
    if style == 8:  # one byte of a valid frame replaced
        changed = bytearray(p.encode(spec.category, spec.direction, rng.randint(spec.minimum, spec.maximum)))
        changed[rng.randrange(p.FRAME_LENGTH)] = rng.randrange(256)
        return bytes(changed)
    return b""  # a burst of nothing: only the clock moves


def stream_lines(seed: int, size: int, max_burst_lines: int = 1) -> str:
    """`<now_ms> <hex>` lines holding about `size` bytes; bursts split over lines at random byte boundaries."""
    rng = random.Random(seed)
    timeout = p.INTER_BYTE_TIMEOUT_MS
    now, total, lines = rng.randrange(2 ** 31), 0, []
    while total < size:
        data = burst(rng)
        gap = rng.choice((0, 0, 0, 1, 2, timeout - 1, timeout, timeout + 1, 3 * timeout, 5000))
        now = (now + gap) % 2 ** 32  # the millisecond clock wraps, as on the Arduino
        pieces = rng.randint(1, max_burst_lines)
        cuts = sorted(rng.sample(range(1, len(data)), min(pieces - 1, max(0, len(data) - 1)))) if data else []
        for start, end in zip([0, *cuts], [*cuts, len(data)], strict=True):
            lines.append(f"{now} {data[start:end].hex()}")
            now = (now + rng.choice((0, 0, 1, timeout))) % 2 ** 32
        total += len(data)
    return "\n".join(lines) + "\n"


def errors_of(line: str) -> dict[str, int]:
    assert line.startswith("errors "), line
    return {name: int(n) for name, n in (item.split("=") for item in line.split()[1:])}


@pytest.mark.parametrize(("seed", "max_burst_lines"), [(20261123, 1), (9, 4)])
def test_every_stream_parser_finds_the_same_commands_and_counts_the_same_errors(seed: int,
                                                                                max_burst_lines: int) -> None:
    stdin = stream_lines(seed, STREAM_BYTES, max_burst_lines)
    assert sum(len(line.split()[1]) // 2 for line in stdin.splitlines() if " " in line.strip()) >= STREAM_BYTES
    outputs = {language: t.run_stream_driver(language, stdin) for language in t.STREAM_DRIVERS}
    reference = outputs["python"]
    errors = errors_of(reference[-1])
    assert list(errors) == [k.name.lower() for k in p.ErrorKind], "the driver reports every error kind in order"
    for language, lines in outputs.items():
        assert errors_of(lines[-1]) == errors, f"{language} counts errors differently"
        at = next((i for i, (a, b) in enumerate(zip(lines, reference, strict=False)) if a != b), None)
        assert (len(lines), at) == (len(reference), None), (
            f"{language} differs from python (line {at}, {len(lines)} vs {len(reference)} lines): "
            f"{lines[max(0, (at or 0) - 2):(at or 0) + 3]} vs {reference[max(0, (at or 0) - 2):(at or 0) + 3]}")
    # The stream exercises every rule: many commands of every kind, every stream error, no saturated counter.
    commands = collections.Counter(line.split()[0] for line in reference[:-1])
    assert set(commands) == set(p.COMMANDS), set(p.COMMANDS) - set(commands)
    assert sum(commands.values()) > STREAM_BYTES // 20
    for kind in ("bad_category", "bad_direction", "bad_digit", "out_of_range", "timeout"):
        assert 100 < errors[kind] < SATURATION, (kind, errors[kind])
