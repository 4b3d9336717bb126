"""The generated Python codec as its users meet it: only its documented errors for any input, the crc8 integrity
mode end to end, and Python 3.9 (Raspberry Pi OS Bullseye) with the standard library only."""

from __future__ import annotations

import contextlib
import glob
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import drone_protocol as dp
import protocol_harness as h
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

ALLOWED = (dp.ProtocolError, TypeError)

ODD_INPUTS: list[object] = [
    10**12, -1, 0, None, 1.5, math.nan, math.inf, "mf1600", ["m"], {"m": 1}, object(), b"", bytearray(b"mf1600"),
    memoryview(b"mf1600"), True, 2**4096, -(2**70), b"\x00" * 10**6,
]
# stable across processes (pytest-xdist compares the ids its workers collect; object()'s repr holds an address)
ODD_IDS = [f"{i}-{type(v).__name__}" for i, v in enumerate(ODD_INPUTS)]


@pytest.mark.parametrize("value", ODD_INPUTS, ids=ODD_IDS)
def test_decode_and_parse_reply_raise_only_documented_errors(value: object) -> None:
    for fn in (dp.decode, dp.parse_reply):
        with contextlib.suppress(*ALLOWED):  # anything else fails the test
            fn(value)  # type: ignore[arg-type]


@pytest.mark.parametrize("value", ODD_INPUTS, ids=ODD_IDS)
def test_encode_raises_only_documented_errors(value: object) -> None:
    for args in ((value,), ("m", value), ("m", "f", value), (value, "f", 1600), (dp.Category.MOVE, value, 1600)):
        with contextlib.suppress(*ALLOWED):  # anything else fails the test
            dp.encode(*args)
    with contextlib.suppress(*ALLOWED):  # anything else fails the test
        dp.move_forward(value)  # type: ignore[arg-type]


def test_floats_are_refused_never_rounded() -> None:
    """The seed's createCommand rounds 1600.6 to mf1601; the spec settles that integers only are encoded."""
    with pytest.raises(TypeError, match="must be an int"):
        dp.move_forward(1600.6)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        dp.encode("m", "f", 1600.0)  # type: ignore[arg-type]


@pytest.mark.parametrize("now", [math.nan, math.inf, -math.inf, 1e308])
def test_a_clock_that_is_not_finite_is_a_clock_error(now: float) -> None:
    with pytest.raises(dp.ClockError):
        dp.StreamDecoder().feed(b"mf1600", now)


@pytest.mark.parametrize("value", ODD_INPUTS, ids=ODD_IDS)
def test_stream_decoder_raises_only_documented_errors(value: object) -> None:
    decoder = dp.StreamDecoder(time_fn=lambda: 0.0)
    for args in ((value,), (b"mf1600", value)):
        with contextlib.suppress(*ALLOWED):  # anything else fails the test
            decoder.feed(*args)


def test_memoryview_and_bytearray_decode_like_bytes() -> None:
    frame = dp.move_up(1700)
    assert dp.decode(memoryview(frame)) == dp.decode(bytearray(frame)) == dp.decode(frame)
    assert dp.StreamDecoder().feed(memoryview(b"xx" + frame), 1.0) == [dp.decode(frame)]


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=40), st.floats(allow_nan=True, allow_infinity=True) | st.integers())
def test_any_bytes_and_any_clock(data: bytes, now: float) -> None:
    with contextlib.suppress(dp.ProtocolError):
        dp.decode(data)
    with contextlib.suppress(dp.ReplyError):
        dp.parse_reply(data)
    with contextlib.suppress(dp.ClockError, TypeError):
        dp.StreamDecoder().feed(data, now)


# Pauses near the timeout, as whole milliseconds plus a fraction near the rounding's halfway point.
_TIMEOUT = dp.INTER_BYTE_TIMEOUT_MS
pauses = st.tuples(st.integers(_TIMEOUT - 2, _TIMEOUT + 2) | st.integers(0, 3 * _TIMEOUT),
                   st.sampled_from([0.0, 0.4999, 0.5, 0.5001, -0.4999, -0.5, -0.5001]) | st.floats(-1.0, 1.0))


