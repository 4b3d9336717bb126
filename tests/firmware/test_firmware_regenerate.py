"""Every spec edit a user can make builds and runs with no hand edit outside spec/: a COPY of the spec gets a new
category (c camera, direction p, a 0-9999 field), a new direction (mg glide_forward on pitch), a new init routine
(iz zoom) and a renamed direction (turn l: left -> ccw); it is regenerated into a temporary folder, and the real AVR
firmware and the virtual drone are built from it. Directions of existing categories reach their category's
handler; a category or routine the firmware has no handler for is answered `unsupported` (Eu) until one is
written. Then the same with frame.integrity crc8.
"""

from __future__ import annotations

from typing import Any

import drone_protocol as dp
import fwsupport as fw
import pytest

from generator.model import check_text

SLOT_MS = 60  # one frame per slot: new pulses start at the next 20 ms output frame


def edited_spec() -> dict[str, Any]:
    data = fw.spec_copy()
    data["fields"]["frames"] = {"width": 4, "unit": "none", "parameter": "count", "range": [0, 9999],
                              "description": "Frames to take"}
    assert "c" not in data["categories"]
    data["categories"]["c"] = {
        "name": "camera", "hardware": "Camera", "description": "Camera commands.", "field": "frames",
        "directions": {"p": {"name": "photo", "description": "Take photos"}},
    }
    moves = data["categories"]["m"]["directions"]
    assert "g" not in moves
    moves["g"] = {"name": "glide_forward", "description": "Glide forward", "channel": "pitch", "default": "high"}
    routines = data["categories"]["i"]["directions"]
    assert "z" not in routines
    routines["z"] = {"name": "zoom", "description": "Zooms the camera", "routine": "zoom()"}
    data["categories"]["t"]["directions"]["l"]["name"] = "ccw"
    return data


@pytest.fixture(scope="module")
def edited(tmp_path_factory: pytest.TempPathFactory) -> fw.Built:
    return fw.build_from_spec(edited_spec(), tmp_path_factory.mktemp("edited"))


def plan(built: fw.Built) -> tuple[list[tuple[int, bytes]], list[str]]:
    """(time ms, wire bytes) after arming, and the reply lines they must get."""
    r = built.replies
    sends = [
        (built.frame("camera_photo", 42), r.line(r.rejected("unsupported"), "armed", False)),
        (built.frame("zoom", 0), r.line(r.rejected("unsupported"), "armed", False)),
        (built.frame("move_glide_forward", 1700), r.line("Amg", "moving", False)),
        (built.frame("turn_ccw", 1424), r.line("Atl", "moving", False)),
    ]
    return [(SLOT_MS * k, frame) for k, (frame, _) in enumerate(sends)], [line for _, line in sends]


def test_the_edited_spec_generates_a_handler_less_dispatch_fallback(edited: fw.Built) -> None:
    dispatch = (edited.library / "src" / "DroneProtocol_dispatch.h").read_text()
    assert "call_camera" in dispatch and "Error::Unsupported" in dispatch
    assert edited.spec.short_fingerprint != dp.SPEC_FINGERPRINT


