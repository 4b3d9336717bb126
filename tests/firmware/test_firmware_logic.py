"""The output clamp behind the parser: handlers given values beyond Table 4 still drive legal pulses."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import drone_protocol as dp
import fwsupport as fw


def test_outputs_are_clamped_to_the_recorded_extremes_even_past_the_parser(tmp_path: Path) -> None:
    exe = tmp_path / "logic_probe"
    subprocess.run(
        [
            "g++", "-std=c++11", "-g", "-Wall", "-Wextra", "-Werror",
            "-fsanitize=address,undefined", "-fno-sanitize-recover=all",
            f"-I{fw.ROOT / 'firmware' / 'drone'}",
            f"-I{fw.ROOT / 'generated' / 'arduino' / 'DroneProtocol' / 'src'}",
            str(Path(__file__).with_name("logic_probe.cpp")),
            str(fw.ROOT / "firmware" / "drone" / "drone_logic.cpp"),
            str(fw.ROOT / "firmware" / "drone" / "drone_handlers.cpp"),
            "-o", str(exe),
        ],
        check=True,
    )  # fmt: skip
    out = json.loads(subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout)
    assert out["armed"] is True
    for case, (channel, end) in {
        "pitch_high": ("pitch", "maximum"),
        "pitch_low": ("pitch", "minimum"),
        "roll_high": ("roll", "maximum"),
        "roll_low": ("roll", "minimum"),
        "throttle_high": ("throttle", "maximum"),
        "throttle_low": ("throttle", "minimum"),
        "yaw_high": ("yaw", "maximum"),
        "yaw_low": ("yaw", "minimum"),
    }.items():
        limits = dp.CHANNELS[channel]
        assert out[case][channel] == getattr(limits, end), case
        others = {k: v for k, v in out[case].items() if k != channel}
        assert others == {k: v for k, v in fw.neutral().items() if k != channel}, case
    pan, tilt = dp.SERVOS[dp.ServoName.PAN], dp.SERVOS[dp.ServoName.TILT]
    assert out["servo_far"] == {"pan": pan.maximum, "tilt": tilt.minimum}