@settings(max_examples=300, deadline=None)
@given(st.sampled_from([0.0, 1.0, 86_400.0, 1e6, 1e9]), st.lists(st.tuples(pauses, st.integers(1, 3)), max_size=12),
       st.sampled_from([dp.move_up(1700), b"zmf16", dp.move_up(1700)[:4]]))
def test_only_the_whole_milliseconds_of_a_pause_count(start: float, steps: list[tuple[tuple[int, float], int]],
                                                     first: bytes) -> None:
    """The decoder rounds a pause only near the timeout: it must act as one given the times rounded first."""
    stream = first + b"".join(dp.move_up(1700) for _ in steps)
    raw, rounded = dp.StreamDecoder(), dp.StreamDecoder()
    at_ms, i = start * 1000.0, 0
    out: tuple[list[dp.Command], list[dp.Command]] = ([], [])
    for (whole, part), size in [((0, 0.0), 2), *steps]:
        at_ms += whole + part
        chunk, i = stream[i:i + size], i + size
        out[0].extend(raw.feed(chunk, at_ms / 1000.0))
        out[1].extend(rounded.feed(chunk, round(at_ms) / 1000.0))
    assert out[0] == out[1] and dict(raw.errors) == dict(rounded.errors) and raw.pending == rounded.pending


def test_one_byte_at_a_time_finds_what_one_chunk_finds() -> None:
    stream = b"".join(dp.command_frame(name) for name in dp.CommandName if dp.COMMANDS[name].default is not None)
    stream = b"zz" + stream[:7] + b"q" + stream + b"\xffmf16"
    whole, single = dp.StreamDecoder(), dp.StreamDecoder()
    assert whole.feed(stream, 1.0) == [c for i in range(len(stream)) for c in single.feed(stream[i:i + 1], 1.0)]
    assert dict(whole.errors) == dict(single.errors) and whole.pending == single.pending == b"mf16"


# -- crc8 ------------------------------------------------------------------------------------------------------

CRC8_CHECK = """
import json, sys
import drone_protocol as p
assert p.INTEGRITY == "crc8" and p.WIRE_LENGTH == p.FRAME_LENGTH + 2
vectors = json.load(open(sys.argv[1]))
assert vectors["integrity"] == "crc8"
for v in vectors["vectors"]:
    frame = bytes.fromhex(v["frame_hex"])
    try:
        c = p.decode(frame)
        assert v["ok"] and c.name == v["command"] and c.value == v["value"], v
        assert c.encode() == frame
    except p.ProtocolError as e:
        assert not v["ok"] and e.kind.value == v["error"], (v, e)
        assert e.kind.code == {e["name"]: e["code"] for e in ERRORS}[v["error"]], (v, e)
        assert e.position == v["position"], (v, e.position)
valid = [bytes.fromhex(v["frame_hex"]) for v in vectors["vectors"] if v["ok"]]
decoder = p.StreamDecoder()
found = decoder.feed(bytes([255]).join(valid), 1.0)
assert found == [p.decode(f) for f in valid] and decoder.errors[p.ErrorKind.BAD_CATEGORY] == len(valid) - 1
stream = b"zz" + valid[0][:5] + b"q" + bytes([255]).join(valid) + valid[0][:7]
whole, single = p.StreamDecoder(), p.StreamDecoder()
assert whole.feed(stream, 1.0) == [c for i in range(len(stream)) for c in single.feed(stream[i:i + 1], 1.0)]
assert dict(whole.errors) == dict(single.errors) and whole.pending == single.pending == valid[0][:7]
line = p.accepted_line(p.decode(p.move_up(1700)), p.DroneState.MOVING, True)
assert line.startswith(b"Amu m1*") and p.parse_reply(line).laser is True
try:
    p.parse_reply(line.replace(b"m1", b"m0"))
    raise SystemExit("a corrupted reply was accepted")
except p.ReplyError:
    pass
print("crc8 ok", len(found))
"""


