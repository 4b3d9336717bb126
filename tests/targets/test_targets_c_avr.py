"""The C99 codec on the ATmega328P (avr-gcc -Os), for the shipped spec and its crc8 variant: a program that encodes
and decodes one frame holds at most 64 B of static RAM (the tables and names live in flash) and, run in simavr,
sends the frame and what it decoded; a tour of the whole API (tests/targets/avr/api_tour.c) prints in simavr what
its host build prints, names read from flash through the _P functions included; the AVR example of the C
codec's README runs in simavr within the same budget."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest
import targets_harness as t
import test_targets_integrity as integrity

RAM_BUDGET = 64  # bytes of .data + .bss for the minimal program
PROGRAMS = Path(__file__).resolve().parent / "avr"
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")
AVR_GCC = ("avr-gcc", *STRICT, "-Os", "-mmcu=atmega328p", f"-I{PROGRAMS}")
# What the Arduino IDE and most AVR makefiles add; the budget holds with and without.
GC_SECTIONS = ("-ffunction-sections", "-fdata-sections", "-Wl,--gc-sections")
SIM = t.ROOT / "firmware" / "build" / "sim" / "drone_sim"


def avr_build(tree: Path, program: str, out: Path, *flags: str) -> Path:
    t.run([*AVR_GCC, f"-I{tree / 'c'}", *flags, str(PROGRAMS / program), str(tree / "c" / "drone_protocol.c"),
           "-o", str(out)])
    return out


def static_ram(elf: Path) -> int:
    """.data + .bss, as avr-size reports them."""
    sections = {}
    for line in t.run(["avr-size", "-A", str(elf)]).splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0] in (".data", ".bss"):
            sections[parts[0]] = int(parts[1])
    assert ".data" in sections or ".bss" in sections, f"avr-size printed no .data or .bss for {elf}"
    return sum(sections.values())


def simulated_output(elf: Path, until_ms: float) -> str:
    """Everything the program sent over the UART in `until_ms` simulated milliseconds (the project's simavr bench)."""
    t.run(["make", "-s", "-C", str(t.ROOT), "firmware-sim"])
    proc = subprocess.run([str(SIM), "--elf", str(elf), "--until", str(until_ms)], input="", capture_output=True,
                          text=True, timeout=120, check=True)
    records = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    assert records and records[-1]["ev"] == "end", proc.stdout + proc.stderr
    return "".join(r["text"] for r in records if r["ev"] == "tx")


def tree_of(spec: str) -> Path:
    return integrity.crc8_tree() if spec == "crc8" else t.GENERATED


@pytest.mark.parametrize("spec", ["shipped", "crc8"])
@pytest.mark.parametrize("flags", [(), GC_SECTIONS], ids=["plain", "gc-sections"])
def test_a_program_that_encodes_and_decodes_a_frame_holds_at_most_64_bytes_of_ram(
    spec: str, flags: tuple[str, ...], tmp_path: Path
) -> None:
    tree = tree_of(spec)
    vector = [v for v in json.loads((tree / "vectors.json").read_text(encoding="utf-8"))["vectors"] if v["ok"]][-1]
    command = f"-DCOMMAND=DP_CMD_{vector['command'].upper()}"
    elf = avr_build(tree, "minimal.c", tmp_path / "minimal.elf", command, f"-DVALUE={vector['value']}u", *flags)
    ram = static_ram(elf)
    assert ram <= RAM_BUDGET, f"{ram} B of static RAM"
    # the frame, no error encoding, none decoding, the same command back and its value
    assert simulated_output(elf, 5) == f"{bytes.fromhex(vector['frame_hex']).decode()} 0 0 1 {vector['value']}\n"


@pytest.mark.parametrize("spec", ["shipped", "crc8"])
def test_the_api_in_simavr_says_what_it_says_on_the_host(spec: str, tmp_path: Path) -> None:
    tree = tree_of(spec)
    vectors = json.loads((tree / "vectors.json").read_text(encoding="utf-8"))["vectors"]
    host = tmp_path / "api_tour"
    t.run(["gcc", *STRICT, "-O1", f"-I{PROGRAMS}", f"-I{tree / 'c'}",
           str(PROGRAMS / "api_tour.c"), str(tree / "c" / "drone_protocol.c"), "-o", str(host)])
    expected = t.run([str(host)])
    lines = expected.splitlines()
    commands = {v["command"] for v in vectors if v["ok"]}
    # a line for every command and one past the last; the stream parser found every command's frame
    assert sum(line.startswith("command ") for line in lines) == len(commands) + 1 and lines[-1] == "end"
    assert sum(line.startswith("found ") for line in lines) == len(commands)
    elf = avr_build(tree, "api_tour.c", tmp_path / "api_tour.elf", *GC_SECTIONS)
    assert simulated_output(elf, 150) == expected


def test_the_readmes_avr_example_runs_in_simavr_within_the_budget(tmp_path: Path) -> None:
    (code,) = re.findall(r"^```c avr\n(.*?)^```$", (t.C_DIR / "README.md").read_text(encoding="utf-8"), re.M | re.S)
    source = tmp_path / "example.c"
    includes = "".join(f"#include {h}\n" for h in ("<assert.h>", "<string.h>", "<avr/pgmspace.h>", '"drone_protocol.h"',
                                                    '"out.h"'))
    source.write_text(includes + "int main(void) {\n  out_init();\n  {\n" + code + '  }\n  out_text("ok\\n");\n'
                      "  for (;;) {\n  }\n}\n", encoding="utf-8")
    elf = tmp_path / "example.elf"
    t.run([*AVR_GCC, f"-I{t.C_DIR}", *GC_SECTIONS, str(source), str(t.C_DIR / "drone_protocol.c"), "-o", str(elf)])
    assert static_ram(elf) <= RAM_BUDGET
    assert simulated_output(elf, 5) == "ok\n"  # a failed assert() aborts before
