"""The generator's writing phase is all or nothing: a run cut off before its commit point leaves the old
files, one cut off after it is finished by the next run; the next run removes any staging folder or stray
temporary file, ``--check`` reports them, and ``.gitignore`` covers them. A handful of real SIGKILLs too
(``make bench-sidechan`` runs 200)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from generator.writing import MANIFEST, STAGING, debris, recover, stale_files, write_atomically

REPO = Path(__file__).resolve().parents[2]
OLD = {"a.txt": b"old a\n", "sub/b.txt": b"old b\n", "sub/deep/c.txt": b"old c\n", "same.txt": b"same\n"}
NEW = {"a.txt": b"new a\n", "sub/b.txt": b"new b\n", "sub/deep/c.txt": b"new c\n", "same.txt": b"same\n"}


def _on_disk(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*") if p.is_file()}


@pytest.fixture
def out(tmp_path: Path) -> Path:
    folder = tmp_path / "generated"
    write_atomically(OLD, folder)
    assert _on_disk(folder) == OLD
    return folder


def test_a_run_cut_off_while_staging_leaves_the_old_files_and_no_staging(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = []

    def write_bytes(self: Path, data: bytes) -> int:
        calls.append(self)
        if len(calls) == 2:
            raise KeyboardInterrupt  # Ctrl-C between two files
        return Path.write_text(self, data.decode())

    monkeypatch.setattr(Path, "write_bytes", write_bytes)
    with pytest.raises(KeyboardInterrupt):
        write_atomically(NEW, out)
    assert _on_disk(out) == OLD and not (out / STAGING).exists()


def test_a_run_cut_off_after_its_commit_point_is_reported_then_finished(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = os.replace
    moves = []

    def replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
        if Path(dst).name != MANIFEST:
            moves.append(dst)
            if len(moves) == 2:
                raise SystemExit("killed")  # after the commit point, between two moves
        real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(SystemExit):
        write_atomically(NEW, out)
    monkeypatch.setattr(os, "replace", real)
    mixed = _on_disk(out)
    assert mixed["a.txt"] == NEW["a.txt"] and mixed["sub/b.txt"] == OLD["sub/b.txt"]  # cut mid-move
    assert (out / STAGING / MANIFEST).is_file()
    assert stale_files(NEW, out)[0].startswith(f"interrupted: {out / STAGING}")
    assert write_atomically(NEW, out) == []  # the next run finishes the cut-off one: nothing left to change
    assert _on_disk(out) == NEW and debris(out) == []


def test_stray_temporary_files_and_a_staging_folder_are_reported_and_removed(out: Path) -> None:
    strays = [out / "sub" / ".b.txt.k2j3.tmp", out / ".a.txt.x9.tmp"]
    for stray in strays:
        stray.write_bytes(b"half")
    (out / STAGING / "files").mkdir(parents=True)
    (out / STAGING / "files" / "a.txt").write_bytes(b"new a\n")  # staged, never committed
    assert debris(out) == [f"debris: {out / STAGING} (a run was cut off before its files were ready; the next "
                           "run removes it)", *(f"debris: {p}" for p in sorted(strays))]
    assert len(recover(out)) == 3
    assert _on_disk(out) == OLD and debris(out) == []


def test_check_reports_debris_in_the_real_output_folder(tmp_path: Path) -> None:
    out = tmp_path / "generated"
    run = [sys.executable, "-m", "generator", "--out", str(out)]
    assert subprocess.run(run, cwd=REPO, capture_output=True, check=False).returncode == 0
    (out / "python" / ".stray.py.abc.tmp").write_bytes(b"")
    check = subprocess.run([*run, "--check"], cwd=REPO, capture_output=True, text=True, check=False)
    assert check.returncode == 1 and f"debris: {out / 'python' / '.stray.py.abc.tmp'}" in check.stdout
    assert subprocess.run(run, cwd=REPO, capture_output=True, check=False).returncode == 0
    assert subprocess.run([*run, "--check"], cwd=REPO, capture_output=True, check=False).returncode == 0


@pytest.mark.parametrize("path", ["generated/.generator-staging/files/python/x.py", "generated/python/.x.py.k2.tmp"])
def test_gitignore_covers_the_debris(path: str) -> None:
    assert subprocess.run(["git", "check-ignore", "-q", path], cwd=REPO, check=False).returncode == 0


def test_a_handful_of_real_kills_leave_nothing_mixed_and_no_debris_after_the_next_run() -> None:
    run = subprocess.run([sys.executable, "-m", "bench.sidechan.generator_kills", "--kills", "6", "--seed", "7",
                          "--json"], cwd=REPO, capture_output=True, text=True, check=True, timeout=600)
    counts = json.loads(run.stdout)
    # a kill in the few milliseconds of moving files into place leaves a mix with its committed manifest
    assert counts["all_old"] + counts["all_new"] + counts["mixed"] == 6, counts
    assert counts["mixed_without_manifest"] == counts["corrupt"] == counts["not_new_after_next_run"] == 0, counts
    assert counts["debris_after_next_run"] == 0, counts