def test_crc8_mode_round_trips_its_vectors_and_checks_replies(tmp_path: Path) -> None:
    spec = tmp_path / "drone.yaml"
    spec.write_text(h.edit(h.spec_text(), "  integrity: none\n", "  integrity: crc8\n"))
    assert h.generate("--spec", spec, "--out", tmp_path / "generated").code == 0
    errors = [{"name": k.name.lower(), "code": k.code} for k in dp.ErrorKind]
    script = tmp_path / "check.py"
    script.write_text(f"ERRORS = {errors!r}\n" + CRC8_CHECK)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "generated" / "python")}
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "generated" / "vectors.json")], env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stdout.startswith("crc8 ok")


# -- Python 3.9 ------------------------------------------------------------------------------------------------

def oldest_python() -> str:
    """The oldest CPython >= 3.9 on this machine (pyenv's, or on PATH), else this one."""
    for minor in (9, 10, 11):
        candidates = sorted(glob.glob(os.path.expanduser(f"~/.pyenv/versions/3.{minor}.*/bin/python3")))
        found = candidates[-1] if candidates else shutil.which(f"python3.{minor}")
        if found:
            return found
    return sys.executable


VECTORS_CHECK = """
import json, sys
import drone_protocol as p
for v in json.load(open(sys.argv[1]))["vectors"]:
    frame = bytes.fromhex(v["frame_hex"])
    try:
        c = p.decode(frame)
        assert v["ok"] and str(c.name) == v["command"] and c.value == v["value"], v
    except p.ProtocolError as e:
        assert not v["ok"], v
print("%d.%d ok" % sys.version_info[:2])
"""


def test_the_codec_imports_and_passes_the_vectors_on_the_oldest_python(tmp_path: Path) -> None:
    python = oldest_python()
    script = tmp_path / "vectors_check.py"
    script.write_text(VECTORS_CHECK)
    env = {"PATH": os.environ.get("PATH", ""), "PYTHONPATH": str(h.GENERATED / "python")}
    proc = subprocess.run([python, "-B", str(script), str(h.GENERATED / "vectors.json")],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    major, minor = (int(n) for n in proc.stdout.split()[0].split("."))
    print(f"generated codec checked under {python} (Python {major}.{minor})")
    assert (major, minor) >= (3, 9)


def test_the_codec_type_checks_for_the_oldest_python_mypy_knows() -> None:
    """mypy 2 checks code for Python >= 3.10 only; 3.9 itself is covered by the import test above and by ruff's
    py39 target (pyproject.toml: per-file-target-version)."""
    proc = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental", "--python-version", "3.10",
                           "--config-file", os.devnull, str(h.GENERATED / "python" / "drone_protocol")],
                          capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout + proc.stderr


RECORDS_CHECK = """
import sys
import drone_protocol as p
assert "typing" not in sys.modules, "the codec imported typing at run time"
reply = p.Reply(p.ReplyKind.READY)
assert reply.state is None and reply.protocol == "" and reply._fields[0] == "kind", reply
command = p.decode(p.hold_altitude())
assert type(command) is p.Command and command.encode() == p.hold_altitude(), command
assert repr(command).startswith("Command(category=") and isinstance(command.direction, p.Direction)
print("ok")
"""


def test_the_codec_never_imports_typing_at_run_time_and_its_records_stay_named_tuples() -> None:
    """typing was a third of the import's time; `-S` keeps site's own imports out of sys.modules."""
    env = {"PATH": os.environ.get("PATH", ""), "PYTHONPATH": str(h.GENERATED / "python")}
    for python in {oldest_python(), sys.executable}:
        proc = subprocess.run([python, "-B", "-S", "-c", RECORDS_CHECK], env=env, capture_output=True, text=True,
                              timeout=120)
        assert proc.stdout == "ok\n", f"{python}: {proc.stdout}{proc.stderr}"
