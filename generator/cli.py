"""Command line: regenerate every target, or check that generated/ matches the spec."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import __version__
from .build import load_spec
from .errors import SpecInvalid
from .render import render_all, stale_files, write_atomically

EXIT_STALE = 1
EXIT_INVALID = 2
# Relative to the current folder: the repository's layout. An installed generator run elsewhere needs --spec.
DEFAULT_SPEC = Path("spec/drone.yaml")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m generator", description=__doc__)
    parser.add_argument("--spec", type=Path, help=f"the YAML spec (default: {DEFAULT_SPEC} in the current folder)")
    parser.add_argument("--out", type=Path, default=Path("generated"), help="output folder (default: %(default)s)")
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 listing stale or missing files")
    parser.add_argument("--version", action="store_true", help="print the generator's version and the spec's "
                        "fingerprint, then exit")
    args = parser.parse_args(argv)
    if args.spec is None:
        if not DEFAULT_SPEC.is_file():
            if args.version:
                print(f"{parser.prog} {__version__} (no spec: {DEFAULT_SPEC} is not in the current folder)")
                return 0
            print(f"{parser.prog}: error: no spec given and no {DEFAULT_SPEC} in the current folder: "
                  "pass --spec FILE", file=sys.stderr)
            return EXIT_INVALID
        args.spec = DEFAULT_SPEC
    try:
        spec = load_spec(args.spec)
    except SpecInvalid as exc:
        count = len(exc.errors)
        print(f"{args.spec}: {count} error{'s' if count != 1 else ''}; nothing was written", file=sys.stderr)
        for error in exc.errors:
            print(error, file=sys.stderr)
        return EXIT_INVALID
    if args.version:
        print(f"{parser.prog} {__version__} (spec {args.spec}: {spec.name} {spec.version}, "
              f"fingerprint {spec.short_fingerprint})")
        return 0
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
