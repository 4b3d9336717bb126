"""Protocol benchmarks (issue 2, "Measure"): every figure against a baseline measured in the same run.

    python -m bench.protocol.run [--quick] [--build DIR] [--results FILE | --no-write] [--only SECTION ...]

Sections: ``python`` (the generated codec against bare f-string and slice-and-int code), ``host`` (the C++
StreamParser and dispatch against a fixed 6-byte atoi loop, timed and counted by callgrind) and ``avr`` (the
parser's flash and RAM on the ATmega328P). Writes the table, the environment and how each figure is measured
(METHOD below) to bench/protocol/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import drone_protocol as dp

from bench.protocol.python_codec import bench_python
from bench.protocol.rows import Row, Settings

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
ARDUINO_SRC = ROOT / "generated" / "arduino" / "DroneProtocol" / "src"
FLASH_TARGET = 908  # issue 11
RAM_TARGET = 28  # issue 11
# The firmware's flags (firmware/firmware.mk), minus the Arduino core: both sketches are built with exactly these.
AVR_FLAGS = [
    "-mmcu=atmega328p", "-Os", "-std=gnu++11", "-DF_CPU=16000000L", "-fno-exceptions", "-fno-threadsafe-statics",
    "-ffunction-sections", "-fdata-sections", "-flto", "-Wall", "-Wextra", "-Werror", "-Wl,--gc-sections",
]
HOST_FLAGS = ["-std=c++11", "-O2", "-g", "-Wall", "-Wextra", "-Werror"]


# ---------------------------------------------------------------------------------------------------- native


def _run(cmd: Sequence[str | Path], cwd: Path | None = None) -> str:
    proc = subprocess.run([str(c) for c in cmd], cwd=cwd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(str(c) for c in cmd)} failed ({proc.returncode}):\n{proc.stdout}{proc.stderr}")
    return proc.stdout


def _key_values(text: str) -> dict[str, str]:
    return dict(line.split("=", 1) for line in text.splitlines() if "=" in line)


def _callgrind_instructions(binary: Path, loop: str, frames: int, out: Path) -> int:
    _run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", f"--toggle-collect=bench_{loop}",
          binary, loop, str(frames)])
    match = re.search(r"^totals:\s+(\d+)", out.read_text(), re.MULTILINE)
    if match is None:
        raise RuntimeError(f"no totals in {out}")
    return int(match.group(1))


def bench_host(settings: Settings) -> list[Row]:
    settings.build.mkdir(parents=True, exist_ok=True)
    binary = settings.build / "host_bench"
    _run(["g++", *HOST_FLAGS, f"-I{ARDUINO_SRC}", HERE / "host_bench.cpp", "-o", binary])
    frames = 100_000  # 600 kB: stays in cache, as a serial stream does; memory bandwidth is not what is measured
    passes = 20 if settings.quick else 200
    kv = _key_values(_run([binary, "time", str(frames), str(passes)]))
    parser_s, naive_s = float(kv["parser_s"]), float(kv["naive_s"])
    rows = [
        Row("host", "StreamParser+dispatch throughput (g++ -O2)",
            f"{float(kv['parser_frames_per_s']) / 1e6:.1f} M frames/s, {float(kv['parser_mb_per_s']):.0f} MB/s",
            f"{float(kv['naive_frames_per_s']) / 1e6:.1f} M frames/s, {float(kv['naive_mb_per_s']):.0f} MB/s "
            "(naive 6-byte atoi)", f"{parser_s / naive_s:.1f}x time", "-", "info"),
        Row("host", "time per frame", f"{parser_s / frames * 1e9:.1f} ns", f"{naive_s / frames * 1e9:.2f} ns (naive)",
            f"{parser_s / naive_s:.1f}x", "-", "info"),
        Row("host", "memcpy of the same stream (bandwidth ceiling)", f"{float(kv['memcpy_mb_per_s']):.0f} MB/s", "-",
            "-", "-", "info"),
    ]
    if shutil.which("valgrind") is None:
        rows.append(Row("host", "instructions per frame (callgrind)", "valgrind missing", "-", "-", "-", "skipped"))
        return rows
    cg_frames = 20_000 if settings.quick else 100_000
    parser_ir = _callgrind_instructions(binary, "parser", cg_frames, settings.build / "callgrind.parser.out")
    naive_ir = _callgrind_instructions(binary, "naive", cg_frames, settings.build / "callgrind.naive.out")
    rows.append(Row("host", "instructions per frame (callgrind, exact)", f"{parser_ir / cg_frames:.1f} Ir",
                    f"{naive_ir / cg_frames:.1f} Ir (naive)", f"{parser_ir / naive_ir:.1f}x", "-", "info"))
    return rows


@dataclass(frozen=True)
class AvrSize:
    flash: int  # .text + .data
    ram: int  # .data + .bss (static; the stack is not counted)


def _avr_size(elf: Path) -> AvrSize:
    sections: dict[str, int] = {}
    for line in _run(["avr-size", "-A", elf]).splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].startswith(".") and parts[1].isdigit():
            sections[parts[0]] = int(parts[1])
    data, text, bss = sections.get(".data", 0), sections.get(".text", 0), sections.get(".bss", 0)
    return AvrSize(text + data, data + bss)


def bench_avr(settings: Settings) -> list[Row]:
    if shutil.which("avr-g++") is None:
        return [Row("avr", "parser flash/RAM on the ATmega328P", "avr-g++ missing", "-", "-", "-", "skipped")]
    settings.build.mkdir(parents=True, exist_ok=True)
    sketch = HERE / "avr_sketch.cpp"
    base_elf, parser_elf = settings.build / "sketch_base.elf", settings.build / "sketch_parser.elf"
    _run(["avr-g++", *AVR_FLAGS, f"-I{ARDUINO_SRC}", sketch, "-o", base_elf])
    _run(["avr-g++", *AVR_FLAGS, f"-I{ARDUINO_SRC}", "-DWITH_PARSER", sketch, "-o", parser_elf])
    base, with_parser = _avr_size(base_elf), _avr_size(parser_elf)
    flash, ram = with_parser.flash - base.flash, with_parser.ram - base.ram
    flash_ok, ram_ok = flash <= FLASH_TARGET, ram <= RAM_TARGET
    return [
        Row("avr", "flash of StreamParser+dispatch (avr-g++ -Os -flto)", f"{flash} B (sketch {with_parser.flash} B)",
            f"sketch without it {base.flash} B", "-", f"<= {FLASH_TARGET} B", "met" if flash_ok else "MISSED"),
        Row("avr", "static RAM of StreamParser+dispatch", f"{ram} B (sketch {with_parser.ram} B)",
            f"sketch without it {base.ram} B", "-", f"<= {RAM_TARGET} B", "met" if ram_ok else "MISSED"),
    ]


# ---------------------------------------------------------------------------------------------------- report

SECTIONS: dict[str, Callable[[Settings], list[Row]]] = {
    "python": bench_python,
    "host": bench_host,
    "avr": bench_avr,
}
HEADER = ("Section", "Measure", "Subject", "Baseline (same run)", "Ratio", "Target", "Verdict")


def _cells(row: Row) -> tuple[str, ...]:
    return (row.section, row.measure, row.subject, row.baseline, row.ratio, row.target, row.verdict)


def text_table(rows: Sequence[Row]) -> str:
    table = [HEADER, *(_cells(r) for r in rows)]
    widths = [max(len(line[i]) for line in table) for i in range(len(HEADER))]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=True)).rstrip() for line in table]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(rows: Sequence[Row]) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "|".join("---" for _ in HEADER) + "|"]
    lines += ["| " + " | ".join(c.replace("|", "\\|") for c in _cells(r)) + " |" for r in rows]
    return "\n".join(lines)


def _first_line(cmd: Sequence[str]) -> str:
    try:
        out = subprocess.run(list(cmd), capture_output=True, text=True, check=False).stdout
    except OSError:
        return "missing"
    return out.splitlines()[0].strip() if out else "missing"


def _shown(path: Path) -> str:
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def environment() -> list[str]:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    commit = _first_line(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"])
    return [
        f"- date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; commit {commit}; spec fingerprint "
        f"{dp.SPEC_FINGERPRINT}; codec {_shown(Path(dp.__file__).resolve().parent)}",
        f"- machine: {cpu}, {os.cpu_count()} CPUs (shared), {platform.system()} {platform.release()}",
        f"- Python {platform.python_version()}; {_first_line(['g++', '--version'])}; "
        f"{_first_line(['avr-g++', '--version'])}; {_first_line(['valgrind', '--version'])}",
    ]


METHOD = """\
## Method

