"""Malformed pilot config files, and the bench that feeds every one of them to the real ``python -m pilot``.

``contents()`` is the generated set of bad file contents (nesting, encodings, YAML tags, huge numbers, wrong
types, broken YAML, binary junk); ``make_files`` writes them into a folder and adds what no content can be: a
folder, a FIFO, a symlink loop, a dangling link, a path through a file, a name with a newline, an unreadable
file. The test (tests/pilot/app/test_pilot_bad_config.py) calls the pilot in-process on them; the bench runs each
in its own process, as a user would, and counts tracebacks, exit codes other than 2, lines other than one, hangs.

    python -m bench.sidechan.bad_configs     (writes bench/sidechan/RESULTS-bad-configs.md)
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

OPTIONS = {  # one option of each kind, and a value of each wrong type for it
    "controller.fire_ms": "int", "controller.dead_band_x": "float", "detector": "str",
    "hsv.ranges": "ranges", "link.rate_hz": "float", "aruco.marker_id": "int", "vision.bridge_frames": "int",
}
VALID = {("float", "1.5"), ("int", "-7")}  # of the right type: for the options above, -7 is only wrong for some
WRONG = ["'text'", "[1, 2]", "{a: 1}", "true", "null", "1.5", "-7", "''", "[[1, 2, 3], [4, 5]]"]
TAGS = ("!!python/object/apply:os.system ['true']", "!!python/name:os.system", "!!binary aGVsbG8=", "!!set {a, b}",
        "!!timestamp 2001-12-14", "!!omap [a: 1]", "!custom 5", "!!float abc", "!!int x", "!!str",
        "!!python/tuple [1, 2]", "!!pairs [a: 1]")
WRITE_ONLY = "/proc/sys/vm/compact_memory"  # mode 0200: unreadable even by root
HUGE = ("1e999", "-1e999", "9" * 5000, "-" + "9" * 4000, "9" * 400, ".nan", ".inf", "-.inf", "0x" + "f" * 3000)


def _nested(option: str, value: str) -> str:
    head, _, leaf = option.rpartition(".")
    return f"{head}:\n  {leaf}: {value}\n" if head else f"{leaf}: {value}\n"


def contents() -> list[tuple[str, bytes]]:
    """(name, bytes) of every malformed content, names distinct."""
    cases: list[tuple[str, bytes]] = []
    for depth in (1_000, 10_000):
        cases += [(f"flow nesting {depth}", ("a: " + "[" * depth + "]" * depth + "\n").encode()),
                  (f"mapping nesting {depth}", ("a: " + "{b: " * depth + "1" + "}" * depth + "\n").encode())]
    cases.append(("block nesting 3000", "".join(f"{' ' * i}k{i}:\n" for i in range(3000)).encode()))
    cases.append(("known option nested 900", ("hsv:\n  ranges: " + "[" * 900 + "]" * 900 + "\n").encode()))
    text = "# café\ncontroller:\n  fire_ms: 1500\n"
    for codec in ("utf-16", "utf-16-le", "utf-16-be", "utf-32", "latin-1", "cp1252"):
        cases.append((f"encoded {codec}", text.encode(codec)))
    cases += [("cp1252 quote", "detector: \u2019hsv\u2019\n".encode("cp1252")),
              ("invalid utf-8 in a value", b"detector: hs\xc3\x28v\n"), ("NUL bytes", b"detector: h\x00sv\n"),
              ("random bytes", random.Random(53).randbytes(4000)), ("control characters", b"detector: \x07\x1b\n"),
              ("UTF-8 BOM then a wrong value", b"\xef\xbb\xbfdetector: 5\n"),
              ("two BOMs", b"\xef\xbb\xbf" * 2 + b"a: 1\n"),
              ("gzip bytes", b"\x1f\x8b\x08\x00" + random.Random(54).randbytes(300)),
              ("PNG header", b"\x89PNG\r\n\x1a\n" + bytes(200)), ("lone surrogate escape", b"detector: \"\\ud800\"\n")]
    for tag in TAGS:
        cases.append((f"tag {tag}", f"controller:\n  fire_ms: {tag}\n".encode()))
        cases.append((f"top-level tag {tag}", f"{tag}\n".encode()))
    for big in HUGE:
        for option in ("controller.fire_ms", "controller.dead_band_x", "link.rate_hz"):
            cases.append((f"{option} = {big[:8]} ({len(big)} chars)", _nested(option, big).encode()))
    for option, kind in OPTIONS.items():
        for value in WRONG:
            if (kind, value) not in VALID:
                cases.append((f"{option} = {value}", _nested(option, value).encode()))
    cases += [
        ("top-level list", b"- a\n- b\n"), ("top-level scalar", b"hello\n"), ("two documents", b"a: 1\n---\nb: 2\n"),
        ("undefined alias", b"detector: *nowhere\n"), ("tab indentation", b"controller:\n\tfire_ms: 1\n"),
        ("unclosed quote", b"detector: 'hsv\n"), ("unclosed flow", b"hsv: {ranges: [1, 2\n"),
        ("complex key", b"? [a, b]\n: 1\n"), ("mapping key", b"{a: 1}: 2\n"), ("bad merge", b"<<: 5\n"),
        ("billion laughs", b"a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                           b"c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
                           b"e: [*d, *d, *d, *d, *d, *d, *d, *d, *d]\n"),
        ("huge string", b"detector: " + b"x" * 200_000 + b"\n"), ("two megabytes", b"# " + b"x" * 2_000_000 + b"\n"),
        ("unknown option with a newline", b"\"a\\nb\": 1\n"), ("null key", b"~: 1\n"), ("bool key", b"true: 1\n"),
        ("integer key", b"1: 2\n"), ("float key in a section", b"controller:\n  1.5: 2\n"),
        ("directive", b"%YAML 9.9\n---\na: 1\n"), ("bad escape", b"detector: \"\\q\"\n"),
        ("record_failure", b"record_failure: crash\n"),
        ("range upside down", b"hsv:\n  ranges: [[[9, 0, 0], [1, 0, 0]]]\n"),
        ("section is a scalar", b"controller: 5\n"), ("section is a list", b"controller: [1, 2]\n"),
        ("section is a string", b"hsv: ranges\n"), ("duplicate section, second wrong", b"link: {}\nlink: 3\n"),
        ("anchor cycle through merge", b"a: &a {<<: *a}\n"), ("only a document end", b"...\n...\n"),
    ]
    return cases


def make_files(root: Path, *, kinds_only: bool = False) -> list[tuple[str, str]]:
    """Writes every case under ``root`` (only what is no file, with ``kinds_only``): (name, path for --config)."""
    root.mkdir(parents=True, exist_ok=True)
    made: list[tuple[str, str]] = []
    for i, (name, data) in enumerate([] if kinds_only else contents()):
        path = root / f"case{i:03d}.yaml"
        path.write_bytes(data)
        made.append((name, str(path)))
    kinds = root / "kinds"
    kinds.mkdir(exist_ok=True)
    (kinds / "folder.yaml").mkdir(exist_ok=True)
    fifo = kinds / "fifo.yaml"
    if not fifo.exists():
        os.mkfifo(fifo)
    for link, target in (("loop.yaml", "loop.yaml"), ("dangling.yaml", "nowhere/pilot.yaml")):
        if not (kinds / link).is_symlink():
            (kinds / link).symlink_to(target)
    (kinds / "plain").write_text("detector: hsv\n")
    newline = kinds / "two\nlines.yaml"
    newline.write_bytes(b"detector: 5\n")
    unreadable = kinds / "unreadable.yaml"
    unreadable.unlink(missing_ok=True)  # a mode-0 file from an earlier run cannot be written again
    unreadable.write_text("detector: hsv\n")
    unreadable.chmod(0)
    if os.geteuid() == 0 and Path(WRITE_ONLY).exists():  # root reads any mode-0 file; not this one
        unreadable = Path(WRITE_ONLY)
    made += [("an unreadable file", str(unreadable)), ("a folder", str(kinds / "folder.yaml")), ("a FIFO", str(fifo)),
             ("a symlink loop", str(kinds / "loop.yaml")), ("a dangling symlink", str(kinds / "dangling.yaml")),
             ("a path through a file", str(kinds / "plain" / "pilot.yaml")),
             ("no such file", str(kinds / "missing.yaml")), ("a name with a newline", str(newline)),
             ("a character device of zeros", "/dev/zero")]
    return made


def run_one(path: str, timeout: float) -> tuple[int | None, str, str, float]:
    """The real pilot on one config: (exit code or None if it hung, stdout, stderr, seconds)."""
    t0 = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, "-m", "pilot", "--config", path, "--max-seconds", "1", "--no-status"],
                              cwd=REPO, capture_output=True, text=True, errors="replace", timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode(errors="replace") if isinstance(exc.stdout, bytes) else ""
        err = exc.stderr.decode(errors="replace") if isinstance(exc.stderr, bytes) else ""
        return None, out, err, time.perf_counter() - t0
    return done.returncode, done.stdout, done.stderr, time.perf_counter() - t0


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="bad_configs")
    p.add_argument("--dir", default="/tmp/pilot-bad-configs", help="where the cases are written")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--timeout", type=float, default=30.0, help="seconds before a run counts as hung")
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args(argv)
    cases = make_files(Path(args.dir))
    t0 = time.perf_counter()
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda c: run_one(c[1], args.timeout), cases))
    wall = time.perf_counter() - t0
    bad: list[str] = []
    tracebacks = hung = not_two = not_one_line = 0
    for (name, path), (code, out, err, _) in zip(cases, results, strict=True):
        problems = []
        if "Traceback" in out + err:
            tracebacks += 1
            problems.append("traceback")
        if code is None:
            hung += 1
            problems.append("hung")
        elif code != 2:
            not_two += 1
            problems.append(f"exit {code}")
        if err.count("\n") != 1 or not err.startswith("pilot: error: "):
            not_one_line += 1
            problems.append(f"{err.count(chr(10))} lines")
        if problems:
            bad.append(f"- {name} ({path!r}): {', '.join(problems)}: {(err or out).strip()[:200]!r}")
    slowest = max(r[3] for r in results)
    line = (f"{len(cases)} malformed configs, each in its own `python -m pilot --config FILE` process: "
            f"{tracebacks} tracebacks, {hung} hung ({args.timeout:g} s), {not_two} exit codes other than 2, "
            f"{not_one_line} answers other than one `pilot: error:` line; slowest {slowest:.1f} s, "
            f"{wall:.0f} s in all with {args.jobs} at a time (load average {os.getloadavg()[0]:.1f}).")
    text = "\n".join(["# Malformed config files (`python -m bench.sidechan.bad_configs`)", "", line, "",
                      *(bad or ["Every case: exit 2 and one line naming the file."]), ""])
    print(text)
    if not args.no_write:
        (HERE / "RESULTS-bad-configs.md").write_text(text)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
