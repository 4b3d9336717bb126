"""The pulse schedule the Timer1 interrupt walks, checked on the host for both output modes."""

from __future__ import annotations

import itertools
import json
import subprocess
from typing import Any

import fwsupport as fw
import pytest

PWM_FRAME_US, PPM_FRAME_US, PPM_SEPARATOR_US = 20000, 22500, 300  # firmware/drone/pins.h
LINES = ["roll", "pitch", "throttle", "yaw", "mode", "pan", "tilt"]
PPM_LINE = 7
CASES = [
    [1500, 1500, 1521, 1524, 1165, 1472, 1472],
    [1000, 2000, 950, 2012, 1425, 544, 2400],  # extremes, failsafe throttle, servo ends
    [2000, 2000, 2012, 2012, 2000, 2400, 2400],  # the longest pulses still leave a gap
]


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


def run(mode: str, widths: list[int]) -> dict[str, Any]:
    out = subprocess.run(
        [str(fw.BUILD / "host" / "pulse_schedule_test"), mode, *map(str, widths)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    result: dict[str, Any] = json.loads(out)
    return result


@pytest.mark.parametrize("widths", CASES)
def test_parallel_schedule_gives_each_line_its_pulse_once_per_50hz_frame(widths: list[int]) -> None:
    result = run("parallel", widths)
    assert result["frame_us"] == PWM_FRAME_US
    for i, name in enumerate(LINES):
        line = result["lines"][i]
        assert line["highs"] == [widths[i]], name
        assert line["period_us"] == PWM_FRAME_US, name
    assert result["lines"][PPM_LINE]["highs"] == []


@pytest.mark.parametrize("widths", CASES)
def test_ppm_schedule_encodes_the_rc_channels_between_separator_edges(widths: list[int]) -> None:
    result = run("ppm", widths)
    assert result["frame_us"] == PPM_FRAME_US
    ppm = result["lines"][PPM_LINE]
    assert ppm["highs"] == [PPM_SEPARATOR_US] * 6
    rises = ppm["rises"]
    assert [b - a for a, b in itertools.pairwise(rises)] == widths[:5]
    assert PPM_FRAME_US - rises[-1] >= 3000  # a sync gap the receiver can find
    for i in (5, 6):  # servos stay parallel, sent inside the sync gap
        assert result["lines"][i]["highs"] == [widths[i]]
        assert result["lines"][i]["period_us"] == PPM_FRAME_US
    for i in range(5):
        assert result["lines"][i]["highs"] == []
