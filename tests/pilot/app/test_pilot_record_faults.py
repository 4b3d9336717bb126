"""``--record`` is best effort and apart from the link: a full disk or an I/O error ends the recording with one
line, the flight goes on (or lands, with ``record_failure: stop``) and ends with its summary; the link's own
log is bounded and a failing log subscriber never reaches the link's caller."""

from __future__ import annotations

import errno
import io
from pathlib import Path
from typing import IO

import drone_protocol as dp
import numpy as np
import pytest
from cli_rig import call

from pilot.app import record
from pilot.app.record import Recorder, RecordingFailed
from pilot.app.runner import Tick
from pilot.control.controller import State
from pilot.link.serial_link import LOG_HISTORY, Link
from pilot.vision.detect import Detection
from pilot.vision.sources import Frame


class FullDisk(io.StringIO):
    """A log file whose disk fills after ``room`` writes."""

    def __init__(self, room: int) -> None:
        super().__init__()
        self.room = room

    def write(self, text: str) -> int:
        if self.room <= 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        self.room -= 1
        return super().write(text)


def _tick(i: int) -> Tick:
    frame = Frame(np.zeros((48, 64, 3), np.uint8), i * 0.05, i)
    return Tick(i, i * 0.05, frame, Detection(False, 0, 0, 0, 0.0), State.TRACK, dp.hold_altitude(), (),
                0.0, None)


def test_a_full_disk_ends_the_recording_with_one_line_and_raises_nothing(tmp_path: Path) -> None:
    lines: list[str] = []
    rec = Recorder(tmp_path, open_log=lambda _: FullDisk(3), warn=lines.append)
    for i in range(10):
        rec.on_tick(_tick(i))
        rec.write({"link": "tx", "data": "is0000"})
    rec.close()
    rec.close()
    assert lines == [f"pilot: recording stopped: {tmp_path / 'log.jsonl'}: No space left on device; the flight goes on"]
    assert rec.failed and rec.path_png is not None


def test_record_failure_land_stops_the_loop_at_its_next_tick(tmp_path: Path) -> None:
    lines: list[str] = []
    rec = Recorder(tmp_path, on_failure="stop", open_log=lambda _: FullDisk(1), warn=lines.append)
    rec.on_tick(_tick(0))
    rec.write({"x": 1})  # the disk is full
    with pytest.raises(RecordingFailed, match="the recording failed"):
        rec.on_tick(_tick(1))
    assert lines[0].endswith("; landing (record_failure: stop)")


def test_the_links_log_is_bounded_and_a_failing_subscriber_is_dropped(capfd: pytest.CaptureFixture[str]) -> None:
    def broken(entry: object) -> None:
        raise OSError(errno.EIO, "Input/output error")

    link = Link("loop://", wait_ready=False, log=broken)
    with link:
        for i in range(LOG_HISTORY + 50):
            link.send(dp.hold_altitude())
            if i % 50 == 0:
                link.poll()  # loop:// echoes the frames back: read them (logged as garbage)
    assert len(link.log) == LOG_HISTORY and link.log[-2].kind == "tx"  # the last: the link closing
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "log subscriber failed" in err and "the link goes on" in err


def test_the_summary_names_the_files_of_a_recording_or_says_why_it_ended(tmp_path: Path) -> None:
    video, log, picture = tmp_path / "flight.avi", tmp_path / "log.jsonl", str(tmp_path / "path.png")
    assert record.summary_lines(tmp_path, "", simulated=True, picture=picture) == [
        f"recording: {video}", f"log:       {log}", f"path:      {picture}"]
    assert record.summary_lines(tmp_path, "", simulated=False) == [f"recording: {video}", f"log:       {log}"]
    stopped = f"recording: stopped early ({log}: No space left on device); {video} and {log} end there"
    assert record.summary_lines(tmp_path, f"{log}: No space left on device", simulated=True) == [
        stopped, "path:      not drawn: the recording had stopped"]
    assert record.summary_lines(tmp_path, f"{log}: No space left on device", simulated=False) == [stopped]


def _full_after(writes: int) -> object:
    def opener(path: Path) -> IO[str]:
        return FullDisk(writes)

    return opener


@pytest.mark.parametrize(("writes", "policy"), [(2, "continue"), (700, "stop")])
def test_a_disk_full_mid_flight_still_lands_disarms_and_prints_the_summary(
    writes: int, policy: str, virtual_drone: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(record, "_open_log", _full_after(writes))
    config = tmp_path / "pilot.yaml"
    config.write_text(f"record_failure: {policy}\n")
    code, out, err = call("--virtual-drone", str(virtual_drone), "--scenario", "ahead", "--seed", "2", "--ideal",
                          "--record", str(tmp_path / "rec"), "--config", str(config), "--no-status",
                          "--max-seconds", "40")
    assert "Traceback" not in out + err
    assert err.count("pilot: recording stopped:") == 1, err
    assert "drone:     laser off, disarmed, altitude 0.00 m" in out, out + err
    assert out.startswith("ahead      seed   2 hsv "), out  # the flight's summary
    # what the recording holds, in words: never "path: None"
    rec = tmp_path / "rec"
    assert (f"recording: stopped early ({rec / 'log.jsonl'}: No space left on device); {rec / 'flight.avi'} and "
            f"{rec / 'log.jsonl'} end there\npath:      not drawn: the recording had stopped\n") in out, out
    assert "None" not in out, out
    if policy == "stop":  # landed early: the flight did not do its job
        assert code == 1 and "landing (record_failure: stop)" in err and "stopped by RecordingFailed" in err
    else:
        assert code == 0 and "SUCCESS" in out
