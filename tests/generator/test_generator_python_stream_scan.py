"""The generated Python StreamDecoder's chunk scan (split at frame-shaped bytes, garbage counted by kind with
compiled patterns) against the plainest reading of the rule: at each position a valid frame is taken whole, any other
start is one error of the kind problem() names, and the valid start of a frame at the end waits for the rest."""

from __future__ import annotations

import itertools
import random

import drone_protocol as dp
import pytest
from drone_protocol import stream as dp_stream
from hypothesis import given, settings
from hypothesis import strategies as st

CODES = sorted({*dp.codec.BY_BYTES, *(d for t in dp.codec.BY_BYTES.values() for d in t), *b"0123456789", 0xFF})


def reference(data: bytes) -> tuple[list[dp.Command], dict[dp.ErrorKind, int], bytes]:
    """One position at a time, with the codec's own valid() and problem()."""
    out: list[dp.Command] = []
    errors = dict.fromkeys(dp.ErrorKind, 0)
    i, n = 0, len(data)
    while i < n:
        if n - i >= dp.WIRE_LENGTH:
            command = dp.codec.valid(data[i:i + dp.WIRE_LENGTH])
            if command is not None:
                out.append(command)
                i += dp.WIRE_LENGTH
                continue
        found = dp.codec.problem(data, i, min(dp.WIRE_LENGTH, n - i))
        if found is None:
            return out, errors, data[i:]
        errors[found[0]] += 1
        i += 1
    return out, errors, b""


def scanned(data: bytes) -> tuple[list[dp.Command], dict[dp.ErrorKind, int], bytes]:
    decoder = dp.StreamDecoder()
    out = decoder.feed(data, 0.0)
    return out, dict(decoder.errors), decoder.pending


def piece(rng: random.Random) -> bytes:
    spec = rng.choice(list(dp.COMMANDS.values()))
    roll = rng.random()
    if roll < 0.4:
        return dp.command_frame(spec.name, rng.randint(spec.minimum, spec.maximum))
    if roll < 0.5:  # frame-shaped, in range or not
        return spec.prefix + b"%04d" % rng.randint(0, 9999)
    if roll < 0.6:
        return dp.command_frame(spec.name, spec.maximum)[:rng.randint(1, dp.WIRE_LENGTH - 1)]
    return bytes(rng.choice(CODES) for _ in range(rng.randint(1, 8)))


@pytest.mark.parametrize("seed", range(4))
def test_the_scan_finds_what_one_position_at_a_time_finds(seed: int) -> None:
    rng = random.Random(seed)
    for _ in range(300):
        data = b"".join(piece(rng) for _ in range(rng.randint(0, 40)))
        if rng.random() < 0.5:
            dp.codec.DECODED.clear()
        assert scanned(data) == reference(data), data


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=60))
def test_the_scan_agrees_with_the_reference_on_any_bytes(data: bytes) -> None:
    assert scanned(data) == reference(data)


def test_an_out_of_range_frame_overlapping_a_valid_one_loses_neither() -> None:
    """After frame-shaped bytes that are not valid the next frame may start inside them: "ml0000" (out of range)
    holds "l0000" plus one byte, a laser toggle when it is a digit."""
    toggle = dp.command_frame(dp.CommandName.LASER_TOGGLE)
    data = b"m" + toggle + dp.command_frame(dp.CommandName.ARM)
    assert data[:dp.WIRE_LENGTH] == b"ml0000" and dp.codec.valid(data[:dp.WIRE_LENGTH]) is None
    assert scanned(data) == reference(data)
    assert [c.name for c in scanned(data)[0]] == [dp.CommandName.LASER_TOGGLE, dp.CommandName.ARM]


