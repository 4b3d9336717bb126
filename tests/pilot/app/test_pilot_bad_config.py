"""Any malformed config file gets one line naming the file and the problem, exit 2, no traceback: nesting
10,000 deep, UTF-16, Latin-1, YAML tags, huge numbers, wrong types, broken YAML (over 100 files, generated
here). An unwritable ``--record`` folder (one that exists on a read-only file system) is refused at start."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from cli_rig import call

OPTIONS = {  # one option of each kind, and a value of each wrong type for it
    "controller.fire_ms": "int", "controller.dead_band_x": "float", "detector": "str",
    "hsv.ranges": "ranges", "link.rate_hz": "float", "aruco.marker_id": "int", "vision.bridge_frames": "int",
}
VALID = {("float", "1.5"), ("int", "-7")}  # of the right type: for the options above, -7 is only wrong for some
WRONG = ["'text'", "[1, 2]", "{a: 1}", "true", "null", "1.5", "-7", "''", "[[1, 2, 3], [4, 5]]"]


def _nested(option: str, value: str) -> str:
    head, _, leaf = option.rpartition(".")
    return f"{head}:\n  {leaf}: {value}\n" if head else f"{leaf}: {value}\n"


def malformed() -> list[tuple[str, bytes]]:
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
              ("random bytes", random.Random(53).randbytes(4000)), ("control characters", b"detector: \x07\x1b\n")]
    for tag in ("!!python/object/apply:os.system ['true']", "!!python/name:os.system", "!!binary aGVsbG8=",
                "!!set {a, b}", "!!timestamp 2001-12-14", "!!omap [a: 1]", "!custom 5", "!!float abc", "!!int x",
                "!!str", "!!python/tuple [1, 2]", "!!pairs [a: 1]"):
        cases.append((f"tag {tag}", f"controller:\n  fire_ms: {tag}\n".encode()))
        cases.append((f"top-level tag {tag}", f"{tag}\n".encode()))
    for big in ("1e999", "-1e999", "9" * 5000, "-" + "9" * 4000, "9" * 400, ".nan", ".inf", "-.inf", "0x" + "f" * 3000):
        for option in ("controller.fire_ms", "controller.dead_band_x", "link.rate_hz"):
            cases.append((f"{option} = {big[:8]} ({len(big)} chars)", _nested(option, big).encode()))
    for option, kind in OPTIONS.items():
        for value in WRONG:
            if (kind, value) in VALID:
                continue
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
        ("directive", b"%YAML 9.9\n---\na: 1\n"), ("bad escape", b"detector: \"\\q\"\n"),
        ("record_failure", b"record_failure: crash\n"),
        ("range upside down", b"hsv:\n  ranges: [[[9, 0, 0], [1, 0, 0]]]\n"),
    ]
    return cases


CASES = malformed()


def test_there_are_over_a_hundred_distinct_cases() -> None:
    assert len(CASES) >= 100 and len({name for name, _ in CASES}) == len(CASES)


@pytest.mark.parametrize(("name", "content"), CASES, ids=[name for name, _ in CASES])
def test_a_malformed_config_is_one_line_naming_the_file_exit_2(name: str, content: bytes, tmp_path: Path) -> None:
    path = tmp_path / "pilot.yaml"
    path.write_bytes(content)
    before = sorted(tmp_path.iterdir())
    code, out, err = call("--config", str(path), "--max-seconds", "1", "--no-status")
    assert "Traceback" not in out + err
    assert code == 2, (name, out, err)
    assert err.count("\n") == 1 and err.startswith(f"pilot: error: {path}") and len(err) < 400, (name, err)
    assert sorted(tmp_path.iterdir()) == before  # nothing written


@pytest.mark.parametrize(("content", "said"), [
    ("# café\n".encode("latin-1"), "is not UTF-8 (byte 0xe9"), ("a: 1\n".encode("utf-16"), "saved as UTF-16"),
    (b"a: " + b"[" * 10_000 + b"]" * 10_000, "nested too deep"), (b"detector: [1\n", ":2:1: not valid YAML:"),
    (b"link:\n  rate_hz: " + b"9" * 400 + b"\n", "'link.rate_hz' is too large a number"),
    (b"controller:\n  fire_ms: !!binary aGVsbG8=\n", "must be an integer, got b'hello'"),
])
def test_the_line_says_what_is_wrong(content: bytes, said: str, tmp_path: Path) -> None:
    path = tmp_path / "pilot.yaml"
    path.write_bytes(content)
    code, _, err = call("--config", str(path), "--max-seconds", "1")
    assert code == 2 and said in err, err


def test_record_into_an_existing_folder_that_cannot_be_written_is_refused_at_start() -> None:
    # /sys exists and is a folder, but no file can be made in it (sysfs), even by root: like a read-only disk
    code, out, err = call("--record", "/sys", "--max-seconds", "1", "--no-status")
    assert code == 2 and out == ""
    assert err.startswith("pilot: error: option --record: cannot write into '/sys': ") and err.count("\n") == 1, err
