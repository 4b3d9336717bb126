"""The generator's writing phase is all or nothing at every instant: the new output folder is built beside the
old one and the two are exchanged in one step, keeping what else lived in the folder; a run cut off before the
exchange leaves the old files, one cut off after it the new ones. Where the exchange is not supported, the
journalled fallback: a run cut off after its commit point is finished by the next run. The next run removes
the folder beside, any staging folder or stray temporary file; ``--check`` reports them and ``.gitignore``
covers them. A handful of real SIGKILLs too (``make bench-sidechan`` runs 200)."""

from __future__ import annotations

import ctypes
import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from generator import writing
from generator.writing import MANIFEST, STAGING, beside, debris, exchange, recover, stale_files, write_atomically

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
    assert _on_disk(out) == OLD and not (out / STAGING).exists() and not beside(out).exists()


def test_the_new_folder_replaces_the_old_in_one_exchange_keeping_what_else_lived_there(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (out / "__pycache__").mkdir()
    (out / "__pycache__" / "x.pyc").write_bytes(b"bytecode")
    (out / "notes.txt").write_bytes(b"mine")
    (out / "link").symlink_to("a.txt")
    kept = {"__pycache__/x.pyc": b"bytecode", "notes.txt": b"mine", "link": NEW["a.txt"]}
    same_inode = (out / "same.txt").stat().st_ino
    seen = []

    def watched(a: Path, b: Path) -> bool:
        seen.append(_on_disk(b))  # the output folder just before the exchange
        done = exchange(a, b)
        seen.append(_on_disk(b))
        return done

    monkeypatch.setattr(writing, "exchange", watched)
    assert write_atomically(NEW, out) == ["a.txt", "sub/b.txt", "sub/deep/c.txt"]
    assert seen == [OLD | kept | {"link": OLD["a.txt"]}, NEW | kept]
    assert _on_disk(out) == NEW | kept and (out / "link").is_symlink()
    assert (out / "same.txt").stat().st_ino == same_inode  # hard-linked, not copied
    assert not beside(out).exists() and debris(out) == []


def test_a_run_cut_off_after_the_exchange_leaves_the_new_files_and_the_next_run_removes_the_old(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def killed(path: Path) -> None:
        raise SystemExit("killed")  # before the old folder, now beside, is removed

    monkeypatch.setattr(writing, "_remove", killed)
    with pytest.raises(SystemExit):
        write_atomically(NEW, out)
    monkeypatch.undo()
    assert _on_disk(out) == NEW and _on_disk(beside(out)) == OLD
    assert debris(out) == [f"debris: {beside(out)} (a run was cut off while building the new output folder or "
                           "removing the old one; the next run removes it)"]
    assert write_atomically(NEW, out) == [] and not beside(out).exists() and _on_disk(out) == NEW


def test_a_half_built_folder_beside_is_reported_and_removed(out: Path) -> None:
    (beside(out) / "sub").mkdir(parents=True)
    (beside(out) / "sub" / "b.txt").write_bytes(NEW["sub/b.txt"])  # a run killed while building
    assert _on_disk(out) == OLD and len(debris(out)) == 1
    assert recover(out) == [f"removed {beside(out)}, left by a cut-off run"]
    assert not beside(out).exists() and _on_disk(out) == OLD


def test_exchange_swaps_two_folders_in_one_call(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "x").write_bytes(b"from a")
    (b / "y").write_bytes(b"from b")
    assert exchange(a, b)  # Linux with glibc 2.28 or later, on a file system that supports it (tmpfs, ext4)
    assert [p.name for p in a.iterdir()] == ["y"] and [p.name for p in b.iterdir()] == ["x"]


def test_without_the_exchange_the_journalled_moves_write_the_new_files(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(writing, "exchange", lambda a, b: False)
    assert write_atomically(NEW, out) == ["a.txt", "sub/b.txt", "sub/deep/c.txt"]
    assert _on_disk(out) == NEW and debris(out) == [] and not beside(out).exists()


def test_a_journalled_run_cut_off_after_its_commit_point_is_reported_then_finished(
    out: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(writing, "exchange", lambda a, b: False)
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
    beside(out).mkdir()
    check = subprocess.run([*run, "--check"], cwd=REPO, capture_output=True, text=True, check=False)
    assert check.returncode == 1 and f"debris: {out / 'python' / '.stray.py.abc.tmp'}" in check.stdout
    assert f"debris: {beside(out)} " in check.stdout
    assert subprocess.run(run, cwd=REPO, capture_output=True, check=False).returncode == 0
    assert subprocess.run([*run, "--check"], cwd=REPO, capture_output=True, check=False).returncode == 0


@pytest.mark.parametrize("path", [".generated.generator-new/python/x.py",
                                  "generated/.generator-staging/files/python/x.py", "generated/python/.x.py.k2.tmp"])
def test_gitignore_covers_the_debris(path: str) -> None:
    assert subprocess.run(["git", "check-ignore", "-q", path], cwd=REPO, check=False).returncode == 0


def test_a_handful_of_real_kills_leave_nothing_mixed_and_no_debris_after_the_next_run() -> None:
    run = subprocess.run([sys.executable, "-m", "bench.sidechan.generator_kills", "--kills", "1", "--aimed", "3",
                          "--seed", "7", "--json"], cwd=REPO, capture_output=True, text=True, check=True, timeout=600)
    found = json.loads(run.stdout)
    for kills, counts in ((1, found["spread"]), (3, found["aimed"])):  # aimed: while the folder beside exists
        assert counts["all_old"] + counts["all_new"] == kills, counts
        assert counts["mixed"] == counts["corrupt"] == counts["other_files_lost"] == 0, counts
        assert counts["not_new_after_next_run"] == counts["debris_after_next_run"] == 0, counts


@pytest.mark.parametrize("err", [errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP, errno.EBUSY, errno.EXDEV])
def test_an_exchange_the_system_refuses_falls_back_to_the_journalled_moves(
    out: Path, monkeypatch: pytest.MonkeyPatch, err: int
) -> None:
    class Libc:
        @staticmethod
        def renameat2(*args: object) -> int:
            ctypes.set_errno(err)
            return -1

    monkeypatch.setattr(ctypes, "CDLL", lambda *a, **k: Libc())
    assert write_atomically(NEW, out) == ["a.txt", "sub/b.txt", "sub/deep/c.txt"]
    assert _on_disk(out) == NEW and debris(out) == [] and not beside(out).exists()
