"""Protocol benchmarks (issue 2, "Measure"): every figure against a baseline measured in the same run.

    python bench/protocol/run.py [--quick] [--build DIR] [--results FILE | --no-write] [--only SECTION ...]

Sections:
  python     encode/decode per message of the generated `drone_protocol` against a bare f-string formatter and a
             bare slice-and-int parser (target: within 2x)
  host       C++ StreamParser + dispatch throughput (g++ -O2) and instructions per frame (callgrind) against a
             naive fixed-6-byte atoi loop in the same program
  avr        flash and RAM of the parser + dispatch for the ATmega328P (avr-g++ -Os): a tiny avr-libc sketch
             built with and without it (target: under 1 KB flash, under 32 bytes RAM)
  generator  `python -m generator --out DIR` and `--check` against `python -c pass`

Times on a shared machine are noisy: Python figures are best-of-N per message and the median of paired ratios
(baseline and subject timed back to back, alternating order); process timings are medians; instruction counts
and sizes are exact. Prints one table and writes it, with the environment, to bench/protocol/RESULTS.md.
"""

from __future__ import annotations

import argparse
import gc
import inspect
import os
import platform
import random
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
GENERATED_PY = ROOT / "generated" / "python"
ARDUINO_SRC = ROOT / "generated" / "arduino" / "DroneProtocol" / "src"
# Measure the repository's generated module, whatever is installed; BENCH_CODEC_DIR=DIR (a folder holding a
# drone_protocol/ package, e.g. a scratch copy with a template change tried by hand) measures that one instead.
CODEC_DIR = Path(os.environ.get("BENCH_CODEC_DIR", GENERATED_PY)).resolve()
sys.path.insert(0, str(CODEC_DIR))

import drone_protocol as dp  # noqa: E402

PYTHON_TARGET = 2.0
FLASH_TARGET = 908  # issue 11
RAM_TARGET = 28  # issue 11
# The firmware's flags (firmware/firmware.mk), minus the Arduino core: both sketches are built with exactly these.
AVR_FLAGS = [
    "-mmcu=atmega328p", "-Os", "-std=gnu++11", "-DF_CPU=16000000L", "-fno-exceptions", "-fno-threadsafe-statics",
    "-ffunction-sections", "-fdata-sections", "-flto", "-Wall", "-Wextra", "-Werror", "-Wl,--gc-sections",
]
HOST_FLAGS = ["-std=c++11", "-O2", "-g", "-Wall", "-Wextra", "-Werror"]


@dataclass(frozen=True)
class Row:
    section: str
    measure: str
    subject: str
    baseline: str
    ratio: str
    target: str
    verdict: str


@dataclass(frozen=True)
class Settings:
    quick: bool
    build: Path


# ---------------------------------------------------------------------------------------------------- python


def floor_encode(category: str, direction: str, value: int) -> bytes:
    """The floor of encoding: format the three fields, no lookup, no check."""
    return f"{category}{direction}{value:04d}".encode("ascii")


def floor_decode(frame: bytes) -> tuple[int, int, int]:
    """The floor of decoding: slice and int, no lookup, no check."""
    return frame[0], frame[1], int(frame[2:6])


def floor_reply(line: bytes) -> tuple[bytes, bytes]:
    """The floor of reading a reply line: its kind byte and the rest, no check."""
    return line[:1], line[1:].rstrip(b"\r\n")


@dataclass(frozen=True)
class Pick:
    spec: dp.CommandSpec
    value: int
    uses_default: bool


def realistic_mix(n: int, seed: int = 2) -> list[Pick]:
    """What a pilot sends: keep-alives, moves and turns at their default speeds or others, servo steps, and the
    odd laser or init command. Drawn from the spec's COMMANDS, so new commands join the mix."""
    rng = random.Random(seed)
    specs = list(dp.COMMANDS.values())
    keep_alive = dp.COMMANDS.get("hold_altitude", specs[0])
    with_default = [s for s in specs if s.default is not None]
    ranged = [s for s in specs if s.minimum < s.maximum]
    out: list[Pick] = []
    for _ in range(n):
        r = rng.random()
        if r < 0.4:
            out.append(Pick(keep_alive, keep_alive.default or keep_alive.minimum, keep_alive.default is not None))
        elif r < 0.7:
            spec = rng.choice(with_default)
            assert spec.default is not None
            out.append(Pick(spec, spec.default, True))
        elif r < 0.95:
            spec = rng.choice(ranged)
            out.append(Pick(spec, rng.randint(spec.minimum, spec.maximum), False))
        else:
            spec = rng.choice(specs)
            out.append(Pick(spec, spec.default if spec.default is not None else spec.minimum, spec.default is not None))
    return out


