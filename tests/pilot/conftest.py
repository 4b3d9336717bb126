"""Fixtures of the pilot tests: the real virtual drone, built from the firmware sources for this run, and a frozen
clock for the detectors' per-frame budget (``vision.budget_ms``): it never runs out in these tests unless a test
gives a detector a clock of its own (test_pilot_budget.py), so a loaded machine cannot change what a detector
sees, nor therefore the path of a flight that a test judges."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

import pilot.vision.budget as budget

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def frozen_budget_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(budget, "CLOCK", lambda: 0.0)


@pytest.fixture(scope="session")
def virtual_drone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The firmware's host build (``make firmware-host``) in a directory of this test run, so that no
    other build in the work tree can change or remove it underneath the tests. ``PILOT_VIRTUAL_DRONE``
    names a prebuilt one instead."""
    prebuilt = os.environ.get("PILOT_VIRTUAL_DRONE")
    if prebuilt:
        path = Path(prebuilt)
        assert path.is_file(), f"PILOT_VIRTUAL_DRONE={prebuilt} does not exist"
        return path
    build = tmp_path_factory.mktemp("firmware-build")
    proc = subprocess.run(
        ["make", "-s", "firmware-host", f"FW_BUILD={build}"],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, f"make firmware-host failed:\n{proc.stdout}\n{proc.stderr}"
    exe = build / "host" / "virtual_drone"
    assert exe.is_file(), f"make firmware-host did not produce {exe}"
    return exe
