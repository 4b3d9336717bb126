"""The generator's writing phase: a run killed at any instant leaves the output folder all old or all new.

The complete new folder is built beside the old one (``.NAME.generator-new/``): changed files written, every
other file (unchanged outputs, and what else lives there: ``__pycache__``, a user's notes) hard-linked, so it
costs little; then the two folders are exchanged in one step (Linux ``renameat2(RENAME_EXCHANGE)``) and the
old one, now under that name, is removed. The next run removes such a folder left by a cut-off run, and
``--check`` reports it as debris.

Where the exchange is not supported (not Linux, glibc before 2.28, a file system without it) the files move
in one by one, journalled: staged in ``.generator-staging/`` inside the output folder, then a manifest
(``COMMIT``) renamed into place as the commit point, then moved. A run killed during the moves leaves a mix
that the next run completes (roll forward): all old or all new only once that run has finished.
"""

from __future__ import annotations

import errno
import fnmatch
import json
import os
import shutil
import sys
from pathlib import Path

STAGING = ".generator-staging"  # inside the output folder: the journalled fallback
MANIFEST = "COMMIT"
STRAY = ".*.tmp"  # temporary files of an older generator's writing scheme
BESIDE = ".generator-new"  # the suffix of the folder built beside the output folder: .NAME.generator-new


def beside(out_dir: Path) -> Path:
    """Where the new output folder is built, and where the old one lies between the exchange and its removal."""
    real = out_dir.resolve()
    return real.with_name(f".{real.name}{BESIDE}")


def stale_files(files: dict[str, bytes], out_dir: Path) -> list[str]:
    """Paths whose content on disk differs from `files`, each with why, and the debris of a cut-off run."""
    problems = debris(out_dir)
    for rel, content in sorted(files.items()):
        path = out_dir / rel
        if not path.exists():
            problems.append(f"missing: {path}")
        elif path.read_bytes() != content:
            problems.append(f"stale: {path}")
    return problems


def debris(out_dir: Path) -> list[str]:
    """What a killed run left: the folder beside, a staging folder (committed or not), stray temporary files."""
    found = []
    if os.path.lexists(beside(out_dir)):
        found.append(f"debris: {beside(out_dir)} (a run was cut off while building the new output folder or "
                     "removing the old one; the next run removes it)")
    staging = out_dir / STAGING
    if (staging / MANIFEST).is_file():
        found.append(f"interrupted: {staging} (a run was cut off while moving its files into place; the next "
                     "run finishes it)")
    elif staging.exists():
        found.append(f"debris: {staging} (a run was cut off before its files were ready; the next run removes it)")
    if out_dir.is_dir():
        found += [f"debris: {tmp}" for tmp in sorted(out_dir.rglob(STRAY)) if STAGING not in tmp.parts]
    return found


def recover(out_dir: Path) -> list[str]:
    """Remove the folder beside, finish a committed journalled run or drop an uncommitted one, and remove stray
    temporary files; returns what was done, one line each."""
    done = []
    if os.path.lexists(beside(out_dir)):
        _remove(beside(out_dir))
        done.append(f"removed {beside(out_dir)}, left by a cut-off run")
    staging = out_dir / STAGING
    manifest = staging / MANIFEST
    if manifest.is_file():
        moved = _move_into_place(json.loads(manifest.read_text(encoding="utf-8")), staging, out_dir)
        done.append(f"finished a run cut off while moving its files: {moved} moved into {out_dir}")
    elif staging.exists():
        done.append(f"removed {staging}, left by a run cut off before its files were ready")
    shutil.rmtree(staging, ignore_errors=True)
    if out_dir.is_dir():
        for tmp in sorted(out_dir.rglob(STRAY)):
            tmp.unlink(missing_ok=True)
            done.append(f"removed {tmp}, a temporary file of a cut-off run")
    return done


