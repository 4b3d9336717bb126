"""Command line: regenerate every target, or check that generated/ matches the spec."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from generator import __version__
from generator.build import load_spec
from generator.errors import SpecInvalid
from generator.render import render_all, stale_files, write_atomically

EXIT_STALE = 1
EXIT_INVALID = 2


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m generator", description=__doc__)
    parser.add_argument("--spec", type=Path, default=Path("spec/drone.yaml"),
                        help="the YAML spec (default: %(default)s)")
    parser.add_argument("--out", type=Path, default=Path("generated"), help="output folder (default: %(default)s)")
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 listing stale or missing files")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    args = parser.parse_args(argv)
    try:
        spec = load_spec(args.spec)
    except SpecInvalid as exc:
        count = len(exc.errors)
        print(f"{args.spec}: {count} error{'s' if count != 1 else ''}; nothing was written", file=sys.stderr)
        for error in exc.errors:
            print(error, file=sys.stderr)
        return EXIT_INVALID
    files = render_all(spec)
    if args.check:
        problems = stale_files(files, args.out)
        for line in problems:
            print(line)
        if problems:
            print(f"{len(problems)} generated file(s) out of date: run `python -m generator`", file=sys.stderr)
            return EXIT_STALE
        print(f"{len(files)} generated files match {args.spec} (fingerprint {spec.short_fingerprint})")
        return 0
    changed = write_atomically(files, args.out)
    print(f"{len(files)} files from {args.spec} (fingerprint {spec.short_fingerprint}) in {args.out}/: "
          f"{len(changed)} changed")
    return 0