def distinct_frames(n: int, seed: int = 3) -> list[bytes]:
    """`n` different valid frames, uniformly over every valid frame of the spec (no repeats: no cache helps)."""
    every = [(spec, value) for spec in dp.COMMANDS.values() for value in range(spec.minimum, spec.maximum + 1)]
    picked = random.Random(seed).sample(every, min(n, len(every)))
    return [dp.encode(spec.category, spec.direction, value) for spec, value in picked]


@dataclass(frozen=True)
class Paired:
    subject_ns: float  # best pass, per item
    baseline_ns: float
    ratio: float  # median over passes of subject/baseline, each pair timed back to back


def paired(subject: Callable[[], object], baseline: Callable[[], object], items: int, passes: int,
           before_subject: Callable[[], object] | None = None) -> Paired:
    subject_t: list[int] = []
    baseline_t: list[int] = []
    subject()
    baseline()
    enabled = gc.isenabled()
    gc.disable()
    try:
        for i in range(passes):
            for run_subject in ((False, True) if i % 2 == 0 else (True, False)):
                if run_subject and before_subject is not None:
                    before_subject()
                fn = subject if run_subject else baseline
                t0 = time.perf_counter_ns()
                fn()
                elapsed = time.perf_counter_ns() - t0
                (subject_t if run_subject else baseline_t).append(elapsed)
    finally:
        if enabled:
            gc.enable()
    ratios = [s / b for s, b in zip(subject_t, baseline_t, strict=True)]
    return Paired(min(subject_t) / items, min(baseline_t) / items, statistics.median(ratios))


def _call_each(calls: Sequence[tuple[Callable[..., object], tuple[Any, ...]]]) -> Callable[[], None]:
    def loop() -> None:
        for fn, args in calls:
            fn(*args)

    return loop