def test_category_bytes_in_garbage_are_counted_without_problem(monkeypatch: pytest.MonkeyPatch) -> None:
    """A category byte followed by none of its directions is a bad_direction counted at C speed: problem() runs only
    where a category and one of its directions start no frame, so the garbage path does not slow down with more
    categories."""
    calls = []
    original = dp.codec.problem

    def counting(data: bytes, start: int, length: int) -> tuple[dp.ErrorKind, int] | None:
        calls.append(start)
        return original(data, start, length)

    monkeypatch.setattr(dp_stream, "problem", counting)
    category = next(iter(dp.codec.BY_BYTES))
    not_direction = next(b for b in range(0x80, 0x100) if b not in dp.codec.BY_BYTES[category])
    garbage = bytes([category, not_direction]) * 50
    data = garbage + dp.command_frame(dp.CommandName.ARM)
    out, errors, pending = scanned(data)
    assert [c.name for c in out] == [dp.CommandName.ARM] and pending == b""
    assert errors[dp.ErrorKind.BAD_DIRECTION] == 50 and errors[dp.ErrorKind.BAD_CATEGORY] == 50
    assert calls == []


def test_the_separator_byte_inside_garbage_does_not_misplace_a_pair() -> None:
    """The pieces of garbage are searched joined by _SEP; a _SEP byte inside the garbage itself (after a category,
    and before a category and one of its directions) must not shift where problem() looks."""
    sep = dp_stream._SEP
    category = next(iter(dp.codec.BY_BYTES))
    direction = next(iter(dp.codec.BY_BYTES[category]))
    arm = dp.command_frame(dp.CommandName.ARM)
    pair = bytes([category, direction]) + b"x"
    data = b"".join([sep, bytes([category]) + sep + sep, arm, sep * 3 + pair, arm, pair + sep, arm, sep + pair])
    assert scanned(data) == reference(data)
    assert scanned(data)[1][dp.ErrorKind.BAD_DIGIT] == 3  # the three pairs


def test_a_category_before_a_frame_whose_first_byte_is_its_direction() -> None:
    """Garbage ending in a category, followed by a frame whose category byte is one of that category's directions
    (m then l, laser's category, a direction of move): a pair, and problem() names its bad digit."""
    edges = [(c, d) for c, table in dp.codec.BY_BYTES.items() for d in table if d in dp.codec.BY_BYTES]
    assert edges, "the shipped spec has a category that is a direction of another"
    for category, direction in edges:
        frame = next(dp.command_frame(s.name, s.default if s.default is not None else s.minimum)
                     for s in dp.COMMANDS.values() if s.prefix[0] == direction)
        arm = dp.command_frame(dp.CommandName.ARM)
        data = b"\xff" + arm + b"\xfe" + bytes([category]) + frame + arm
        dp.codec.DECODED.clear()
        assert scanned(data) == reference(data), data


def test_the_memo_of_frames_stays_bounded_whatever_the_chunk() -> None:
    """The stream checks the memo's bound once a chunk: a chunk of more new frames than it holds decodes them all
    and leaves the memo no larger than its bound; smaller chunks fill it up to the bound, then it starts over."""
    bound = dp.codec._DECODED_MAX
    every = (dp.command_frame(s.name, v) for s in dp.COMMANDS.values() for v in range(s.minimum, s.maximum + 1))
    frames = list(itertools.islice(every, 2 * bound + 10))
    assert len(frames) == 2 * bound + 10, "the spec has too few distinct frames"
    dp.codec.DECODED.clear()
    big = b"".join(frames[:bound + 10])
    assert [c.encode() for c in dp.StreamDecoder().feed(big, 0.0)] == frames[:bound + 10]
    assert len(dp.codec.DECODED) <= bound
    decoder = dp.StreamDecoder()
    sizes = []
    for i in range(0, 2 * bound, 100):
        assert [c.encode() for c in decoder.feed(b"".join(frames[i:i + 100]), 0.0)] == frames[i:i + 100]
        sizes.append(len(dp.codec.DECODED))
    assert max(sizes) <= bound and sizes.index(max(sizes)) < len(sizes) - 1  # filled, then started over
