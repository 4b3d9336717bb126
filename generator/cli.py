"""Command line: regenerate every target, check that generated/ matches the spec, or diff two spec versions.

  python -m generator [--spec FILE] [--out DIR] [--check]
  python -m generator diff OLD [NEW]     (OLD, NEW: a spec, or a generated contract.json; NEW: spec/drone.yaml)
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import __version__
from .build import load_spec
from .diff import Contract, contract, contract_problem, diff
from .errors import SpecInvalid
from .source import display_path

EXIT_STALE = 1
EXIT_BREAKING = 1
EXIT_INVALID = 2
CONTRACT_FILE = "contract.json"
# Relative to the current folder: the repository's layout. An installed generator run elsewhere needs --spec.
DEFAULT_SPEC = Path("spec/drone.yaml")
INSTALLED = "drone-protocol-gen"  # the console script of the tools' distribution (pyproject.toml)


def program() -> str:
    """How the user ran the generator: the installed command, or the module in the repository."""
    return INSTALLED if Path(sys.argv[0]).name == INSTALLED else "python -m generator"


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args[:1] == ["diff"]:
        return diff_main(args[1:])
    prog = program()
    parser = argparse.ArgumentParser(prog=prog, description=(__doc__ or "").replace("python -m generator", prog),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spec", type=Path, help=f"the YAML spec (default: {DEFAULT_SPEC} in the current folder)")
    parser.add_argument("--out", type=Path, default=Path("generated"), help="output folder (default: %(default)s)")
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 listing stale or missing files")
    parser.add_argument("--version", action="store_true", help="print the generator's version and the spec's "
                        "fingerprint, then exit")
    opts = parser.parse_args(args)
    if opts.spec is None:
        if not DEFAULT_SPEC.is_file():
            if opts.version:
                print(f"{parser.prog} {__version__} (no spec: {DEFAULT_SPEC} is not in the current folder)")
                return 0
            print(f"{parser.prog}: error: no spec given and no {DEFAULT_SPEC} in the current folder: "
                  "pass --spec FILE", file=sys.stderr)
            return EXIT_INVALID
        opts.spec = DEFAULT_SPEC
    shown = display_path(opts.spec)
    try:
        previous = None if opts.version else _previous_contract(opts.out / CONTRACT_FILE)
        spec = load_spec(opts.spec, previous=previous)
    except BrokenContract as exc:
        print(f"{parser.prog}: error: {exc}; restore it (git checkout {display_path(opts.out / CONTRACT_FILE)}) or "
              "delete it to generate without the check that a breaking edit raised protocol.version; nothing was "
              "written", file=sys.stderr)
        return EXIT_INVALID
    except SpecInvalid as exc:
        _report(shown, exc)
        return EXIT_INVALID
    if opts.version:
        print(f"{parser.prog} {__version__} (spec {shown}: {spec.name} {spec.version}, "
              f"fingerprint {spec.short_fingerprint})")
        return 0
    from . import precompiled
    from .render import environments, render_all  # Jinja only for a valid spec
    from .safety import report as safety_report
    from .writing import stale_files, write_atomically

    envs = environments()
    files = render_all(spec, envs)
    if opts.check:
        for line in safety_report(spec) + precompiled.notes(envs):
            print(line)
        problems = stale_files(files, opts.out) + precompiled.problems(envs, display_path)
        for line in problems:
            print(line)
        if problems:
            print(f"{len(problems)} generated file(s) out of date or left over: run `{parser.prog}`",
                  file=sys.stderr)
            return EXIT_STALE
        print(f"{len(files)} generated files match {shown} (fingerprint {spec.short_fingerprint})")
        return 0
    try:
        changed = write_atomically(files, opts.out)
    except OSError as exc:  # a folder that cannot be made or written: a usage error, as argparse's are
        where = display_path(Path(exc.filename)) if exc.filename else display_path(opts.out)
        print(f"{parser.prog}: error: --out {display_path(opts.out)}: cannot write {where}: {exc.strerror}; "
              "no file was written", file=sys.stderr)
        return EXIT_INVALID
    print(f"{len(files)} files from {shown} (fingerprint {spec.short_fingerprint}) in {display_path(opts.out)}/: "
          f"{len(changed)} changed")
    refreshed = precompiled.refresh(envs)  # after edited templates, so that the next run need not compile them
    if refreshed:
        print(f"{len(refreshed)} precompiled template(s) rewritten in {display_path(precompiled.PRECOMPILED)}/")
    return 0


def diff_main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(
        prog=f"{program()} diff",
        description="List what changed between two versions of the protocol; exit 1 if a change breaks a peer "
                    "built from OLD, 2 if a spec is invalid.")
    parser.add_argument("old", type=Path, help="the old spec, or a generated contract.json")
    parser.add_argument("new", type=Path, nargs="?", default=DEFAULT_SPEC, help="the new spec (default: %(default)s)")
    opts = parser.parse_args(argv)
    try:
        old, new = _contract_of(opts.old), _contract_of(opts.new)
    except BrokenContract as exc:
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except SpecInvalid as exc:
        _report(display_path(exc.errors[0].location.file) if exc.errors else "spec", exc)
        return EXIT_INVALID
    changes = diff(old, new)
    for change in changes:
        print(change)
    breaks = sum(c.breaking for c in changes)
    version = f"version {old.get('version')} -> {new.get('version')}"
    if breaks and new.get("version", 0) <= old.get("version", 0):
        version += ": the version must rise"
    print(f"{breaks} breaking, {len(changes) - breaks} compatible change{'s' if len(changes) - breaks != 1 else ''}"
          f" ({version})")
    return EXIT_BREAKING if breaks else 0


def _report(shown: str, exc: SpecInvalid) -> None:
    count = len(exc.errors)
    print(f"{shown}: {count} error{'s' if count != 1 else ''}; nothing was written", file=sys.stderr)
    for error in exc.errors:
        print(error, file=sys.stderr)


class BrokenContract(Exception):
    """A contract.json that is there but unreadable: the version check it feeds would be skipped unseen."""


def _previous_contract(file: Path) -> Contract | None:
    """The contract in a generated contract.json; None if there is no such file or it holds no contract (another
    tool's JSON). Raises BrokenContract if it does not parse or is not the shape the generator writes."""
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except OSError:
        return None
    except ValueError as exc:  # not UTF-8 or not JSON: a merge's conflict markers, a hand edit
        raise BrokenContract(f"{display_path(file)} is not valid JSON ({exc})") from exc
    found = data.get("contract") if isinstance(data, dict) else None
    if found is None:
        return None
    problem = contract_problem(found)
    if problem is not None:
        raise BrokenContract(f"{display_path(file)} is not a contract the generator wrote: {problem}")
    checked: Contract = found
    return checked


def _contract_of(path: Path) -> Contract:
    found = _previous_contract(path) if path.suffix == ".json" else None
    return found if found is not None else contract(load_spec(path))