def _decode_each(fn: Callable[[bytes], object], frames: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        for frame in frames:
            fn(frame)

    return loop


def _feed_each(frames: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        decoder = dp.StreamDecoder(time_fn=lambda: 0.0)
        for frame in frames:
            decoder.feed(frame, 0.0)

    return loop


def _clear_decode_cache() -> None:
    dp.codec.DECODED.clear()  # the generated decoder's memo of frames


def _feed_stream(chunks: Sequence[bytes]) -> Callable[[], None]:
    def loop() -> None:
        feed = dp.StreamDecoder(time_fn=lambda: 0.0).feed
        for chunk in chunks:
            feed(chunk, 0.0)

    return loop


def _chunks(data: bytes, size: int) -> list[bytes]:
    return [data[i:i + size] for i in range(0, len(data), size)]


def _with_garbage(frames: Sequence[bytes], seed: int = 5) -> bytes:
    """The frames with as many random bytes as frame bytes between them (50 % garbage)."""
    rng = random.Random(seed)
    return b"".join(bytes(rng.randrange(256) for _ in range(len(f))) + f for f in frames)


def _python_row(measure: str, result: Paired, baseline_name: str, target: float | None) -> Row:
    verdict = "info" if target is None else ("met" if result.ratio <= target else "MISSED")
    return Row("python", measure, f"{result.subject_ns:.0f} ns/msg",
               f"{result.baseline_ns:.0f} ns/msg ({baseline_name})", f"{result.ratio:.2f}x",
               "-" if target is None else f"<= {target:.1f}x", verdict)


def _per_command_call(pick: Pick) -> tuple[Callable[..., bytes], tuple[int, ...]]:
    fn: Callable[..., bytes] = getattr(dp, pick.spec.name)
    if not inspect.signature(fn).parameters or pick.uses_default:
        return fn, ()
    return fn, (pick.value,)


def bench_python(settings: Settings) -> list[Row]:
    n = 1000
    passes = 40 if settings.quick else 300
    mix = realistic_mix(n)
    floor_calls = [(floor_encode, (p.spec.category.value, p.spec.direction.value, p.value)) for p in mix]
    enum_calls = [(dp.encode, (p.spec.category, p.spec.direction, p.value)) for p in mix]
    text_calls = [(dp.encode, (p.spec.category.value, p.spec.direction.value, p.value)) for p in mix]
    command_calls = [_per_command_call(p) for p in mix]
    frames = [dp.encode(p.spec.category, p.spec.direction, p.value) for p in mix]
    distinct = distinct_frames(n)
    # What the Arduino answers to that mix: mostly acceptances, some refusals and the odd failsafe.
    reply_rng = random.Random(4)
    errors = list(dp.ErrorKind)
    moving, failsafe = dp.DroneState.MOVING, dp.DroneState.FAILSAFE
    replies = [dp.accepted_line(dp.decode(f), moving, False) if reply_rng.random() < 0.9 else
               (dp.rejected_line(reply_rng.choice(errors), moving, False) if reply_rng.random() < 0.95
                else dp.failsafe_line(failsafe, False))
               for f in frames]

    # The subjects must produce what the floors produce before they are timed.
    for (fn, args), frame in zip(command_calls, frames, strict=True):
        assert fn(*args) == frame, (fn, args, frame)
    for frame in frames + distinct:
        command = dp.decode(frame)
        assert dp.encode(command.category, command.direction, command.value) == frame

    floor = _call_each(floor_calls)
    rows = [
        _python_row("encode(Category, Direction, value), mix", paired(_call_each(enum_calls), floor, n, passes),
                    "f-string", PYTHON_TARGET),
        _python_row("encode(str, str, value), mix", paired(_call_each(text_calls), floor, n, passes), "f-string",
                    PYTHON_TARGET),
        _python_row("per-command functions, mix", paired(_call_each(command_calls), floor, n, passes), "f-string",
                    PYTHON_TARGET),
        _python_row("decode(frame), mix", paired(_decode_each(dp.decode, frames), _decode_each(floor_decode, frames),
                                                  n, passes), "slice+int", PYTHON_TARGET),
        _python_row("decode(frame), 1000 distinct frames, cold", paired(
            _decode_each(dp.decode, distinct), _decode_each(floor_decode, distinct), n, passes,
            before_subject=_clear_decode_cache), "slice+int", 2.0),
        _python_row("StreamDecoder.feed(6-byte chunks), mix", paired(
            _feed_each(frames), _decode_each(floor_decode, frames), n, max(passes // 5, 10)), "slice+int", None),
        _python_row("StreamDecoder, clean stream in 4 kB reads, cold", paired(
            _feed_stream(_chunks(b"".join(distinct), 4096)), _decode_each(floor_decode, distinct), n,
            max(passes // 5, 10), before_subject=_clear_decode_cache), "slice+int", 3.0),
        _python_row("StreamDecoder, 50 % garbage in 4 kB reads, cold", paired(
            _feed_stream(_chunks(_with_garbage(distinct), 4096)), _decode_each(floor_decode, distinct), n,
            max(passes // 5, 10), before_subject=_clear_decode_cache), "slice+int", 10.0),
        _python_row("StreamDecoder, clean stream one byte per call", paired(
            _feed_stream(_chunks(b"".join(frames), 1)), _decode_each(floor_decode, frames), n,
            max(passes // 10, 10)), "slice+int", 10.0),
        _python_row("parse_reply(line), replies to the mix", paired(
            _decode_each(dp.parse_reply, replies), _decode_each(floor_reply, replies), n, max(passes // 5, 10)),
            "slice", None),
    ]
    return rows


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


# ---------------------------------------------------------------------------------------------------- generator


def _seconds(args: Sequence[str]) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(list(args), cwd=ROOT, capture_output=True, check=False)
    elapsed = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed ({proc.returncode}): {proc.stderr.decode(errors='replace')}")
    return elapsed


def bench_generator(settings: Settings) -> list[Row]:
    reps = 3 if settings.quick else 11
    py = sys.executable
    start: list[float] = []
    regen: list[float] = []
    check: list[float] = []
    with tempfile.TemporaryDirectory(prefix="bench-generator-") as tmp:
        # Interleaved, one run of each in turn, so that drift hits all three alike. Regenerating writes into a
        # new folder each time, so every file is written.
        for i in range(reps):
            start.append(_seconds([py, "-c", "pass"]))
            regen.append(_seconds([py, "-m", "generator", "--out", str(Path(tmp) / f"out{i}")]))
            check.append(_seconds([py, "-m", "generator", "--check"]))
    base = statistics.median(start)
    rows = []
    for measure, times in (("regenerate everything (--out fresh dir)", regen), ("--check", check)):
        t = statistics.median(times)
        rows.append(Row("generator", measure, f"{t * 1000:.0f} ms", f"{base * 1000:.0f} ms (python -c pass)",
                        f"{t / base:.1f}x", "-", "info"))
    return rows


# ---------------------------------------------------------------------------------------------------- report

SECTIONS: dict[str, Callable[[Settings], list[Row]]] = {
    "python": bench_python,
    "host": bench_host,
    "avr": bench_avr,
    "generator": bench_generator,
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
- **generator**: wall time of whole processes, median of 11 interleaved runs; regenerating writes into a new
  folder each time.
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
            "Written by `make bench-protocol` (`bench/protocol/run.py`). Every figure is measured against its baseline",
            "in the same run; compare the ratios, not the absolute times (a shared, noisy machine).",
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
