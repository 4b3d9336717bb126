"""Command indexes scale past 255: a synthetic spec of 26 categories x 26 directions (676 commands) generates,
its C++ compiles for the ATmega328P with -Wall -Wextra -Werror (parser, dispatch to category handlers and to the
`unsupported` fallback, replies), and the host build decodes every one of its conformance vectors as the vectors
say (tests/generator/cpp/protocol_driver.cpp). Its C99 codec passes the C tests, and on the ATmega328P encodes and
decodes its last command (index 675) in simavr with its tables in flash (tests/targets/avr/minimal.c).
"""

from __future__ import annotations

import json
import string
import subprocess
import sys
from pathlib import Path
from typing import Any

import fwsupport as fw
import pytest
import yaml

AVR_FLAGS = ["-mmcu=atmega328p", "-Os", "-std=gnu++11", "-DF_CPU=16000000L", "-fno-exceptions",
             "-fno-threadsafe-statics", "-ffunction-sections", "-fdata-sections", "-flto", "-Wall", "-Wextra",
             "-Werror", "-Wl,--gc-sections"]
# Category codes: the shipped ones keep theirs, 21 more letters; every category gets the 26 letters as directions.
NEW_CODES = [c for c in string.ascii_lowercase if c not in "mtsli"]


def synthetic_spec() -> dict[str, Any]:
    data = fw.spec_copy()
    cats = data["categories"]
    for code in NEW_CODES:
        cats[code] = {"name": f"group_{code}", "hardware": "Bench", "description": f"Synthetic category {code}.",
                      "field": "speed", "directions": {}}
    for code, cat in cats.items():
        dirs = cat["directions"]
        keep = {d: dirs[d] for d in dirs if d in string.ascii_lowercase}
        for d in string.ascii_lowercase:
            if d in keep:
                continue
            if code in "mt":
                keep[d] = {"name": f"extra_{d}", "description": f"Extra {d}", "channel": "pitch", "default": "high"}
            elif code == "s":
                keep[d] = {"name": f"extra_{d}", "description": f"Extra {d}", "servo": "pan", "sense": 1}
            elif code in "li":
                keep[d] = {"name": f"extra_{d}", "description": f"Extra {d}"}
            else:
                keep[d] = {"name": f"d_{d}", "description": f"Direction {d}", "channel": "roll", "default": "low"}
        cat["directions"] = keep
    return data


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("many")
    spec = tmp / "drone.yaml"
    spec.write_text(yaml.safe_dump(synthetic_spec(), sort_keys=False), encoding="utf-8")
    out = tmp / "generated"
    result = subprocess.run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out)], cwd=fw.ROOT,
                            capture_output=True, text=True, check=False, env=fw.python_env())
    assert result.returncode == 0, result.stderr
    return out


def test_676_commands_use_16_bit_indexes(generated: Path) -> None:
    vectors = json.loads((generated / "vectors.json").read_text())["vectors"]
    assert len({v["command"] for v in vectors if v["ok"]}) == 26 * 26
    spec_h = (generated / "arduino" / "DroneProtocol" / "src" / "DroneProtocol_spec.h").read_text()
    assert "typedef uint16_t CommandIndex;" in spec_h and "COMMAND_COUNT = 676;" in spec_h


