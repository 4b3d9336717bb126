"""The firmware's build refuses what its hardware cannot do, whatever the library says: a baud rate the 16 MHz UART
cannot make within 5 % (4000000 baud built and ran at 2000000), and a servo range past the full scale (a library
generated without the generator's check would pulse past SERVO_MAX_US)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import fwsupport as fw
import yaml

from generator.cli import main as generate

ARDUINO_AVR = Path("/usr/share/arduino/hardware/arduino/avr")
FLAGS = ("-std=gnu++11", "-mmcu=atmega328p", "-DF_CPU=16000000L", "-DARDUINO=10819", "-Os", "-Wall", "-Wextra",
         "-Werror", f"-I{ARDUINO_AVR / 'cores' / 'arduino'}", f"-I{ARDUINO_AVR / 'variants' / 'standard'}",
         f"-I{fw.ROOT / 'firmware' / 'drone'}")


def compile_with(library: Path, source: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["avr-g++", *FLAGS, f"-I{library}", "-c", str(fw.ROOT / "firmware" / "drone" / source),
                           "-o", "/dev/null"], capture_output=True, text=True, timeout=120)


def test_a_baud_rate_the_uart_cannot_make_stops_the_build(tmp_path: Path) -> None:
    spec = fw.spec_copy()
    spec["link"]["baud"] = 4_000_000
    (tmp_path / "drone.yaml").write_text(yaml.safe_dump(spec, sort_keys=False, allow_unicode=True))
    assert generate(["--spec", str(tmp_path / "drone.yaml"), "--out", str(tmp_path / "out")]) == 0
    refused = compile_with(tmp_path / "out" / "arduino" / "DroneProtocol" / "src", "serial_avr.cpp")
    assert refused.returncode != 0 and "cannot make the spec's baud rate within 5 %" in refused.stderr
    shipped = compile_with(fw.ROOT / "generated" / "arduino" / "DroneProtocol" / "src", "serial_avr.cpp")
    assert shipped.returncode == 0, shipped.stderr


def test_a_library_with_a_servo_range_past_the_full_scale_stops_the_build(tmp_path: Path) -> None:
    library = tmp_path / "src"
    shutil.copytree(fw.ROOT / "generated" / "arduino" / "DroneProtocol" / "src", library)
    header = library / "DroneProtocol_spec.h"
    text = header.read_text()
    assert text.count("SERVO_PAN_MAX = 180;") == 1
    header.write_text(text.replace("SERVO_PAN_MAX = 180;", "SERVO_PAN_MAX = 200;"))
    refused = compile_with(library, "drone_app.cpp")
    assert refused.returncode != 0 and "a servo range past the full scale" in refused.stderr
