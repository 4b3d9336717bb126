"""``python -m pilot``: the simulated flight, --record, --dry-run, --calibrate, the --arm guard and
config errors."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from contextlib import redirect_stdout
from pathlib import Path

import cv2
import drone_protocol as dp
import numpy as np
import pilot_synth as synth
import pytest
import yaml
from cli_rig import call

from pilot.app.cli import main

REPO = Path(__file__).resolve().parents[3]


def test_sim_flight_with_record(virtual_drone: Path, tmp_path: Path) -> None:
    rec = tmp_path / "rec"
    code, out, err = call(
        "--virtual-drone", str(virtual_drone), "--scenario", "side", "--seed", "5", "--record", str(rec), "--no-status",
        "--ideal",  # the recording's plumbing, not the pilot's flying in the randomised world
    )
    assert code == 0, out + err
    assert "SUCCESS" in out
    assert f"recording: {rec / 'flight.avi'}" in out and f"path:      {rec / 'path.png'}" in out
    assert (rec / "flight.avi").stat().st_size > 0 and (rec / "path.png").stat().st_size > 0
    commands = [json.loads(line).get("command") for line in (rec / "log.jsonl").read_text().splitlines()]
    sent = [c for c in commands if c]
    assert sent and all(dp.encode(*_parts(c)) == c.encode() for c in sent)


def _parts(frame: str) -> tuple[str, str, int]:
    cmd = dp.decode(frame.encode())
    return cmd.category.value, cmd.direction.value, cmd.value or 0


def test_status_line_shows_state_target_and_rate(virtual_drone: Path) -> None:
    code, _out, err = call("--virtual-drone", str(virtual_drone), "--scenario", "ahead", "--seed", "2", "--ideal")
    assert code == 0
    lines = [line for line in err.splitlines() if line.startswith("t ")]
    states = [line.split("state")[1].split()[0] for line in lines]
    assert states[0] == "arm" and "fire" in states and states[-1] == "done"
    assert any("target yes" in line for line in lines)
    rates = [int(line.split("cmd/s")[0].split()[-1]) for line in lines if "state track" in line]
    assert rates and all(15 <= r <= 21 for r in rates)  # the steady 20 Hz


def test_time_limit_is_a_failure_exit(virtual_drone: Path) -> None:
    code, out, _ = call("--virtual-drone", str(virtual_drone), "--max-seconds", "4", "--no-status")
    assert code == 1 and "time limit (4 s)" in out


def test_real_port_needs_arm() -> None:
    code, _out, err = call("--port", "loop://", "--video", "nothing.avi")
    assert code == 2
    assert "needs --arm" in err


def test_dry_run_prints_only_generated_frames(tmp_path: Path) -> None:
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(8):
        cv2.imwrite(str(folder / f"{i:03d}.png"), synth.red_disc(synth.background(320, 240), 200, 120, 30))
    code, out, _err = call("--images", str(folder), "--no-status")
    assert code == 1  # the frames ran out before the mission could end
    printed = [line.split()[1] for line in out.splitlines() if line.startswith("dry-run ")]
    assert printed[0] == dp.arm().decode()
    for frame in printed:
        dp.decode(frame.encode())  # every printed frame is a valid generated frame
    # no drone answers a dry run, so nothing is confirmed: the landing routine once, never the laser toggle
    assert printed[-1] == dp.land().decode() and printed.count(dp.land().decode()) == 1
    assert dp.laser_toggle().decode() not in printed
    assert "nothing confirmed" in out
    assert "end of frames" in out


def test_calibrate_writes_config(tmp_path: Path) -> None:
    img = synth.background(320, 240)
    cv2.circle(img, (160, 120), 40, (40, 160, 40), -1)  # a green target
    sample = tmp_path / "sample.png"
    cv2.imwrite(str(sample), img)
    cfg = tmp_path / "pilot.yaml"
    code, _out, err = call("--calibrate", str(sample), "--config", str(cfg))
    assert code == 0, err
    data = yaml.safe_load(cfg.read_text())
    ((lo, hi),) = data["hsv"]["ranges"]
    hue = int(cv2.cvtColor(np.array([[[40, 160, 40]]], np.uint8), cv2.COLOR_BGR2HSV)[0, 0, 0])
    assert lo[0] <= hue <= hi[0]
    code, _, err = call("--calibrate", str(sample))
    assert code == 2 and "--config" in err


def test_config_error_names_the_option(tmp_path: Path) -> None:
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("controller:\n  acquire_frames: many\n")
    code, _out, err = call("--config", str(cfg))
    assert code == 2
    assert "controller.acquire_frames" in err and str(cfg) in err


def test_missing_virtual_drone_is_explained(tmp_path: Path) -> None:
    code, _, err = call("--virtual-drone", str(tmp_path / "none"), "--no-status")
    assert code == 2 and "make firmware-host" in err


def test_python_dash_m_pilot_flies_the_demos_flight(virtual_drone: Path) -> None:
    """The flight `make demo` promises a newcomer (pilot/pilot.mk's DEMO_FLIGHT_ARGS), through `python -m pilot`."""
    line = next(x for x in (REPO / "pilot" / "pilot.mk").read_text().splitlines() if x.startswith("DEMO_FLIGHT_ARGS"))
    demo = line.split("?=", 1)[1].split()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), str(REPO / "generated" / "python")]))
    proc = subprocess.run(
        [sys.executable, "-m", "pilot", "--virtual-drone", str(virtual_drone), *demo],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "SUCCESS" in proc.stdout


def test_help_lists_the_options() -> None:
    out = io.StringIO()
    with redirect_stdout(out), pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    for option in ("--sim", "--port", "--baud", "--camera", "--video", "--detector", "--config", "--dry-run",
                   "--record", "--seed", "--max-seconds", "--arm", "--images", "--calibrate"):
        assert option in out.getvalue(), option
    assert str(dp.BAUD) in out.getvalue()  # the default baud rate comes from the spec


def test_fingerprint_mismatch_refused_before_anything_is_sent(tmp_path: Path) -> None:
    import select
    import tty

    folder = tmp_path / "frames"
    folder.mkdir()
    cv2.imwrite(str(folder / "0.png"), synth.background(320, 240))
    master, slave = os.openpty()
    tty.setraw(slave)
    try:
        other = "0" * len(dp.SPEC_FINGERPRINT) if dp.SPEC_FINGERPRINT != "0" * 16 else "1" * 16
        os.write(master, dp.ready_line().replace(dp.SPEC_FINGERPRINT.encode(), other.encode()))
        code, _out, err = call("--port", os.ttyname(slave), "--arm", "--images", str(folder), "--no-status")
        assert code == 2
        assert "spec fingerprint mismatch" in err and other in err and "refusing to fly" in err
        assert not select.select([master], [], [], 0.2)[0]  # not a byte went to the drone
    finally:
        os.close(master)
        os.close(slave)


def test_record_of_a_dry_run_on_frames(tmp_path: Path) -> None:
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(5):
        cv2.imwrite(str(folder / f"{i}.png"), synth.red_disc(synth.background(320, 240), 100 + 10 * i, 120, 20))
    rec = tmp_path / "rec"
    code, out, _err = call("--images", str(folder), "--record", str(rec), "--no-status")
    assert code == 1 and f"recording: {rec / 'flight.avi'}" in out
    lines = [json.loads(line) for line in (rec / "log.jsonl").read_text().splitlines()]
    ticks = [d for d in lines if "tick" in d]
    assert len(ticks) == 5
    assert [round(d["detection"]["cx"]) for d in ticks] == [100, 110, 120, 130, 140]
    assert "no path picture" in lines[-1]["result"]["note"]
    assert not (rec / "path.png").exists()
    cap = cv2.VideoCapture(str(rec / "flight.avi"))
    assert int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) == 5
    cap.release()
