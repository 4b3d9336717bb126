"""The generated Arduino library as an Arduino IDE user gets it, and sketches built the way the IDE builds them.

    python firmware/ide/sketchbook.py install SKETCHBOOK   # SKETCHBOOK/libraries/DroneProtocol (+ DroneFirmware)
    python firmware/ide/sketchbook.py zip OUT_DIR           # OUT_DIR/DroneProtocol-<version>.zip for "Add .ZIP Library"
    python firmware/ide/sketchbook.py build SKETCH.ino SKETCHBOOK BUILD_DIR [--board uno|mega]

The library folder is generated/arduino/DroneProtocol with one example added: examples/DroneFirmware, the
drone firmware itself (firmware/drone, its .ino renamed), so the firmware has one source and still shows under
File > Examples. Installing is atomic: the folder is staged beside its destination and renamed into place.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIBRARY = ROOT / "generated" / "arduino" / "DroneProtocol"
FIRMWARE = ROOT / "firmware" / "drone"
FIRMWARE_EXAMPLE = "DroneFirmware"

# Debian's arduino-builder and arduino-core-avr: the platform (with its ctags recipe) is a hardware folder too.
HARDWARE = ("/usr/share/arduino/hardware", "/usr/share/arduino-builder")
TOOLS = "/usr/share/arduino-builder"
BOARDS = {"uno": "arduino:avr:uno", "mega": "arduino:avr:mega:cpu=atmega2560"}
# Debian's core does not build without it (WString.cpp: 'DECIMAL_DIG' was not declared).
DEBIAN_CORE_FIX = "compiler.cpp.extra_flags=-DDECIMAL_DIG=__DECIMAL_DIG__"
CORE_API_VERSION = "10819"  # the ARDUINO define of IDE 1.8.19, as firmware.mk passes it

_SIZES = re.compile(r"Sketch uses (\d+) bytes.*?Global variables use (\d+) bytes", re.S)


class SketchbookError(Exception):
    """A build or install that failed; the message is one line for the user."""


def library_version(library: Path = LIBRARY) -> str:
    for line in (library / "library.properties").read_text(encoding="utf-8").splitlines():
        if line.startswith("version="):
            return line.split("=", 1)[1]
    raise SketchbookError(f"{library}/library.properties has no version")


def _stage(library: Path, firmware: Path, into: Path) -> Path:
    """Copy the library with the firmware example into `into`/<library name>; return that folder."""
    dest = into / library.name
    shutil.copytree(library, dest)
    example = dest / "examples" / FIRMWARE_EXAMPLE
    shutil.copytree(firmware, example, ignore=shutil.ignore_patterns("*.ino"))
    inos = sorted(firmware.glob("*.ino"))
    if len(inos) != 1:
        raise SketchbookError(f"{firmware} must hold exactly one .ino, found {len(inos)}")
    shutil.copyfile(inos[0], example / f"{FIRMWARE_EXAMPLE}.ino")
    return dest


def install(sketchbook: Path, library: Path = LIBRARY, firmware: Path = FIRMWARE) -> Path:
    """Install into `sketchbook`/libraries, replacing an older copy; nothing half-written on failure."""
    libraries = sketchbook / "libraries"
    libraries.mkdir(parents=True, exist_ok=True)
    dest = libraries / library.name
    with tempfile.TemporaryDirectory(prefix=".install-", dir=libraries) as tmp:
        staged = _stage(library, firmware, Path(tmp))
        if dest.exists():
            old = Path(tmp) / "old"
            dest.rename(old)
        staged.rename(dest)
    return dest


def make_zip(out_dir: Path, library: Path = LIBRARY, firmware: Path = FIRMWARE) -> Path:
    """The library as the IDE's "Add .ZIP Library" takes it: one top folder named like the library."""
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{library.name}-{library_version(library)}.zip"
    with tempfile.TemporaryDirectory() as tmp:
        staged = _stage(library, firmware, Path(tmp))
        partial = out_dir / f".{target.name}.tmp"
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in sorted(staged.rglob("*")):
                archive.write(path, path.relative_to(staged.parent).as_posix())
        partial.replace(target)
    return target


@dataclass(frozen=True)
class Build:
    flash: int
    ram: int
    elf: Path
    output: str  # everything arduino-builder printed


def build(sketch: Path, sketchbook: Path, build_dir: Path, board: str = "uno", cache: Path | None = None) -> Build:
    """Build like the Arduino IDE 1.8: the sketchbook's libraries folder, the board's FQBN, verbose output."""
    build_dir.mkdir(parents=True, exist_ok=True)
    command = ["arduino-builder", "-compile", "-verbose", "-logger", "human", "-core-api-version", CORE_API_VERSION,
               "-fqbn", BOARDS[board], "-libraries", str(sketchbook / "libraries"), "-tools", TOOLS,
               "-build-path", str(build_dir), f"-prefs={DEBIAN_CORE_FIX}"]
    for hardware in HARDWARE:
        command += ["-hardware", hardware]
    if cache is not None:
        cache.mkdir(parents=True, exist_ok=True)
        command += ["-build-cache", str(cache)]
    run = subprocess.run([*command, str(sketch)], capture_output=True, text=True, check=False)
    output = run.stdout + run.stderr
    sizes = _SIZES.search(output)
    if run.returncode != 0 or sizes is None:
        tail = "\n".join(output.splitlines()[-25:])
        raise SketchbookError(f"arduino-builder failed on {sketch} for {board} (exit {run.returncode}):\n{tail}")
    return Build(int(sizes.group(1)), int(sizes.group(2)), build_dir / f"{sketch.name}.elf", output)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="action", required=True)
    sub.add_parser("install").add_argument("sketchbook", type=Path)
    sub.add_parser("zip").add_argument("out_dir", type=Path)
    b = sub.add_parser("build")
    b.add_argument("sketch", type=Path)
    b.add_argument("sketchbook", type=Path)
    b.add_argument("build_dir", type=Path)
    b.add_argument("--board", choices=sorted(BOARDS), default="uno")
    args = parser.parse_args(argv)
    try:
        if args.action == "install":
            print(f"installed {install(args.sketchbook)}")
        elif args.action == "zip":
            print(f"wrote {make_zip(args.out_dir)} (Arduino IDE: Sketch > Include Library > Add .ZIP Library)")
        else:
            result = build(args.sketch, args.sketchbook, args.build_dir, args.board)
            print(f"{args.sketch.name} ({args.board}): flash {result.flash} B, RAM {result.ram} B")
    except (SketchbookError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
