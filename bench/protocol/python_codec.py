"""The generated Python codec against bare floors, timed: encode and decode per message, the stream decoder, replies.

One section of `python -m bench.protocol.run` (see its docstring); the same codec in callgrind instructions is
bench/protocol/python_instructions.py.
"""

from __future__ import annotations

import gc
import inspect
import os
import random
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bench.protocol.rows import Row, Settings

ROOT = Path(__file__).resolve().parents[2]
# Measure the repository's generated module, whatever is installed; BENCH_CODEC_DIR=DIR (a folder holding a
# drone_protocol/ package, e.g. a scratch copy with a template change tried by hand) measures that one instead.
CODEC_DIR = Path(os.environ.get("BENCH_CODEC_DIR", ROOT / "generated" / "python")).resolve()
sys.path.insert(0, str(CODEC_DIR))

import drone_protocol as dp  # noqa: E402

PYTHON_TARGET = 2.0


def floor_encode(category: str, direction: str, value: int) -> bytes:
    """The floor of encoding: format the three fields, no lookup, no check."""
    return f"{category}{direction}{value:04d}".encode("ascii")


def floor_decode(frame: bytes) -> tuple[int, int, int]:
    """The floor of decoding: slice and int, no lookup, no check."""
    return frame[0], frame[1], int(frame[2:6])


def floor_reply(line: bytes) -> tuple[bytes, bytes]:
    """The floor of reading a reply line: its kind byte and the rest, no check."""
    return line[:1], line[1:].rstrip(b"\r\n")


@dataclass(frozen=True)
class Pick:
    spec: dp.CommandSpec
    value: int
    uses_default: bool


def realistic_mix(n: int, seed: int = 2) -> list[Pick]:
    """What a pilot sends: keep-alives, moves and turns at their default speeds or others, servo steps, and the
    odd laser or init command. Drawn from the spec's COMMANDS, so new commands join the mix."""
    rng = random.Random(seed)
    specs = list(dp.COMMANDS.values())
    keep_alive = dp.COMMANDS.get("hold_altitude", specs[0])
    with_default = [s for s in specs if s.default is not None]
    ranged = [s for s in specs if s.minimum < s.maximum]
    out: list[Pick] = []
    for _ in range(n):
        r = rng.random()
        if r < 0.4:
            out.append(Pick(keep_alive, keep_alive.default or keep_alive.minimum, keep_alive.default is not None))
        elif r < 0.7:
            spec = rng.choice(with_default)
            assert spec.default is not None
            out.append(Pick(spec, spec.default, True))
        elif r < 0.95:
            spec = rng.choice(ranged)
            out.append(Pick(spec, rng.randint(spec.minimum, spec.maximum), False))
        else:
            spec = rng.choice(specs)
            out.append(Pick(spec, spec.default if spec.default is not None else spec.minimum, spec.default is not None))
    return out


def distinct_frames(n: int, seed: int = 3) -> list[bytes]:
    """`n` different valid frames, uniformly over every valid frame of the spec (no repeats: no cache helps)."""
    every = [(spec, value) for spec in dp.COMMANDS.values() for value in range(spec.minimum, spec.maximum + 1)]
    picked = random.Random(seed).sample(every, min(n, len(every)))
    return [dp.encode(spec.category, spec.direction, value) for spec, value in picked]


@dataclass(frozen=True)
class Paired:
    subject_ns: float  # best pass, per item
    baseline_ns: float
    ratio: float  # median over passes of subject/baseline, each pair timed back to back


def paired(subject: Callable[[], object], baseline: Callable[[], object], items: int, passes: int,
           before_subject: Callable[[], object] | None = None) -> Paired:
    subject_t: list[int] = []
    baseline_t: list[int] = []
    subject()
    baseline()
    enabled = gc.isenabled()
    gc.disable()
    try:
        for i in range(passes):
            for run_subject in ((False, True) if i % 2 == 0 else (True, False)):
                if run_subject and before_subject is not None:
                    before_subject()
                fn = subject if run_subject else baseline
                t0 = time.perf_counter_ns()
                fn()
                elapsed = time.perf_counter_ns() - t0
                (subject_t if run_subject else baseline_t).append(elapsed)
    finally:
        if enabled:
            gc.enable()
    ratios = [s / b for s, b in zip(subject_t, baseline_t, strict=True)]
    return Paired(min(subject_t) / items, min(baseline_t) / items, statistics.median(ratios))


def _call_each(calls: Sequence[tuple[Callable[..., object], tuple[Any, ...]]]) -> Callable[[], None]:
    def loop() -> None:
        for fn, args in calls:
            fn(*args)

    return loop


