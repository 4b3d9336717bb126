"""Hypothesis properties of the generated codecs: round trips, and the stream parsers of both ends.

Times are whole milliseconds. The Python StreamDecoder takes seconds (now = ms / 1000): a gap of exactly
INTER_BYTE_TIMEOUT_MS is then a float comparison whose outcome depends on the absolute time, so the strategies
below never draw a gap of exactly the timeout (in-frame gaps stay below it, resynchronising gaps above it).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass

import drone_protocol as p
import protocol_harness as h
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

TIMEOUT = p.INTER_BYTE_TIMEOUT_MS
FAST = settings(max_examples=200, deadline=None)
# Each example runs the C++ driver once (a few ms).
CPP = settings(max_examples=75, deadline=None, suppress_health_check=[HealthCheck.too_slow])

SPECS = list(p.COMMANDS.values())
commands = st.sampled_from(SPECS).flatmap(lambda s: st.tuples(st.just(s), st.integers(s.minimum, s.maximum)))
frames = commands.map(lambda sv: p.encode(sv[0].category, sv[0].direction, sv[1]))
# Bytes that look like the protocol (codes, digits) mixed with anything.
ALPHABET = sorted({ord(s.category.value) for s in SPECS} | {ord(s.direction.value) for s in SPECS}
                  | set(b"0123456789"))
protocolish = st.one_of(st.sampled_from(ALPHABET), st.integers(0, 255))
garbage = st.one_of(st.binary(max_size=24), st.lists(protocolish, max_size=24).map(bytes),
                    st.lists(frames, max_size=2).map(lambda fs: b"".join(fs)[1:]))  # frames missing a byte
in_frame_gap = st.integers(0, TIMEOUT - 1)
resync_gap = st.integers(TIMEOUT + 1, 5 * TIMEOUT + 1000)


@dataclass(frozen=True)
class Chunk:
    at_ms: int
    data: bytes


def split(data: bytes, sizes: list[int]) -> list[bytes]:
    """`data` cut into chunks of the given sizes (cycled), none empty."""
    out, i, k = [], 0, 0
    while i < len(data):
        size = max(1, sizes[k % len(sizes)]) if sizes else len(data)
        out.append(data[i:i + size])
        i, k = i + size, k + 1
    return out


def python_stream(chunks: list[Chunk | str]) -> list[str]:
    """Feed chunks to a StreamDecoder; output in the C++ driver's format (frames, marks, pending, counts)."""
    decoder = p.StreamDecoder(time_fn=lambda: 0.0)
    out: list[str] = []
    for chunk in chunks:
        if isinstance(chunk, str):
            out.append(chunk)
            continue
        for cmd in decoder.feed(chunk.data, now=chunk.at_ms / 1000):
            out.append("frame " + cmd.encode().hex())
        assert len(decoder.pending) < p.FRAME_LENGTH
    out.append(f"pending {len(decoder.pending)}")
    for kind in list(p.ErrorKind)[:7]:
        out.append(f"count {kind.name.lower()} {decoder.errors[kind]}")
    return out


def cpp_stream(chunks: list[Chunk | str]) -> list[str]:
    text = "".join(c + "\n" if isinstance(c, str) else f"{c.at_ms} {c.data.hex()}\n" for c in chunks)
    return h.run_driver("stream", text)


# -- round trips ---------------------------------------------------------------------------------------------------

@FAST
@given(commands)
def test_encode_then_decode_is_the_identity(command: tuple[p.CommandSpec, int]) -> None:
    spec, value = command
    frame = p.encode(spec.category, spec.direction, value)
    assert len(frame) == p.FRAME_LENGTH
    decoded = p.decode(frame)
    assert decoded == p.Command(spec.category, spec.direction, value, spec.name)
    assert decoded.encode() == frame
    assert p.encode(spec.category.value, spec.direction.value, value) == frame  # plain str codes too


@FAST
@given(st.binary(min_size=6, max_size=6) | frames | st.tuples(frames, st.integers(0, 5), protocolish).map(
    lambda t: t[0][:t[1]] + bytes([t[2]]) + t[0][t[1] + 1:]))
def test_decode_then_encode_is_the_identity_and_errors_point_at_the_first_bad_byte(frame: bytes) -> None:
    try:
        cmd = p.decode(frame)
    except p.ProtocolError as exc:
        kind, pos = exc.kind, exc.position
        assert kind is not None
        table = {s.direction.value: s for s in SPECS if ord(s.category.value) == frame[0]}  # bytes.isdigit: ASCII
        if kind is p.ErrorKind.BAD_CATEGORY:
            assert pos == 0 and not table
        elif kind is p.ErrorKind.BAD_DIRECTION:
            assert pos == 1 and table and chr(frame[1]) not in table
        elif kind is p.ErrorKind.BAD_DIGIT:
            assert 2 <= pos <= 5 and not frame[pos:pos + 1].isdigit() and (pos == 2 or frame[2:pos].isdigit())
        else:
            assert kind is p.ErrorKind.OUT_OF_RANGE and pos == 2 and frame[2:].isdigit()
            spec = table[chr(frame[1])]
            assert not spec.minimum <= int(frame[2:]) <= spec.maximum
        assert f"{pos}" in str(exc) or kind is p.ErrorKind.OUT_OF_RANGE, str(exc)
    else:
        assert cmd.encode() == frame


# -- stream parsers -------------------------------------------------------------------------------------------------

