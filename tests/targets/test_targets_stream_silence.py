"""A partial frame never survives a silence longer than the inter-byte timeout, in any language's stream parser,
however long the silence (the C++ parser once measured it in 16 bits and kept a frame across 65,536-65,556 ms)
and across the wrap of a 32-bit millisecond clock (millis() after 49.7 days). No expire() call is needed."""

from __future__ import annotations

import drone_protocol as p
import pytest
import targets_harness as t

WRAP = 2 ** 32
GAPS = (p.INTER_BYTE_TIMEOUT_MS + 1, 1000, 65535, 65536, 65537, 65540, 65556, 65557, 131072 + 5, 10 ** 6, 2 ** 31)
# The clock the bytes arrive on: from boot, and just before millis() wraps (the silence spans the wrap).
STARTS = (1000, WRAP - 7)


def stream(start: int, gap: int) -> tuple[str, bytes]:
    frame = p.arm()
    after = p.turn_right(1624)
    later = (start + gap) % WRAP
    return f"{start} {frame[:4].hex()}\n{later} {frame[4:].hex()}\n{(later + 5) % WRAP} {after.hex()}\n", after


@pytest.mark.parametrize("language", sorted(t.STREAM_DRIVERS))
def test_a_partial_frame_is_dropped_after_any_silence_longer_than_the_timeout(language: str) -> None:
    for start in STARTS:
        for gap in GAPS:
            if language == "python" and start + gap >= WRAP:
                continue  # Python's clock is time.monotonic() in seconds: it does not wrap
            text, after = stream(start, gap)
            lines = t.run_stream_driver(language, text)
            commands, errors = lines[:-1], dict(kv.split("=") for kv in lines[-1].split()[1:])
            assert commands == [f"{p.decode(after).name} {p.decode(after).value}"], (language, start, gap, lines)
            assert errors["timeout"] == "1", (language, start, gap, lines[-1])


@pytest.mark.parametrize("language", sorted(t.STREAM_DRIVERS))
def test_a_pause_within_the_timeout_keeps_the_frame(language: str) -> None:
    for start in STARTS:
        text, after = stream(start, p.INTER_BYTE_TIMEOUT_MS)
        if language == "python" and start + p.INTER_BYTE_TIMEOUT_MS >= WRAP:
            continue
        lines = t.run_stream_driver(language, text)
        want = [f"{c.name} {c.value}" for c in (p.decode(p.arm()), p.decode(after))]
        assert lines[:-1] == want, (language, start, lines)
