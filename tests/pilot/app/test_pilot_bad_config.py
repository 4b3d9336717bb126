"""Any malformed config file gets one line naming the file and the problem, exit 2, no traceback: nesting
10,000 deep, UTF-16, Latin-1, YAML tags, huge numbers, wrong types, broken YAML, binary junk (over 100 contents,
from bench.sidechan.bad_configs, whose bench runs them in real processes), and what is no config file at all (a
folder, a FIFO, a symlink loop...). An unwritable ``--record`` folder is refused at start."""

from __future__ import annotations

import contextlib
import os
import threading
from pathlib import Path

import pytest
from cli_rig import call

from bench.sidechan.bad_configs import contents, make_files

CASES = contents()


def _unblock(fifo: str) -> None:
    with contextlib.suppress(OSError):  # no reader any more (ENXIO): nothing to unblock
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))


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
    assert err.count("\n") == 1 and err.startswith(f"pilot: error: {path}") and len(err) < 1000, (name, err)
    assert sorted(tmp_path.iterdir()) == before  # nothing written


@pytest.mark.parametrize("kind", ["an unreadable file", "a folder", "a FIFO", "a symlink loop", "a dangling symlink",
                                  "a path through a file", "no such file", "a name with a newline",
                                  "a character device of zeros"])
def test_what_is_no_config_file_is_one_line_exit_2(kind: str, tmp_path: Path) -> None:
    path = dict(make_files(tmp_path, kinds_only=True))[kind]
    if kind == "a FIFO":  # were the pilot waiting for a writer, the test fails in 3 s rather than hanging
        threading.Timer(3.0, _unblock, (path,)).start()
    code, out, err = call("--config", path, "--max-seconds", "1", "--no-status")
    assert "Traceback" not in out + err
    assert code == 2 and err.count("\n") == 1 and err.startswith("pilot: error: "), (kind, out, err)


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


@pytest.mark.parametrize("folder", ["", "  "])
def test_record_into_an_empty_name_is_refused_not_ignored(folder: str) -> None:
    code, out, err = call("--record", folder, "--max-seconds", "1", "--no-status")
    assert code == 2 and out == ""  # it flew without recording before
    assert err == "pilot: error: option --record: expected a folder, got an empty name\n", err
