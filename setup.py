"""The project's packages, installed under one namespace: the repo's ``generator/`` and ``pilot/`` folders become
``drone_protocol_tools.generator`` and ``drone_protocol_tools.pilot`` (their imports are relative, so the same
code runs as ``python -m generator`` / ``python -m pilot`` in the repo). Template folders are listed too, as
data-only packages, so setuptools ships them without warnings. Everything else is in pyproject.toml.

The simulator flies the firmware's own logic (the virtual drone, a host build of ``firmware/``): its C++ sources
and the generated Arduino library it includes are copied into ``pilot/sim/firmware/`` of the wheel, where
``pilot.sim.virtual`` compiles them once on a machine without the repository; the generated parameter file the
simulated flight controller reads goes to ``pilot/sim/drone.parm``."""

from pathlib import Path

from setuptools import find_namespace_packages, setup
from setuptools.command.build_py import build_py

NAMESPACE = "drone_protocol_tools"
HERE = Path(__file__).resolve().parent
found = [p for p in find_namespace_packages(include=["generator", "generator.*", "pilot", "pilot.*"])
         if all(part.isidentifier() for part in p.split("."))]
# (folder in the repository, folder under pilot/sim/firmware in the wheel): the virtual drone's sources
VIRTUAL_DRONE_SOURCES = (("firmware/drone", "drone"), ("firmware/host", "host"),
                         ("generated/arduino/DroneProtocol/src", "DroneProtocol/src"))


class BuildWithFirmware(build_py):
    """build_py, plus the virtual drone's C++ sources as data of drone_protocol_tools.pilot.sim."""

    def run(self) -> None:
        super().run()
        target = Path(self.build_lib) / NAMESPACE / "pilot" / "sim" / "firmware"
        for source, dest in VIRTUAL_DRONE_SOURCES:
            self.mkpath(str(target / dest))
            for path in sorted((HERE / source).iterdir()):
                if path.suffix in (".cpp", ".h"):
                    self.copy_file(str(path), str(target / dest / path.name), preserve_mode=False)
        # the flight controller's parameters the simulator flies with (pilot.sim.rc)
        parm = HERE / "generated" / "ardupilot" / "arducopter-4" / "drone.parm"
        self.copy_file(str(parm), str(target.parent / "drone.parm"), preserve_mode=False)


setup(
    packages=[f"{NAMESPACE}.{p}" for p in found],
    package_dir={f"{NAMESPACE}.{p}": p.replace(".", "/") for p in found},
    # *.pyj: the templates precompiled to Python (generator/precompiled.py)
    package_data={f"{NAMESPACE}.{p}": ["py.typed", "*.j2", "**/*.j2", "*.pyj", "**/*.pyj", "*.html", "*.yaml",
                                       "LICENSE"] for p in found},
    cmdclass={"build_py": BuildWithFirmware},
)
