"""Build the two Python wheels into a folder: the codec (generated/python) and the tools (this repository).

Used by `make dist` (which adds the npm tarball and the crate) and by the install tests. The tools' wheel is built
from a copy of exactly what it ships, so that setuptools' build/ and *.egg-info never land in the repository and a
stale build/lib cannot leak a deleted module into the wheel.

    python tests/packaging/make_dist.py OUT_DIR
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CODEC = ROOT / "generated" / "python"
# what the tools' sdist and wheel are built from (setup.py and MANIFEST.in read the same folders)
TOOLS_FILES = ("pyproject.toml", "setup.py", "MANIFEST.in", "README.md", "LICENSE", "generator", "pilot",
               "firmware/drone", "firmware/host", "generated/arduino/DroneProtocol/src",
               "generated/ardupilot/arducopter-4/drone.parm")


def pip_wheel(source: Path, out: Path) -> str:
    """`pip wheel` of `source` into `out`; pip's and the backend's output (the caller checks it for warnings)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--disable-pip-version-check", "--no-deps", "-w", str(out),
         str(source)], cwd=out, env=env, capture_output=True, text=True, timeout=600, check=False)
    if proc.returncode != 0:
        raise SystemExit(f"make_dist: pip wheel {source} failed:\n{proc.stdout}{proc.stderr}")
    return proc.stdout + proc.stderr


def copy_tools_source(dest: Path) -> Path:
    """A copy of what the tools' distribution is built from, in `dest`."""
    for name in TOOLS_FILES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, dest / name, ignore=shutil.ignore_patterns("__pycache__", "build"))
        else:
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(path, dest / name)
    return dest


def build(out: Path) -> tuple[Path, Path, str]:
    """The codec's and the tools' wheels in `out`, and the builds' output."""
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("*.whl"):
        old.unlink()
    log = pip_wheel(CODEC, out)
    with tempfile.TemporaryDirectory() as tmp:
        log += pip_wheel(copy_tools_source(Path(tmp) / "drone-protocol-tools"), out)
    (codec,) = out.glob("drone_protocol-*.whl")
    (tools,) = out.glob("drone_protocol_tools-*.whl")
    return codec, tools, log


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit("usage: make_dist.py OUT_DIR")
    for wheel in build(Path(sys.argv[1]).resolve())[:2]:
        print(wheel.relative_to(ROOT) if wheel.is_relative_to(ROOT) else wheel)