def write_atomically(files: dict[str, bytes], out_dir: Path) -> list[str]:
    """Write every changed file or none; returns the paths that changed."""
    recover(out_dir)
    changed = [rel for rel in sorted(files)
               if not (out_dir / rel).exists() or (out_dir / rel).read_bytes() != files[rel]]
    if changed and not _swap_in(files, changed, out_dir):
        _write_journalled(files, changed, out_dir)
    return changed


def _swap_in(files: dict[str, bytes], changed: list[str], out_dir: Path) -> bool:
    """Build the new folder beside the old one and exchange them; False, nothing changed, where that cannot be
    done (no exchange on this system, a parent folder that is not writable)."""
    new, real = beside(out_dir), out_dir.resolve()
    try:
        real.parent.mkdir(parents=True, exist_ok=True)
        new.mkdir()
    except OSError as exc:
        if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS) and real.is_dir():
            return False  # the output folder may still be writable: the journalled moves
        raise
    had_old = real.is_dir()
    try:
        if had_old:
            _link_tree(real, new)
        for rel in changed:
            dest = new / rel
            dest.parent.mkdir(parents=True, exist_ok=True)
            dest.unlink(missing_ok=True)  # a hard link to the old file: never write through it
            dest.write_bytes(files[rel])
            os.chmod(dest, 0o644)
        if not had_old:
            os.rename(new, real)  # no old folder: a plain rename is one step
            return True
        if not exchange(new, real):
            _remove(new)
            return False
    except BaseException:
        _remove(new)
        raise
    _remove(new)  # the old folder, now beside
    return True


def _link_tree(src: Path, dest: Path) -> None:
    """Fill `dest` with the tree of `src`, its files as hard links (copies where linking fails); the debris of
    the journalled fallback is left out."""
    shutil.copystat(src, dest)
    for entry in os.scandir(src):
        target = dest / entry.name
        if entry.name == STAGING or fnmatch.fnmatch(entry.name, STRAY):  # the debris the next run removes
            continue
        if entry.is_symlink():
            os.symlink(os.readlink(entry.path), target)
        elif entry.is_dir():
            target.mkdir()
            _link_tree(Path(entry.path), target)
        else:
            try:
                os.link(entry.path, target, follow_symlinks=False)
            except OSError:  # a file system without hard links, or another device mounted inside
                shutil.copy2(entry.path, target, follow_symlinks=False)


def _remove(path: Path) -> None:
    if path.is_symlink() or path.is_file():
        path.unlink(missing_ok=True)
    else:
        shutil.rmtree(path, ignore_errors=True)  # what stays is debris: --check reports it, the next run retries


def exchange(a: Path, b: Path) -> bool:
    """Swap the two paths in one step (renameat2 with RENAME_EXCHANGE); False where the system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes  # only when a run writes

    libc = ctypes.CDLL(None, use_errno=True)
    renameat2 = getattr(libc, "renameat2", None)  # glibc 2.28 and later
    if renameat2 is None:
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    # an old kernel, a file system without it, an output folder that is a mount point (or on another device
    # than its parent folder)
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP, errno.EBUSY, errno.EXDEV):
        return False
    raise OSError(err, os.strerror(err), str(a), None, str(b))


def _write_journalled(files: dict[str, bytes], changed: list[str], out_dir: Path) -> None:
    staging = out_dir / STAGING
    try:
        for rel in changed:
            dest = staging / "files" / rel
            dest.parent.mkdir(parents=True, exist_ok=True)
            dest.write_bytes(files[rel])
            os.chmod(dest, 0o644)
        pending = staging / ".manifest-pending"
        pending.write_text(json.dumps(changed), encoding="utf-8")
        os.replace(pending, staging / MANIFEST)  # the commit point
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    _move_into_place(changed, staging, out_dir)
    shutil.rmtree(staging)


def _move_into_place(rels: list[str], staging: Path, out_dir: Path) -> int:
    moved = 0
    for rel in rels:
        src = staging / "files" / rel
        if src.exists():  # else moved before the cut
            (out_dir / rel).parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, out_dir / rel)
            moved += 1
    return moved
