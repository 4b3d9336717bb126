"""The Python and C++ codecs agree with vectors.json and with each other on a large sample of inputs."""

from __future__ import annotations

import collections
import json
import random
from typing import Any

import drone_protocol as p
import protocol_harness as h
import pytest

VECTORS: list[dict[str, Any]] = json.loads((h.GENERATED / "vectors.json").read_text())["vectors"]
SAMPLE_SIZE = 100_000


def python_result(frame: bytes) -> str:
    """The Python decode of `frame` in the driver's output format."""
    try:
        cmd = p.decode(frame)
    except p.ProtocolError as exc:
        assert exc.kind is not None
        return f"err {exc.kind.name.lower()}"
    return f"ok {cmd.name} {ord(cmd.category.value)} {ord(cmd.direction.value)} {cmd.value}"


def cpp_results(frames: list[bytes]) -> list[str]:
    lines = h.run_driver("decode", "".join(f.hex() + "\n" for f in frames))
    assert len(lines) == len(frames), "the driver skipped or added lines"
    return lines


def test_the_vectors_cover_every_command_and_every_frame_error() -> None:
    assert {v["command"] for v in VECTORS if v["ok"]} == set(p.COMMANDS)
    kinds = {"bad_category", "bad_direction", "bad_digit", "out_of_range", "too_short", "too_long"}
    assert {v["error"] for v in VECTORS if not v["ok"]} == kinds
    assert len({v["frame_hex"] for v in VECTORS}) == len(VECTORS), "duplicate vectors"
    for v in VECTORS:
        assert bytes.fromhex(v["frame_hex"]).decode("latin-1") == v["frame"] or "\\x" in v["frame"], v


@pytest.mark.parametrize("vector", VECTORS, ids=[f"{v['frame_hex'] or 'empty'}" for v in VECTORS])
def test_python_decode_matches_the_vector(vector: dict[str, Any]) -> None:
    frame = bytes.fromhex(vector["frame_hex"])
    if vector["ok"]:
        cmd = p.decode(frame)
        assert (cmd.name, cmd.category.value, cmd.direction.value, cmd.value) == (
            vector["command"], vector["category"], vector["direction"], vector["value"])
        assert cmd.encode() == frame
        assert p.encode(vector["category"], vector["direction"], vector["value"]) == frame
        spec = p.COMMANDS[cmd.name]
        assert spec.minimum <= cmd.value <= spec.maximum
    else:
        with pytest.raises(p.ProtocolError) as info:
            p.decode(frame)
        assert info.value.kind is not None
        assert (info.value.kind.name.lower(), info.value.position) == (vector["error"], vector["position"])
        assert isinstance(info.value, ValueError)
        assert str(info.value), "an error without a message"


def test_cpp_decode_matches_every_vector() -> None:
    frames = [bytes.fromhex(v["frame_hex"]) for v in VECTORS]
    for vector, line in zip(VECTORS, cpp_results(frames), strict=True):
        if vector["ok"]:
            expected = f"ok {vector['command']} {ord(vector['category'])} {ord(vector['direction'])} {vector['value']}"
        else:
            expected = f"err {vector['error']}"
        assert line == expected, vector


def near_valid_frames(count: int, seed: int) -> list[bytes]:
    """6-byte inputs biased toward almost-valid frames, where the two codecs are most likely to differ."""
    rng = random.Random(seed)
    specs = list(p.COMMANDS.values())
    categories = [ord(c.value) for c in p.Category]
    directions = sorted({ord(s.direction.value) for s in specs})
    edge = [0, 1, 9, 10, 99, 100, 180, 181, 999, 1000, 1034, 1035, 1999, 2000, 2001, 2012, 2013, 9999]
    alphabet = sorted(set(categories + directions + list(b"0123456789") + [0, 0x20, 0x2D, 0x7F, 0xFF]))
    out: list[bytes] = []
    for i in range(count):
        spec = rng.choice(specs)
        head = bytes([ord(spec.category.value), ord(spec.direction.value)])
        style = i % 6
        if style == 0:  # anything at all
            frame = rng.randbytes(6)
        elif style == 1:  # a valid command at any value (in or out of range)
            frame = head + b"%04d" % rng.randrange(10_000)
        elif style == 2:  # a valid command near the edges of every range
            frame = head + b"%04d" % max(0, min(9999, rng.choice(edge) + rng.choice((-1, 0, 0, 1))))
        elif style == 3:  # a valid frame with one byte replaced
            value = rng.randint(spec.minimum, spec.maximum)
            mutable = bytearray(head + b"%04d" % value)
            mutable[rng.randrange(6)] = rng.randrange(256)
            frame = bytes(mutable)
        elif style == 4:  # bytes of the protocol's own alphabet
            frame = bytes(rng.choice(alphabet) for _ in range(6))
        else:  # a category with another category's direction
            frame = bytes([rng.choice(categories), rng.choice(directions)]) + b"%04d" % rng.choice(edge)
        assert len(frame) == 6
        out.append(frame)
    return out