@st.composite
def garbage_then_frames(draw: st.DrawFn) -> tuple[list[Chunk | str], list[bytes]]:
    """Segments of arbitrary garbage, an inter-byte gap, then a valid frame (each in arbitrary chunks)."""
    chunks: list[Chunk | str] = []
    sent: list[bytes] = []
    now = draw(st.integers(0, 10_000))
    for _ in range(draw(st.integers(1, 5))):
        junk = draw(garbage)
        for piece in split(junk, draw(st.lists(st.integers(1, 7), min_size=1, max_size=4))):
            now += draw(st.integers(0, 3 * TIMEOUT))  # garbage comes with any timing
            chunks.append(Chunk(now, piece))
        frame = draw(frames)
        now += draw(resync_gap)
        for i, piece in enumerate(split(frame, draw(st.lists(st.integers(1, 6), min_size=1, max_size=4)))):
            now += draw(in_frame_gap) if i else 0
            chunks.append(Chunk(now, piece))
        chunks.append("mark")
        sent.append(frame)
    return chunks, sent


@st.composite
def clean_streams(draw: st.DrawFn) -> tuple[list[Chunk | str], list[bytes]]:
    """Valid frames only, cut anywhere; pauses of any length between frames, short ones inside a frame."""
    sent = draw(st.lists(frames, min_size=1, max_size=12))
    data = b"".join(sent)
    chunks: list[Chunk | str] = []
    now, offset = draw(st.integers(0, 10_000)), 0
    for piece in split(data, draw(st.lists(st.integers(1, 13), min_size=1, max_size=6))):
        at_boundary = offset % p.FRAME_LENGTH == 0
        now += draw(st.integers(0, 3000) if at_boundary else in_frame_gap)
        chunks.append(Chunk(now, piece))
        offset += len(piece)
    return chunks, sent


def frames_before_marks(lines: list[str]) -> list[str]:
    return [lines[i - 1] for i, line in enumerate(lines) if line == "mark"]


@FAST
@given(garbage_then_frames())
def test_python_stream_decoder_recovers_every_frame_after_garbage_and_a_gap(
        case: tuple[list[Chunk | str], list[bytes]]) -> None:
    chunks, sent = case
    assert frames_before_marks(python_stream(chunks)) == ["frame " + f.hex() for f in sent]


@CPP
@given(garbage_then_frames())
def test_cpp_stream_parser_recovers_every_frame_after_garbage_and_a_gap(
        case: tuple[list[Chunk | str], list[bytes]]) -> None:
    chunks, sent = case
    assert frames_before_marks(cpp_stream(chunks)) == ["frame " + f.hex() for f in sent]


@FAST
@given(clean_streams())
def test_python_stream_decoder_emits_exactly_the_frames_sent_when_there_is_no_garbage(
        case: tuple[list[Chunk | str], list[bytes]]) -> None:
    chunks, sent = case
    lines = python_stream(chunks)
    assert [line for line in lines if line.startswith("frame")] == ["frame " + f.hex() for f in sent]
    assert all(line.endswith(" 0") for line in lines if not line.startswith("frame")), lines  # no error, nothing left


@CPP
@given(clean_streams())
def test_cpp_stream_parser_emits_exactly_the_frames_sent_when_there_is_no_garbage(
        case: tuple[list[Chunk | str], list[bytes]]) -> None:
    chunks, sent = case
    lines = cpp_stream(chunks)
    assert [line for line in lines if line.startswith("frame")] == ["frame " + f.hex() for f in sent]
    assert all(line.endswith(" 0") for line in lines if not line.startswith("frame")), lines


@st.composite
def any_streams(draw: st.DrawFn) -> list[Chunk | str]:
    chunks: list[Chunk | str] = []
    now = draw(st.integers(0, 1_000_000))
    for _ in range(draw(st.integers(1, 30))):
        now += draw(st.one_of(in_frame_gap, resync_gap))
        data = draw(st.one_of(frames, garbage, st.lists(protocolish, min_size=1, max_size=8).map(bytes)))
        chunks.append(Chunk(now, data))
    return chunks


@CPP
@given(any_streams())
def test_python_and_cpp_stream_parsers_agree_on_any_stream(chunks: list[Chunk | str]) -> None:
    """Same frames, same error counts by kind, same bytes pending: byte for byte the same parser."""
    assert cpp_stream(chunks) == python_stream(chunks)


def test_the_inter_byte_timeout_boundary_on_both_ends() -> None:
    """A gap of exactly INTER_BYTE_TIMEOUT_MS keeps a partial frame; one millisecond more drops it (and counts)."""
    frame = max(p.encode(s.category, s.direction, s.maximum) for s in p.COMMANDS.values())
    for gap, expected in ((TIMEOUT, ["frame " + frame.hex()]), (TIMEOUT + 1, [])):
        chunks: list[Chunk | str] = [Chunk(0, frame[:3]), Chunk(gap, frame[3:])]
        for lines in (python_stream(chunks), cpp_stream(chunks)):
            assert [line for line in lines if line.startswith("frame")] == expected, (gap, lines)
            assert f"count timeout {0 if expected else 1}" in lines


def test_the_driver_rejects_nothing_silently() -> None:
    """The driver's own checks run (a sanity test of the harness: a bad mode is an error, not a pass)."""
    proc = subprocess.run([str(h.protocol_driver()), "nope"], capture_output=True, text=True, timeout=30)
    assert proc.returncode == 2
