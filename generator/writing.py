"""The generator's writing phase: every generated file changes or none does, whenever the run is killed.

Changed files are first written into a staging folder inside the output folder (``.generator-staging/``);
then a manifest (``COMMIT``) naming them is renamed into place: that rename is the commit point. Only then
are the files moved into their places and the staging folder removed. A run killed before the commit point
leaves the old files untouched; one killed after it leaves a committed manifest, which the next run
completes (roll forward) before anything else. The next run also removes an unfinished staging folder and
any stray temporary file (``.NAME.*.tmp``, from older generators); ``--check`` reports both as debris.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

STAGING = ".generator-staging"
MANIFEST = "COMMIT"
STRAY = ".*.tmp"  # temporary files of the generator's previous writing scheme


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
    """What a killed run left: a staging folder (committed or not) and stray temporary files."""
    found = []
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
    """Finish a committed run, or drop an uncommitted one, and remove stray temporary files; returns what
    was done, one line each."""
    done = []
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


def _move_into_place(rels: list[str], staging: Path, out_dir: Path) -> int:
    moved = 0
    for rel in rels:
        src = staging / "files" / rel
        if src.exists():  # else moved before the cut
            (out_dir / rel).parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, out_dir / rel)
            moved += 1
    return moved


def write_atomically(files: dict[str, bytes], out_dir: Path) -> list[str]:
    """Write every changed file or none, through the staging folder; returns the paths that changed."""
    recover(out_dir)
    changed = [rel for rel in sorted(files)
               if not (out_dir / rel).exists() or (out_dir / rel).read_bytes() != files[rel]]
    if not changed:
        return changed
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
    return changed