def test_python_and_cpp_agree_on_a_large_sample_of_6_byte_inputs() -> None:
    frames = near_valid_frames(SAMPLE_SIZE, seed=20261121)
    python = [python_result(f) for f in frames]
    cpp = cpp_results(frames)
    differ = [(f, a, b) for f, a, b in zip(frames, python, cpp, strict=True) if a != b]
    assert differ == [], f"{len(differ)} inputs decode differently, e.g. {differ[:5]}"
    # The bias works: every outcome is well represented, so agreement means something.
    outcomes = collections.Counter(r.split()[1] if r.startswith("err") else "ok" for r in python)
    for outcome in ("ok", "bad_category", "bad_direction", "bad_digit", "out_of_range"):
        assert outcomes[outcome] >= SAMPLE_SIZE // 50, outcomes
    assert len({r for r in python if r.startswith("ok")}) > 500, "too few distinct valid commands"


def test_python_and_cpp_agree_on_every_length() -> None:
    rng = random.Random(7)
    good = max(p.encode(s.category, s.direction, s.maximum) for s in p.COMMANDS.values())
    frames = [good[:n] for n in range(7)] + [good + b"0", good * 2, b"", rng.randbytes(40)]
    frames += [rng.randbytes(rng.randrange(12)) for _ in range(2000)]
    assert [python_result(f) for f in frames] == cpp_results(frames)


def test_both_ends_write_and_read_the_same_reply_lines() -> None:
    """The Arduino's reply encoders print exactly what the Python reply functions print and parse_reply reads.

    The driver cycles the status through the states in spec order and sets the laser at odd indexes."""
    lines = [bytes.fromhex(line) for line in h.run_driver("replies", "")]
    states = list(p.DroneState)
    commands = [p.decode(p.encode(s.category, s.direction, s.minimum)) for s in p.COMMANDS.values()]
    errors = list(p.ErrorKind)
    accepted = [(c, states[i % len(states)], i % 2 == 1) for i, c in enumerate(commands)]
    rejected = [(k, states[(i + 1) % len(states)], (i + 1) % 2 == 1) for i, k in enumerate(errors)]
    failsafe = [(s, i % 2 == 1) for i, s in enumerate(states)]
    expected = [p.ready_line(), *(p.accepted_line(*a) for a in accepted), *(p.rejected_line(*r) for r in rejected),
                *(p.failsafe_line(*f) for f in failsafe)]
    assert lines == expected
    ready = p.parse_reply(lines[0])
    assert (ready.kind, ready.protocol, ready.fingerprint) == (p.ReplyKind.READY, p.PROTOCOL_NAME, p.SPEC_FINGERPRINT)
    assert ready.integrity == p.INTEGRITY
    rest = iter(lines[1:])
    for (cmd, state, laser), line in zip(accepted, rest, strict=False):
        reply = p.parse_reply(line)
        assert (reply.kind, reply.category, reply.direction, reply.state, reply.laser) == (
            p.ReplyKind.ACCEPTED, cmd.category, cmd.direction.value, state, laser)
    for (kind, state, laser), line in zip(rejected, rest, strict=False):
        reply = p.parse_reply(line)
        assert (reply.error, reply.state, reply.laser) == (kind, state, laser)
    for (state, laser), line in zip(failsafe, rest, strict=False):
        reply = p.parse_reply(line)
        assert (reply.kind, reply.state, reply.laser) == (p.ReplyKind.FAILSAFE, state, laser)