def test_the_676_command_header_compiles_for_the_avr_with_werror(generated: Path, tmp_path: Path) -> None:
    src = tmp_path / "sketch.cpp"
    src.write_text(
        "#include <avr/io.h>\n#include <DroneProtocol.h>\n"
        "namespace dp = drone_protocol;\n"
        "struct Handlers {\n"
        "  void on_move(const dp::Command& c) { OCR1A = c.value; }\n"
        "  void on_group_z(const dp::Command& c) { OCR1B = c.value; }\n"
        "};\n"
        "static dp::StreamParser parser;\nstatic Handlers handlers;\n"
        "int main() {\n  uint32_t now = 0;\n  char line[dp::REPLY_MAX_LENGTH];\n  for (;;) {\n"
        "    if (parser.feed(UDR0, ++now)) {\n"
        "      const dp::Error e = dp::dispatch(parser.command(), handlers);\n"
        "      const uint8_t n = e == dp::Error::None ? dp::write_accepted(parser.command(), dp::State::Armed, false,"
        " line) : dp::write_rejected(e, dp::State::Armed, false, line);\n"
        "      for (uint8_t i = 0; i < n; ++i) UDR0 = static_cast<uint8_t>(line[i]);\n"
        "    }\n  }\n}\n",
        encoding="utf-8")
    elf = tmp_path / "sketch.elf"
    include = generated / "arduino" / "DroneProtocol" / "src"
    result = subprocess.run(["avr-g++", *AVR_FLAGS, f"-I{include}", str(src), "-o", str(elf)], capture_output=True,
                            text=True, check=False)
    assert result.returncode == 0, result.stderr
    assert elf.stat().st_size > 0


def test_the_676_command_host_build_decodes_every_vector(generated: Path, tmp_path: Path) -> None:
    include = generated / "arduino" / "DroneProtocol" / "src"
    exe = tmp_path / "driver"
    driver = fw.ROOT / "tests" / "generator" / "cpp" / "protocol_driver.cpp"
    result = subprocess.run(["g++", "-std=c++11", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{include}", str(driver),
                             "-o", str(exe)], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    vectors = json.loads((generated / "vectors.json").read_text())["vectors"]
    run = subprocess.run([str(exe), "decode"], input="".join(v["frame_hex"] + "\n" for v in vectors),
                         capture_output=True, text=True, check=True)
    lines = run.stdout.splitlines()
    assert len(lines) == len(vectors)
    for v, line in zip(vectors, lines, strict=True):
        expected = (f"ok {v['command']} {ord(v['category'])} {ord(v['direction'])} {v['value']}" if v["ok"]
                    else f"err {v['error']}")
        assert line == expected, v


def test_the_676_command_c99_codec_passes_the_c_tests(generated: Path, tmp_path: Path) -> None:
    c_dir, exe = generated / "c", tmp_path / "test_c_codec"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1",
                    "-fsanitize=address,undefined", f"-I{c_dir}", str(fw.ROOT / "tests" / "targets" / "c" /
                    "test_c_codec.c"), str(c_dir / "drone_protocol.c"), "-o", str(exe)], check=True, timeout=120)
    run = subprocess.run([str(exe), str(generated / "vectors.json")], capture_output=True, text=True, check=False)
    assert run.returncode == 0 and "3551 vectors" in run.stdout, run.stdout + run.stderr


def test_the_676_command_c99_codec_on_the_avr_keeps_its_tables_in_flash(generated: Path, tmp_path: Path) -> None:
    vector = [v for v in json.loads((generated / "vectors.json").read_text())["vectors"] if v["ok"]][-1]
    assert vector["command"] == "group_z_d_z"  # the last of the 676
    elf, programs = tmp_path / "minimal.elf", fw.ROOT / "tests" / "targets" / "avr"
    # -Wl,--gc-sections as the Arduino IDE builds: the whole codec of 676 commands is more than the Uno's flash
    subprocess.run(["avr-gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Os", "-mmcu=atmega328p",
                    "-ffunction-sections", "-fdata-sections", "-Wl,--gc-sections",
                    f"-I{programs}", f"-I{generated / 'c'}", f"-DCOMMAND=DP_CMD_{vector['command'].upper()}",
                    f"-DVALUE={vector['value']}u", str(programs / "minimal.c"),
                    str(generated / "c" / "drone_protocol.c"), "-o", str(elf)], check=True, timeout=120)
    size = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True, check=True).stdout
    ram = sum(int(line.split()[1]) for line in size.splitlines() if line.split()[:1] in ([".data"], [".bss"]))
    assert ram <= 64, f"{ram} B of static RAM"
    fw.make("firmware-sim")
    assert fw.simulate([], 5, elf).lines() == [f"{vector['frame']} 0 0 1 {vector['value']}"]
