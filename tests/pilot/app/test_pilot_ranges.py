"""Every option that feeds a safety path or a time limit is range-checked at start-up: one test per option,
each a value outside its range (NaN and infinity included), through the real command line: exit 2, one line
naming the option, nothing flown."""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import pytest
import yaml

from pilot.app.cli import main
from pilot.common.config import RANGES, PilotConfig, from_dict, to_dict


def call(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def _bad_values(path: str) -> list[object]:
    low, high = RANGES[path]
    default = to_dict(PilotConfig())
    for part in path.split("."):
        default = default[part]
    if isinstance(default, int):
        return [int(low) - 1, int(high) + 1]
    return [math.nan, math.inf, low - 1.0, high + 1.0]


@pytest.mark.parametrize("path", sorted(RANGES))
def test_config_option_out_of_range_is_refused_naming_it(path: str, tmp_path: Path) -> None:
    section, option = path.split(".")
    for value in _bad_values(path):
        cfg = tmp_path / "pilot.yaml"
        cfg.write_text(yaml.safe_dump({section: {option: value}}))
        code, out, err = call("--config", str(cfg), "--dry-run", "--no-status")
        assert code == 2, (value, err)
        assert err.count("\n") == 1 and path in err and str(cfg) in err, err
        assert "Traceback" not in err and out == ""


def test_land_time_must_fit_the_firmware_landing_and_disarm() -> None:
    import drone_protocol as dp

    for value in (-5, 0, dp.LANDING_MS + dp.ARMING_HOLD_MS - 1):
        with pytest.raises(ValueError, match=r"controller\.land_ms"):
            from_dict({"controller": {"land_ms": value}})
    from_dict({"controller": {"land_ms": dp.LANDING_MS + dp.ARMING_HOLD_MS}})  # the least that fits


@pytest.mark.parametrize(
    "argv,option",
    [
        (["--max-seconds", "nan"], "--max-seconds"),
        (["--max-seconds", "inf"], "--max-seconds"),
        (["--max-seconds", "0"], "--max-seconds"),
        (["--max-seconds", "-1"], "--max-seconds"),
        (["--wind", "nan"], "--wind"),
        (["--wind", "-1"], "--wind"),
        (["--baud", "0"], "--baud"),
        (["--readout-ms", "nan"], "--readout-ms"),
        (["--readout-ms", "-5"], "--readout-ms"),
        (["--seed", "-1"], "--seed"),  # raised numpy's ValueError from inside the simulator
        (["--size", "100000x100000"], "--size"),
        (["--size", "4097x240"], "--size"),
        (["--size", "16x16"], "--size"),
        (["--size", "axb"], "--size"),
    ],
)
def test_command_line_option_out_of_range_is_refused_naming_it(argv: list[str], option: str) -> None:
    code, out, err = call(*argv, "--no-status")
    assert code == 2, err
    assert err.count("\n") == 1 and option in err and "Traceback" not in err and out == ""


def test_the_largest_frame_size_is_accepted() -> None:
    from pilot.app.cli import _size

    assert _size("4096x4096") == (4096, 4096)
