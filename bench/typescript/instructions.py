"""The TypeScript codec's stream parser and decode() against lean hand-written floors, in instructions: Node
under callgrind (bench/typescript/instructions.mjs marks each measured loop), on the shipped spec and on it plus
26 categories x 26 directions.

Usage: python bench/typescript/instructions.py [--no-write] (after `make typescript`); replaces the instruction
section of bench/typescript/RESULTS.md.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import re
import subprocess
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
BUILD = ROOT / "build" / "bench" / "typescript"
TSC = ROOT / "tests" / "targets" / "typescript" / "node_modules" / ".bin" / "tsc"


def _rust_harness() -> Any:
    """bench/rust_c/instructions.py: the 26x26 variant, the table's rows and the section's writing."""
    path = ROOT / "bench" / "rust_c" / "instructions.py"
    source = importlib.util.spec_from_file_location("rust_c_instructions", path)
    assert source is not None and source.loader is not None
    module = importlib.util.module_from_spec(source)
    source.loader.exec_module(module)
    return module


RUST = _rust_harness()


def run(cmd: list[str]) -> str:
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    return proc.stdout


def variant_dist() -> Path:
    """The 26x26 variant's package, compiled with the repository's pinned tsc."""
    RUST.BUILD.mkdir(parents=True, exist_ok=True)
    tree: Path = RUST.variant_tree()
    out = BUILD / "26x26" / "dist"
    run([str(TSC), "-p", str(tree / "typescript" / "tsconfig.json"), "--outDir", str(out)])
    (out.parent / "package.json").write_text('{"type": "module"}\n', encoding="utf-8")  # ES modules, as packed
    return out


def measure(dist: Path, name: str) -> list[dict[str, Any]]:
    """The measures instructions.mjs prints, each with the instructions of its two loops from their dumps."""
    logs = BUILD / name
    logs.mkdir(parents=True, exist_ok=True)
    for old in logs.glob("callgrind.out*"):
        old.unlink()
    out = run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={logs / 'callgrind.out'}",
               "--dump-before=uv_loadavg", "node", "--single-threaded", str(HERE / "instructions.mjs"), str(dist)])
    measures: list[dict[str, Any]] = json.loads(out.strip().splitlines()[-1])

    def dump(n: int) -> int:
        match = re.search(r"^(?:summary|totals): (\d+)", (logs / f"callgrind.out.{n}").read_text(), re.M)
        if match is None:
            raise SystemExit(f"no instruction count in dump {n}")
        return int(match.group(1))

    timed = json.loads(run(["node", str(HERE / "instructions.mjs"), str(dist), "--time"]).strip().splitlines()[-1])
    for i, m in enumerate(measures):  # dumps 1, 3, 5 ... end the warm-ups; 2, 4, 6 ... the measured loops
        m["time"] = timed[i]["ns"]["codec"] / timed[i]["ns"]["floor"]
        m["codec"], m["floor"] = dump(4 * i + 2), dump(4 * i + 4)
        found = m["found"]
        if found["codec"] != found["floor"]:
            raise SystemExit(f"{name} {m['label']}: the codec found {found['codec']}, the floor {found['floor']}")
    return measures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    version = run(["node", "--version"]).strip()
    lines = [RUST.SECTION, "",
             f"`python bench/typescript/instructions.py`: Node {version} (`--single-threaded`) under callgrind; each",
             "loop counted alone, after ten times as many warm-up passes, on about 120000 units (30000 stream bytes,",
             "clean or with 6 random bytes after each frame; every command at up to 64 distinct values, shuffled, for",
             "decode). The floors (`instructions.mjs`) check each byte with tables and slide one byte on an invalid",
             "one, with no timeouts, error kinds or counts. Units: per byte (stream) or per frame (decode). The time",
             "ratio (the same loops run natively, best of 9) is information: the goals are on instructions.", "",
             *RUST.TABLE_HEAD]
    for name, dist in (("shipped", ROOT / "build" / "typescript" / "package" / "dist"), ("26x26", variant_dist())):
        lines += [RUST.row(name, m["label"], m["codec"] / m["units"], m["floor"] / m["units"], m["time"])
                  for m in measure(dist, name)]
    RUST.publish(HERE / "RESULTS.md", lines, not args.no_write)

if __name__ == "__main__":
    main()