- **python**: 1000 messages per pass; a realistic mix (40 % `hold_altitude` keep-alives, 30 % moves, turns and
  others at their default values, 25 % commands at a random value in range, 5 % any command). The floors are a
  bare f-string formatter (`f"{c}{d}{v:04d}".encode()`) and a bare slice-and-int parser
  (`frame[0], frame[1], int(frame[2:6])`), called through the same loop shape as the subject. Baseline and
  subject passes alternate back to back; ns/msg is the best pass, the ratio is the median of the per-pair
  ratios. "Cold" decodes 1000 distinct valid frames with the decoder's memo emptied before each pass (its worst
  case). `StreamDecoder` (fed 6-byte chunks) and `parse_reply` (90 % `A..` lines, the rest `E.` and `!F`,
  against slicing off the kind byte) are informational: no target.
- **host**: `bench/protocol/host_bench.cpp`, g++ -O2; one stream of 100,000 frames (600 kB, cache-resident) of
  the same kind of mix, fed byte by byte to `StreamParser::feed` with `dispatch()` to one handler per category;
  the baseline trusts the framing and does a fixed 6-byte atoi (the compiler vectorises it). Best of 200
  interleaved passes. Instructions are counted by callgrind over the same 100,000 frames inside the measured
  loop only (`--toggle-collect`): exact and repeatable, unlike the times.
