"""`make upload`: the avrdude command each board's bootloader needs, composed without a board (a fake avrdude on
PATH records its arguments), and one clear line, exit 2, for a missing port or an unknown board."""

from __future__ import annotations

import json
import os
import stat
import subprocess
from collections.abc import Iterator
from pathlib import Path

import fwsupport as fw
import pytest

# Optiboot (Uno) speaks the arduino protocol at 115200; the Mega 2560's stk500v2 bootloader is "wiring".
EXPECTED = {
    "uno": ["-p", "m328p", "-c", "arduino", "-b", "115200", "-D"],
    "uno_ppm": ["-p", "m328p", "-c", "arduino", "-b", "115200", "-D"],
    "mega": ["-p", "m2560", "-c", "wiring", "-b", "115200", "-D"],
}


@pytest.fixture
def fake_avrdude(tmp_path: Path) -> Path:
    """A bin folder whose avrdude appends its arguments, as JSON, to calls.jsonl (exit status from FAKE_EXIT)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    script = bin_dir / "avrdude"
    script.write_text("#!/usr/bin/env python3\nimport json, os, sys\n"
                      f"with open({str(tmp_path / 'calls.jsonl')!r}, 'a') as f:\n"
                      "    f.write(json.dumps(sys.argv[1:]) + '\\n')\n"
                      "sys.exit(int(os.environ.get('FAKE_EXIT', '0')))\n", encoding="utf-8")
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    return bin_dir


@pytest.fixture
def port() -> Iterator[str]:
    """A real serial-like device node: the slave side of a pseudo-terminal."""
    leader, follower = os.openpty()
    try:
        yield os.ttyname(follower)
    finally:
        os.close(leader)
        os.close(follower)


def make_upload(bin_dir: Path, *variables: str, fake_exit: int = 0) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}", "FAKE_EXIT": str(fake_exit)}
    return subprocess.run(["make", "-s", "--no-print-directory", "-C", str(fw.ROOT), "upload", *variables],
                          capture_output=True, text=True, env=env, timeout=300, check=False)


def calls(bin_dir: Path) -> list[list[str]]:
    log = bin_dir.parent / "calls.jsonl"
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []


@pytest.mark.parametrize("board", sorted(EXPECTED))
def test_upload_runs_avrdude_with_the_bootloaders_programmer_and_baud(fake_avrdude: Path, port: str,
                                                                     board: str) -> None:
    run = make_upload(fake_avrdude, f"PORT={port}", f"BOARD={board}")
    assert run.returncode == 0, run.stderr
    hex_file = f"firmware/build/{board}/{board}.hex"
    assert calls(fake_avrdude) == [[*EXPECTED[board], "-P", port, "-U", f"flash:w:{hex_file}:i"]]
    assert (fw.ROOT / hex_file).stat().st_size > 0
    assert f"Flashing {hex_file} (BOARD={board}) to {port}" in run.stdout  # says what it does first
    assert f"avrdude {' '.join(EXPECTED[board])} -P {port}" in run.stdout


def test_dry_run_prints_the_command_and_runs_nothing(fake_avrdude: Path, port: str) -> None:
    run = make_upload(fake_avrdude, f"PORT={port}", "BOARD=mega", "DRY_RUN=1")
    assert run.returncode == 0, run.stderr
    assert "avrdude -p m2560 -c wiring" in run.stdout and "DRY_RUN" in run.stdout
    assert calls(fake_avrdude) == []


def test_a_failing_avrdude_fails_the_upload(fake_avrdude: Path, port: str) -> None:
    assert make_upload(fake_avrdude, f"PORT={port}", "BOARD=uno", fake_exit=1).returncode != 0


@pytest.mark.parametrize(("variables", "message"), [
    ((), "PORT is not set: make upload PORT=/dev/ttyACM0 BOARD=uno"),
    (("PORT=/dev/ttyACM_missing_board",), "PORT=/dev/ttyACM_missing_board does not exist: is the board plugged in?"),
    (("PORT=/dev/null", "BOARD=leonardo"), "BOARD=leonardo is not a board we build: use BOARD=uno, BOARD=mega or "
                                           "BOARD=uno_ppm"),
])
def test_bad_port_or_board_is_one_line_and_exit_2(fake_avrdude: Path, variables: tuple[str, ...],
                                                  message: str) -> None:
    run = make_upload(fake_avrdude, *variables)
    assert run.returncode == 2
    assert len(run.stderr.splitlines()) == 1 and message in run.stderr, run.stderr
    assert run.stdout == ""
    assert calls(fake_avrdude) == []
