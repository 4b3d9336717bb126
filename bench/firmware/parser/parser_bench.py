"""The generated StreamParser on the ATmega328P and under corruption; writes bench/firmware/PARSER_RESULTS.md.

- cycles per byte on a clean stream and on random garbage (simavr, bench/firmware/parser/parser_cycles.cpp), net of
  the same loop without the parser, against a naive 6-byte atoi in the same binary;
- flash of parser + dispatch per command: the same AVR sketch built from the shipped spec and from a synthetic
  26 x 26 = 676-command spec (the RAM of the parser is the same for both);
- spurious frames accepted under 1/10/50 % byte corruption, integrity none and crc8 (host build,
  bench/firmware/parser/corruption.cpp), dangerous ones (arm, disarm, laser, self-test, land) apart.

Run with `make bench-parser` (part of `make bench-firmware`).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[3]
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT / "tests" / "firmware"))
from test_firmware_many_commands import AVR_FLAGS, synthetic_spec  # noqa: E402  (the test's synthetic spec)

SPEC = ROOT / "spec" / "drone.yaml"
SHIPPED = ROOT / "generated" / "arduino" / "DroneProtocol" / "src"
CORRUPT_FRAMES = 1_000_000
RATES = (1, 10, 50)


def run(cmd: list[str], stdin: str = "") -> str:
    return subprocess.run(cmd, input=stdin, capture_output=True, text=True, check=True).stdout


def generate(data: dict[str, object], out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    spec = out / "drone.yaml"
    spec.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    run([sys.executable, "-m", "generator", "--spec", str(spec), "--out", str(out / "generated")])
    return out / "generated" / "arduino" / "DroneProtocol" / "src"


def avr_size(elf: Path) -> tuple[int, int]:
    text, data, bss = (int(x) for x in run(["avr-size", str(elf)]).splitlines()[1].split()[:3])
    return text + data, data + bss


def cycles(build: Path) -> dict[str, float]:
    elf = build / "parser_cycles.elf"
    run(["avr-g++", *AVR_FLAGS, f"-I{SHIPPED}", str(HERE / "parser_cycles.cpp"), "-o", str(elf)])
    out = run([str(ROOT / "firmware" / "build" / "sim" / "drone_sim"), "--elf", str(elf), "--until", "200"], "\n")
    widths = [json.loads(x)["width"] for x in out.splitlines() if x.startswith("{") and '"pin":7' in x]
    mark, spans = min(widths[:8]), widths[8:]
    assert len(spans) % 4 == 0 and spans, spans
    stream = 96 * wire_length()
    per = {k: min(spans[i::4]) - mark for i, k in enumerate(("clean", "garbage", "naive", "empty"))}
    return {"clean": (per["clean"] - per["empty"]) / stream, "garbage": (per["garbage"] - per["empty"]) / stream,
            "naive": per["naive"] / stream, "clean_raw": per["clean"] / stream, "empty": per["empty"] / stream}


def wire_length() -> int:
    text = (SHIPPED / "DroneProtocol_spec.h").read_text()
    return int(text.split("WIRE_LENGTH = ")[1].split(";")[0])


SKETCH = """#include <avr/io.h>
#include <DroneProtocol.h>
namespace dp = drone_protocol;
struct Handlers {
%s};
static dp::StreamParser parser;
static Handlers handlers;
int main() {
  uint32_t now = 0;
  for (;;) {
    if (parser.feed(UDR0, ++now)) GPIOR0 = static_cast<uint8_t>(dp::dispatch(parser.command(), handlers));
  }
}
"""


def sketch_size(include: Path, categories: list[str], build: Path, name: str) -> tuple[int, int]:
    """Flash and RAM of a sketch with the parser and dispatch to one handler per category."""
    handlers = "".join(f"  void on_{c}(const dp::Command& c) {{ GPIOR1 = {i}; OCR1A = c.value; }}\n"
                       for i, c in enumerate(categories))
    src = build / f"{name}.cpp"
    src.write_text(SKETCH % handlers, encoding="utf-8")
    elf = build / f"{name}.elf"
    run(["avr-g++", *AVR_FLAGS, f"-I{include}", str(src), "-o", str(elf)])
    return avr_size(elf)


def corruption(include: Path, build: Path, name: str) -> dict[int, dict[str, int]]:
    exe = build / name
    run(["g++", "-std=c++11", "-O2", "-Wall", "-Wextra", "-Werror", f"-I{include}", str(HERE / "corruption.cpp"),
         "-o", str(exe)])
    out: dict[int, dict[str, int]] = {}
    for rate in RATES:
        words = run([str(exe), str(CORRUPT_FRAMES), str(rate), "20261121"]).split()
        out[rate] = {words[i]: int(words[i + 1]) for i in range(0, len(words), 2)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", type=Path, default=ROOT / "build" / "bench" / "parser")
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "firmware" / "PARSER_RESULTS.md")
    args = parser.parse_args()
    build: Path = args.build
    build.mkdir(parents=True, exist_ok=True)
    shipped = yaml.safe_load(SPEC.read_text(encoding="utf-8"))
    c = cycles(build)

    many = synthetic_spec()
    many_inc = generate(many, build / "many")
    base_src = build / "empty.cpp"
    base_src.write_text("#include <avr/io.h>\nint main() { for (;;) GPIOR0 = UDR0; }\n", encoding="utf-8")
    run(["avr-g++", *AVR_FLAGS, str(base_src), "-o", str(build / "empty.elf")])
    floor = avr_size(build / "empty.elf")
    cats = [str(v["name"]) for v in shipped["categories"].values()]
    small = sketch_size(SHIPPED, cats, build, "small")
    large = sketch_size(many_inc, [str(v["name"]) for v in many["categories"].values()], build, "large")
    n_small = sum(len(v["directions"]) for v in shipped["categories"].values())
    n_large = sum(len(v["directions"]) for v in many["categories"].values())
    per_command = (large[0] - small[0]) / (n_large - n_small)

    crc = dict(shipped)
    crc["frame"] = {**shipped["frame"], "integrity": "crc8"}
    crc_inc = generate(crc, build / "crc8")
    corrupt = {"none": corruption(SHIPPED, build, "corrupt_none"), "crc8": corruption(crc_inc, build, "corrupt_crc8")}

    def verdict(ok: bool) -> str:
        return "met" if ok else "missed"

    rows = [
        "| measure | ours | floor / peer (same run) | goal | verdict |",
        "|---|---:|---:|---:|---|",
        f"| cycles per byte, clean stream (parser alone) | {c['clean']:.1f} | naive atoi {c['naive']:.1f} "
        f"({c['clean'] / c['naive']:.1f}x) | <= 60 | {verdict(c['clean'] <= 60)} |",
        f"| cycles per byte, random garbage (parser alone) | {c['garbage']:.1f} | | <= 90 | "
        f"{verdict(c['garbage'] <= 90)} |",
        f"| CPU share at 115200 back to back, clean (11520 bytes/s) | {100 * c['clean'] * 11520 / 16e6:.2f} % | | "
        f"<= 4.3 % | {verdict(c['clean'] * 11520 / 16e6 <= 0.043)} |",
        f"| flash of parser + dispatch, shipped spec ({n_small} commands) | {small[0] - floor[0]} B | | <= 908 B | "
        f"{verdict(small[0] - floor[0] <= 908)} |",
        f"| static RAM of parser + dispatch, shipped spec | {small[1] - floor[1]} B | | <= 28 B | "
        f"{verdict(small[1] - floor[1] <= 28)} |",
        f"| flash of parser + dispatch, {n_large} commands | {large[0] - floor[0]} B | | | |",
        f"| static RAM of parser + dispatch, {n_large} commands | {large[1] - floor[1]} B | | same as above | "
        f"{verdict(large[1] == small[1])} |",
        f"| flash per command ({n_small} -> {n_large}) | {per_command:.1f} B | | <= 12 B | "
        f"{verdict(per_command <= 12)} |",
    ]
    corr = ["| integrity | corruption | frames | corrupted frames | emitted | spurious | dangerous spurious |",
            "|---|---:|---:|---:|---:|---:|---:|"]
    for mode, by_rate in corrupt.items():
        for rate, r in by_rate.items():
            corr.append(f"| {mode} | {rate} % | {r['frames']} | {r['corrupted_frames']} | {r['emitted']} | "
                        f"{r['spurious']} | {r['dangerous']} |")
    text = "\n".join([
        "# Generated StreamParser: AVR cycles, flash per command, corruption (`make bench-parser`)",
        "",
        "Written by bench/firmware/parser/parser_bench.py. Cycles: ATmega328P at 16 MHz in simavr, the parser fed",
        f"{96} frames byte by byte (best of 3 passes), minus the same loop without the parser "
        f"({c['empty']:.1f} cycles per byte;",
        f"with it: {c['clean_raw']:.1f}); the naive floor reads 6-byte frames with a fixed atoi and checks nothing.",
        "Flash: a minimal avr-libc sketch with parser + dispatch to one handler per category, minus the sketch",
        "without them (avr-g++ -Os -flto, gc-sections). Corruption: host build, each byte replaced by a random one",
        "with the given probability, frames uniform over the commands; spurious = emitted but not a sent frame",
        "received intact; dangerous = spurious arm, disarm, laser, self-test or land.",
        "",
        *rows,
        "",
        *corr,
        "",
    ])
    args.out.write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