def _decode_each(fn: Callable[[bytes], object], frames: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        for frame in frames:
            fn(frame)

    return loop


def _feed_each(frames: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        decoder = dp.StreamDecoder(time_fn=lambda: 0.0)
        for frame in frames:
            decoder.feed(frame, 0.0)

    return loop


def _clear_decode_cache() -> None:
    dp.codec.DECODED.clear()  # the generated decoder's memo of frames


def _feed_stream(chunks: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        feed = dp.StreamDecoder(time_fn=lambda: 0.0).feed
        for chunk in chunks:
            feed(chunk, 0.0)

    return loop


def _chunks(data: bytes, size: int) -> list[bytes]:
    return [data[i:i + size] for i in range(0, len(data), size)]


def _with_garbage(frames: Sequence[bytes], seed: int = 5) -> bytes:
    """The frames with as many random bytes as frame bytes between them (50 % garbage)."""
    rng = random.Random(seed)
    return b"".join(bytes(rng.randrange(256) for _ in range(len(f))) + f for f in frames)


def _python_row(measure: str, result: Paired, baseline_name: str, target: float | None) -> Row:
    verdict = "info" if target is None else ("met" if result.ratio <= target else "MISSED")
    return Row("python", measure, f"{result.subject_ns:.0f} ns/msg",
               f"{result.baseline_ns:.0f} ns/msg ({baseline_name})", f"{result.ratio:.2f}x",
               "-" if target is None else f"<= {target:.1f}x", verdict)


def _per_command_call(pick: Pick) -> tuple[Callable[..., bytes], tuple[int, ...]]:
    fn: Callable[..., bytes] = getattr(dp, pick.spec.name)
    if not inspect.signature(fn).parameters or pick.uses_default:
        return fn, ()
    return fn, (pick.value,)


def bench_python(settings: Settings) -> list[Row]:
    n = 1000
    passes = 40 if settings.quick else 300
    mix = realistic_mix(n)
    floor_calls = [(floor_encode, (p.spec.category.value, p.spec.direction.value, p.value)) for p in mix]
    enum_calls = [(dp.encode, (p.spec.category, p.spec.direction, p.value)) for p in mix]
    text_calls = [(dp.encode, (p.spec.category.value, p.spec.direction.value, p.value)) for p in mix]
    command_calls = [_per_command_call(p) for p in mix]
    frames = [dp.encode(p.spec.category, p.spec.direction, p.value) for p in mix]
    distinct = distinct_frames(n)
    # What the Arduino answers to that mix: mostly acceptances, some refusals and the odd failsafe.
    reply_rng = random.Random(4)
    errors = list(dp.ErrorKind)
    moving, failsafe = dp.DroneState.MOVING, dp.DroneState.FAILSAFE
    replies = [dp.accepted_line(dp.decode(f), moving, False) if reply_rng.random() < 0.9 else
               (dp.rejected_line(reply_rng.choice(errors), moving, False) if reply_rng.random() < 0.95
                else dp.failsafe_line(failsafe, False))
               for f in frames]

    # The subjects must produce what the floors produce before they are timed.
    for (fn, args), frame in zip(command_calls, frames, strict=True):
        assert fn(*args) == frame, (fn, args, frame)
    for frame in frames + distinct:
        command = dp.decode(frame)
        assert dp.encode(command.category, command.direction, command.value) == frame

    floor = _call_each(floor_calls)
    rows = [
        _python_row("encode(Category, Direction, value), mix", paired(_call_each(enum_calls), floor, n, passes),
                    "f-string", PYTHON_TARGET),
        _python_row("encode(str, str, value), mix", paired(_call_each(text_calls), floor, n, passes), "f-string",
                    PYTHON_TARGET),
        _python_row("per-command functions, mix", paired(_call_each(command_calls), floor, n, passes), "f-string",
                    PYTHON_TARGET),
        _python_row("decode(frame), mix", paired(_decode_each(dp.decode, frames), _decode_each(floor_decode, frames),
                                                  n, passes), "slice+int", PYTHON_TARGET),
        _python_row("decode(frame), 1000 distinct frames, cold", paired(
            _decode_each(dp.decode, distinct), _decode_each(floor_decode, distinct), n, passes,
            before_subject=_clear_decode_cache), "slice+int", 2.0),
        _python_row("StreamDecoder.feed(6-byte chunks), mix", paired(
            _feed_each(frames), _decode_each(floor_decode, frames), n, max(passes // 5, 10)), "slice+int", None),
        _python_row("StreamDecoder, clean stream in 4 kB reads, cold", paired(
            _feed_stream(_chunks(b"".join(distinct), 4096)), _decode_each(floor_decode, distinct), n,
            max(passes // 5, 10), before_subject=_clear_decode_cache), "slice+int", 3.0),
        _python_row("StreamDecoder, 50 % garbage in 4 kB reads, cold", paired(
            _feed_stream(_chunks(_with_garbage(distinct), 4096)), _decode_each(floor_decode, distinct), n,
            max(passes // 5, 10), before_subject=_clear_decode_cache), "slice+int", 10.0),
        _python_row("StreamDecoder, clean stream one byte per call", paired(
            _feed_stream(_chunks(b"".join(frames), 1)), _decode_each(floor_decode, frames), n,
            max(passes // 10, 10)), "slice+int", 10.0),
        _python_row("parse_reply(line), replies to the mix", paired(
            _decode_each(dp.parse_reply, replies), _decode_each(floor_reply, replies), n, max(passes // 5, 10)),
            "slice", None),
    ]
    return rows
