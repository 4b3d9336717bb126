"""The command line's small fixes: --record guard, flushed log, times from the start of the run, the laser
summary, outlined overlay text, one frame source, one image size, --version, the dialout hint."""

from __future__ import annotations

import errno
import io
import json
from contextlib import redirect_stdout
from pathlib import Path

import cv2
import drone_protocol as dp
import numpy as np
import pilot_synth as synth
import pytest
import serial
from cli_rig import call

from pilot.app.cli import main
from pilot.app.observers import LaserTally
from pilot.app.overlay import annotate
from pilot.app.record import LOG, Recorder
from pilot.app.runner import StatusLine, Tick
from pilot.control.controller import State
from pilot.vision.detect import Detection
from pilot.vision.sources import Frame

REPO = Path(__file__).resolve().parents[3]


def _folder(tmp_path: Path, sizes: list[tuple[int, int]]) -> Path:
    folder = tmp_path / "frames"
    folder.mkdir()
    for i, (w, h) in enumerate(sizes):
        cv2.imwrite(str(folder / f"{i:03d}.png"), synth.red_disc(synth.background(w, h), w // 2, h // 2, 12))
    return folder


def _tick(t: float, *, laser: bool = False, image: np.ndarray | None = None, index: int = 0) -> Tick:
    img = image if image is not None else np.zeros((120, 160, 3), np.uint8)
    return Tick(index, t, Frame(img, t, index), Detection(False, 0, 0, 0, 0.0), State.TRACK, dp.hold_altitude(), (),
                t, t, laser_on=laser)


def _one_line_usage_error(code: int, out: str, err: str, option: str) -> None:
    assert code == 2, out + err
    assert err.count("\n") == 1 and option in err and "Traceback" not in err, err


def test_record_refuses_an_existing_recording_unless_force(tmp_path: Path) -> None:
    folder = _folder(tmp_path, [(160, 120)] * 3)
    rec = tmp_path / "rec"
    code, out, err = call("--images", str(folder), "--record", str(rec), "--no-status")
    assert code in (0, 1), out + err
    first_log = (rec / LOG).read_text()
    assert first_log
    (rec / LOG).write_text("earlier flight\n")
    code, out, err = call("--images", str(folder), "--record", str(rec), "--no-status")
    _one_line_usage_error(code, out, err, "--record")
    assert "--force" in err and (rec / LOG).read_text() == "earlier flight\n"  # nothing overwritten
    code, out, err = call("--images", str(folder), "--record", str(rec), "--force", "--no-status")
    assert code in (0, 1) and "earlier flight" not in (rec / LOG).read_text()


def test_record_into_a_file_and_force_without_record_are_usage_errors(tmp_path: Path) -> None:
    folder = _folder(tmp_path, [(160, 120)])
    target = tmp_path / "a-file"
    target.write_text("keep me")
    _one_line_usage_error(*call("--images", str(folder), "--record", str(target)), "--record")
    assert target.read_text() == "keep me"
    _one_line_usage_error(*call("--images", str(folder), "--force"), "--force")


def test_log_is_flushed_per_line_and_times_count_from_the_start(tmp_path: Path) -> None:
    rec = Recorder(tmp_path / "rec")
    try:
        boot = 86_400.0  # a real run's monotonic clock: a day since the machine booted
        rec.on_tick(_tick(boot))
        rec.on_tick(_tick(boot + 0.05, index=1))
        lines = (tmp_path / "rec" / LOG).read_text().splitlines()  # read while the recorder is still open
        assert [json.loads(line)["t"] for line in lines] == [0.0, 0.05]
    finally:
        rec.close()


def test_status_line_counts_from_the_start_of_the_run() -> None:
    out = io.StringIO()
    status = StatusLine(out, live=False)
    status.on_tick(_tick(86_400.0))
    assert out.getvalue().startswith("t    0.00s")


def test_dry_run_log_times_start_near_zero(tmp_path: Path) -> None:
    folder = _folder(tmp_path, [(160, 120)] * 2)
    code, out, err = call("--images", str(folder), "--record", str(tmp_path / "rec"), "--no-status")
    assert code in (0, 1), out + err
    records = [json.loads(line) for line in (tmp_path / "rec" / LOG).read_text().splitlines()]
    times = [r["t"] for r in records if "t" in r]
    assert times and 0.0 <= min(times) < 1.0


def test_laser_summary_says_fired_when_it_was_lit() -> None:
    tally = LaserTally()
    for i in range(40):  # 20 Hz: lit from tick 5 to tick 27, 1.1 s
        tally.on_tick(_tick(100.0 + i * 0.05, laser=5 <= i < 27, index=i))
    assert tally.fired and tally.summary() == "laser fired: yes (lit 1.10 s)"
    never = LaserTally()
    never.on_tick(_tick(0.0))
    assert not never.fired and never.summary() == "laser fired: no (lit 0.00 s)"


@pytest.mark.parametrize("shade", [0, 255])
def test_overlay_text_is_outlined_and_readable_on_dark_and_bright_frames(shade: int) -> None:
    plain = np.full((240, 320, 3), shade, np.uint8)
    img = annotate(_tick(3.0, image=plain), 3.0, "mf1600")
    band = img[:30, :200].reshape(-1, 3).astype(int).sum(axis=1)
    assert (band > 600).sum() > 50 and (band < 100).sum() > 50  # light letters and a dark rim, whatever the frame


def test_only_one_frame_source(tmp_path: Path) -> None:
    folder = _folder(tmp_path, [(160, 120)])
    _one_line_usage_error(*call("--video", str(tmp_path / "v.avi"), "--images", str(folder)), "--video and --images")
    _one_line_usage_error(*call("--camera", "0", "--images", str(folder)), "--camera and --images")


def test_mixed_image_sizes_are_refused_before_anything_runs(tmp_path: Path) -> None:
    folder = _folder(tmp_path, [(160, 120), (160, 120), (320, 240)])
    rec = tmp_path / "rec"
    code, out, err = call("--images", str(folder), "--record", str(rec))
    _one_line_usage_error(code, out, err, "--images")
    assert "320x240" in err and "160x120" in err and "dry-run" not in out
    assert not (rec / LOG).exists() or (rec / LOG).read_text() == ""


def test_version_names_the_spec_fingerprint() -> None:
    out = io.StringIO()
    with redirect_stdout(out), pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0 and dp.SPEC_FINGERPRINT in out.getvalue() and out.getvalue().startswith("pilot ")


def test_permission_denied_on_the_port_hints_at_the_dialout_group(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def refuse(self: serial.Serial) -> None:
        raise serial.SerialException(errno.EACCES, f"could not open port {self.port}: [Errno 13] Permission denied")

    monkeypatch.setattr(serial.Serial, "open", refuse)
    folder = _folder(tmp_path, [(160, 120)])
    code, out, err = call("--port", "/dev/ttyACM7", "--arm", "--images", str(folder), "--no-status")
    _one_line_usage_error(code, out, err, "--port")
    assert "dialout" in err and "/dev/ttyACM7" in err


def test_license_is_the_mit_text_pyproject_names() -> None:
    text = (REPO / "LICENSE").read_text()
    assert text.startswith("MIT License") and 'license = "MIT"' in (REPO / "pyproject.toml").read_text()