def test_new_frames_in_the_virtual_drone(edited: fw.Built) -> None:
    script = fw.Script()
    script.send(edited.frame("arm", 0)).step(1)
    for _ in range(dp.ARMING_HOLD_MS // 200 + 1):  # past the arming hold, the link kept alive
        script.step(200).send(edited.frame("servo_reset", 0))
    t0 = script.step(5).t_ms
    sends, expected = plan(edited)
    for t, frame in sends:
        script.step(t - (script.t_ms - t0)).send(frame)
    trace = script.step(20).run(binary=edited.virtual_drone)
    assert trace.lines()[0] == edited.replies.ready()
    assert trace.lines(since_ms=t0) == expected
    assert trace.changes[-1]["pitch"] == dp.CHANNELS[dp.ChannelName.PITCH].median  # the turn ended the glide
    assert trace.changes[-1]["yaw"] == 1424
    assert any(c["pitch"] == 1700 for c in trace.changes)


def test_new_frames_in_simavr(edited: fw.Built) -> None:
    events: list[tuple[float, bytes]] = [(50.0, edited.frame("arm", 0))]
    events += [(50.0 + 300 * k, edited.frame("servo_reset", 0)) for k in range(1, 8)]
    t0 = 50.0 + dp.ARMING_HOLD_MS + 150
    sends, expected = plan(edited)
    events += [(t0 + t, frame) for t, frame in sends]
    end = t0 + sends[-1][0] + SLOT_MS
    result = fw.simulate(events, end, elf=edited.uno_elf)
    assert result.lines()[0] == edited.replies.ready()
    assert result.lines_between(t0, end) == expected
    glide = result.widths_us(fw.PINS["pitch"], t0 + sends[2][0] + 25, t0 + sends[3][0])
    assert glide and all(abs(w - 1700) <= 2 for w in glide), glide
    turn = result.widths_us(fw.PINS["yaw"], t0 + sends[3][0] + 25, end)
    assert turn and all(abs(w - 1424) <= 2 for w in turn), turn


# --- frame.integrity: crc8 ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def crc8(tmp_path_factory: pytest.TempPathFactory) -> fw.Built:
    data = fw.spec_copy()
    data["frame"]["integrity"] = "crc8"
    return fw.build_from_spec(data, tmp_path_factory.mktemp("crc8"))


def corrupt_check(frame: bytes) -> bytes:
    """The frame with its check digits replaced by another valid pair."""
    good = frame[-2:]
    other = check_text(bytes([frame[0] ^ 1]) + frame[1:-2]).encode("ascii")
    assert other != good
    return frame[:-2] + other


def crc8_plan(built: fw.Built) -> tuple[list[tuple[int, bytes]], list[str]]:
    r = built.replies
    ln = built.frame("laser_on", 0)
    sends = [
        (ln, r.line(r.accepted(ln), "disarmed", True)),
        (corrupt_check(built.frame("laser_off", 0)), r.line(r.rejected("bad_check"), "disarmed", True)),
        (built.frame("laser_off", 0), r.line(r.accepted(ln[:1] + b"f"), "disarmed", False)),
        (built.frame("arm", 0)[:-1] + b"x", r.line(r.rejected("bad_check"), "disarmed", False)),
        (built.frame("servo_right", 10), r.line("Asr", "disarmed", False)),
        (built.frame("servo_right", 10)[:6], ""),  # a seed frame without its check is not a frame
    ]
    return [(30 * k, frame) for k, (frame, _) in enumerate(sends)], [line for _, line in sends if line]


def without_slides(built: fw.Built, lines: list[str]) -> list[str]:
    """The lines but the bad_category rejections that follow a bad check while the parser slides past the rest of
    the refused frame (answered once per kind of error)."""
    out: list[str] = []
    for line in lines:
        body = built.replies.body(line)
        if body == built.replies.rejected("bad_category"):
            assert out and built.replies.body(out[-1]) == built.replies.rejected("bad_check"), lines
            continue
        out.append(line)
    return out


def test_crc8_ready_line_and_checked_frames_in_the_virtual_drone(crc8: fw.Built) -> None:
    assert crc8.replies.ready().split("*")[0].endswith(" crc8")
    script = fw.Script().step(5)
    sends, expected = crc8_plan(crc8)
    for t, frame in sends:
        script.step(t + 5 - script.t_ms).send(frame)
    trace = script.step(60).run(binary=crc8.virtual_drone)
    assert trace.lines()[0] == crc8.replies.ready()
    assert without_slides(crc8, trace.lines(since_ms=5)) == expected
    assert trace.changes[-1]["pan"] == dp.SERVOS[dp.ServoName.PAN].default + 10
    assert trace.changes[-1]["laser"] is False


def test_crc8_in_simavr(crc8: fw.Built) -> None:
    sends, expected = crc8_plan(crc8)
    result = fw.simulate([(50.0 + t, frame) for t, frame in sends], 50.0 + sends[-1][0] + 40, elf=crc8.uno_elf)
    assert result.lines()[0] == crc8.replies.ready()
    assert without_slides(crc8, result.lines()[1:]) == expected
    assert result.laser_at(50.0 + sends[1][0] + 5) == 1 and result.laser_at(50.0 + sends[2][0] + 5) == 0