- **avr**: `bench/protocol/avr_sketch.cpp`, plain avr-libc (UART polled at 115200, Timer0 milliseconds), built
  twice with the firmware's flags (`-Os -flto -ffunction-sections -fdata-sections -Wl,--gc-sections`), once with
  `-DWITH_PARSER` (StreamParser + dispatch to 5 category handlers). Flash = .text + .data, RAM = .data + .bss
  (static only) from `avr-size -A`; the figure is the difference.
"""


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--quick", action="store_true", help="fewer repetitions (a smoke run, not for figures)")
    parser.add_argument("--build", type=Path, default=ROOT / "build" / "bench" / "protocol", help="scratch folder")
    parser.add_argument("--results", type=Path, default=HERE / "RESULTS.md", help="where to write the figures")
    parser.add_argument("--no-write", action="store_true", help="print only")
    parser.add_argument("--only", nargs="+", choices=sorted(SECTIONS), help="run only these sections")
    args = parser.parse_args(argv)
    settings = Settings(quick=args.quick, build=args.build.resolve())
    rows: list[Row] = []
    for name, bench in SECTIONS.items():
        if args.only and name not in args.only:
            continue
        print(f"running {name} ...", file=sys.stderr, flush=True)
        rows += bench(settings)
    print(text_table(rows))
    missed = [r for r in rows if r.verdict == "MISSED"]
    if not args.no_write:
        text = "\n".join([
            "# Protocol benchmarks",
            "",
            "Written by `make bench-protocol` (`python -m bench.protocol.run`). Every figure is measured against its",
            "baseline in the same run; compare the ratios, not the absolute times (a shared, noisy machine).",
            "",
            *environment(),
            *(["- **quick run** (fewer repetitions)"] if args.quick else []),
            "",
            markdown_table(rows),
            "",
            METHOD,
        ])
        args.results.write_text(text)
        print(f"wrote {args.results}", file=sys.stderr)
    if missed:
        print("missed targets: " + "; ".join(r.measure for r in missed), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
