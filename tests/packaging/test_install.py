"""The wheels install and run on the oldest and the newest Python the project supports (3.9, Pi OS Bullseye's, and
3.13), each in a fresh virtual environment, from a folder of wheels alone (`pip install --no-index`): the tools
resolve their codec from the same folder; every module imports; `pilot --version`, `pilot --help`,
`drone-protocol-gen --spec S --out D` from an empty folder and a short `pilot --sim` flight with the `[sim]` extra
(the virtual drone compiled from the sources the wheel carries) exit 0, with no pip warning.

The interpreters come from pyenv (`make install-pythons` installs a missing one); the third-party wheels are
downloaded once per interpreter into build/wheelhouse and reused, so a run costs the venvs' installs and the flights.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import drone_protocol as dp
import make_dist
import pytest

ROOT = Path(__file__).resolve().parents[2]
WHEELHOUSE = ROOT / "build" / "wheelhouse"
PYTHONS = ("3.9", "3.13")  # the oldest requires-python allows and the newest the project is tested on
PIP = ("-m", "pip", "--disable-pip-version-check", "--no-input")
# the tools' distribution with its simulator
TOOLS = "drone-protocol-tools[sim]"

pytestmark = pytest.mark.xdist_group("install")


def interpreter(version: str) -> Path:
    """The newest pyenv-managed (or PATH's) python<version>."""
    root = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"
    found = sorted(root.glob(f"{version}.*/bin/python{version}"),
                   key=lambda p: tuple(int(x) for x in p.parts[-3].split(".") if x.isdigit()))
    path = found[-1] if found else shutil.which(f"python{version}")
    assert path, f"Python {version} is missing: run `make install-pythons` (pyenv install {version})"
    return Path(path)


def run(*cmd: str | Path, cwd: Path, env: dict[str, str] | None = None,
        timeout: float = 600) -> subprocess.CompletedProcess[str]:
    base = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PILOT_VIRTUAL_DRONE")}
    return subprocess.run([str(c) for c in cmd], cwd=cwd, env={**base, **(env or {})}, capture_output=True,
                          text=True, timeout=timeout, check=False)


def ok(proc: subprocess.CompletedProcess[str]) -> str:
    assert proc.returncode == 0, f"exit {proc.returncode}: {proc.args}\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def dist(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of wheels: `make dist`'s when make passes it, else one built here."""
    given = os.environ.get("DRONE_PROTOCOL_DIST")
    if given:
        return Path(given)
    out = tmp_path_factory.mktemp("dist")
    *_, log = make_dist.build(out)
    assert "warning" not in log.lower(), log
    return out


def wheelhouse(python: Path, version: str, dist: Path) -> Path:
    """The third-party wheels the tools need on this interpreter, downloaded once (keyed by their requirements)."""
    (tools,) = dist.glob("drone_protocol_tools-*.whl")
    with zipfile.ZipFile(tools) as zf:
        meta = zf.read(next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA")))
    requires = b"\n".join(line for line in meta.splitlines() if line.startswith(b"Requires-Dist"))
    folder = WHEELHOUSE / f"py{version}-{hashlib.sha256(requires).hexdigest()[:12]}"
    if not (folder / ".complete").is_file():
        folder.mkdir(parents=True, exist_ok=True)
        ok(run(python, *PIP, "download", "-q", "--only-binary=:all:", "-d", folder, "--find-links", dist, TOOLS,
               cwd=folder))
        for ours in folder.glob("drone_protocol*.whl"):
            ours.unlink()  # ours come from dist/ only
        (folder / ".complete").touch()
    return folder


@pytest.mark.parametrize("version", PYTHONS)
def test_the_wheels_install_and_fly_in_a_fresh_venv(version: str, dist: Path, tmp_path: Path) -> None:
    python = interpreter(version)
    house = wheelhouse(python, version, dist)
    env_dir = tmp_path / "venv"
    ok(run(python, "-m", "venv", env_dir, cwd=tmp_path))
    bin_dir = env_dir / "bin"
    # the codec is found in dist/ only: the wheelhouse has the third-party wheels alone
    # --no-compile: byte-compiling scipy, scikit-image and the rest was much of the install time
    install = ok(run(bin_dir / "python", *PIP, "install", "--no-compile", "--no-index", "--find-links", dist,
                     "--find-links", house, TOOLS, cwd=tmp_path))
    assert not re.search(r"warning|deprecat|error", install, re.I), install
    work = tmp_path / "empty"
    work.mkdir()

    # every module of the installed packages imports on this Python (3.10+ syntax or names would fail here)
    imports = ok(run(bin_dir / "python", "-I", "-c", (
        "import importlib, pkgutil, drone_protocol_tools as t\n"
        "names = [m.name for m in pkgutil.walk_packages(t.__path__, 'drone_protocol_tools.')\n"
        "         if not m.name.endswith('__main__')]\n"
        "for n in names: importlib.import_module(n)\n"
        "print(len(names))"), cwd=work))
    assert int(imports.split()[-1]) > 50, imports

    version_out = ok(run(bin_dir / "pilot", "--version", cwd=work))
    assert dp.SPEC_FINGERPRINT in version_out, version_out
    assert "--sim" in ok(run(bin_dir / "pilot", "--help", cwd=work))

    spec = work / "drone.yaml"  # the spec's file name is printed in every generated header
    shutil.copy(ROOT / "spec" / "drone.yaml", spec)
    ok(run(bin_dir / "drone-protocol-gen", "--spec", spec, "--out", work / "out", cwd=work))
    made = sorted(p.relative_to(work / "out").as_posix() for p in (work / "out").rglob("*") if p.is_file())
    committed = sorted(p.relative_to(ROOT / "generated").as_posix() for p in (ROOT / "generated").rglob("*")
                       if p.is_file() and "__pycache__" not in p.parts)
    assert made == committed
    assert (work / "out" / "vectors.json").read_bytes() == (ROOT / "generated" / "vectors.json").read_bytes()

    # the virtual drone is compiled once from the wheel's sources into this cache, shared by both interpreters
    cache = {"XDG_CACHE_HOME": str(WHEELHOUSE / "cache")}
    flight = ok(run(bin_dir / "pilot", "--sim", "--ideal", "--max-seconds", "20", "--no-status", cwd=work, env=cache))
    assert "SUCCESS" in flight and "drone confirmed disarmed" in flight, flight
    assert sorted(p.name for p in work.iterdir()) == ["drone.yaml", "out"]  # nothing written beside the user's files
    assert sys.version_info >= (3, 9)
