"""Build the virtual drone from the firmware sources an installed package carries.

In the repository, ``make firmware-host`` builds the virtual drone. A wheel has no repository: setup.py copies the
firmware's C++ sources and the generated Arduino library into ``firmware/`` beside this module, and the first
``pilot --sim`` compiles them with the machine's C++ compiler (``$CXX``, else ``c++``/``g++``) into the user's cache,
named by a hash of the sources and the command, so a new version of the package builds again and nothing else does.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from ..common.errors import SimulatorError

PACKAGED = Path(__file__).resolve().parent / "firmware"
# The sources of the host build, as firmware/firmware.mk lists them for virtual_drone
SOURCES = ("host/virtual_drone.cpp", "drone/drone_app.cpp", "drone/drone_logic.cpp", "drone/drone_handlers.cpp",
           "drone/pulse_schedule.cpp", "host/pulse_out_host.cpp", "host/fake_arduino.cpp")
INCLUDES = ("host", "drone", "DroneProtocol/src")
FLAGS = ("-std=c++11", "-O2")


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "drone-protocol-tools"


def compiler() -> str:
    found = os.environ.get("CXX") or shutil.which("c++") or shutil.which("g++")
    if not found:
        raise SimulatorError("the simulator compiles the virtual drone once and needs a C++ compiler: install g++ "
                             "(sudo apt-get install g++) or point CXX at one")
    return found


def build(sources: Path = PACKAGED) -> Path:
    """The virtual drone built from ``sources`` (compiled on the first call, then reused from the cache)."""
    cxx = compiler()
    command = [cxx, *FLAGS, *(f"-I{sources / i}" for i in INCLUDES), *(str(sources / s) for s in SOURCES)]
    digest = hashlib.sha256(" ".join([cxx, *FLAGS]).encode())
    for path in sorted(p for p in sources.rglob("*") if p.is_file()):
        digest.update(path.relative_to(sources).as_posix().encode() + b"\0" + path.read_bytes())
    exe = cache_dir() / f"virtual_drone-{digest.hexdigest()[:16]}"
    if exe.is_file():
        return exe
    exe.parent.mkdir(parents=True, exist_ok=True)
    print(f"pilot: building the virtual drone once, into {exe}", file=sys.stderr)
    with tempfile.TemporaryDirectory(dir=exe.parent) as tmp:
        out = Path(tmp) / "virtual_drone"
        proc = subprocess.run([*command, "-o", str(out)], capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            first = (proc.stderr.strip().splitlines() or ["(no message)"])[0]
            raise SimulatorError(f"building the virtual drone with {cxx} failed: {first}")
        os.replace(out, exe)  # atomic: a second pilot started meanwhile finds a whole executable or none
    return exe
