"""Two groups for pytest-xdist (`make test` runs `-n 2 --dist loadgroup`): the pilot's tests, which fly the
simulator and build their own virtual drone in a temporary folder, on one worker; everything else, whose
tests share the build folders of the repo (firmware/build, build/tests, build/targets), on the other, in turn.
The pilot's tests that only run its detector on photographs (no flight, no build) join the second group: the
flights alone took 300 s of a run, everything else 180 s."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
DETECTOR_ONLY = ("test_pilot_hsv_", "test_pilot_vision", "test_pilot_noise", "test_pilot_detect")  # file names


def pytest_configure(config: pytest.Config) -> None:
    # a shell starts a background job (`make test &`, nohup) with SIGINT ignored, and every child inherits that; the
    # pilot's tests deliver SIGINT to it, in the worker itself and to the pilot's own processes, and would wait in vain
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the groups
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        folder = item.path.resolve().relative_to(TESTS).parts[0]
        flies = folder == "pilot" and not item.path.name.startswith(DETECTOR_ONLY)
        item.add_marker(pytest.mark.xdist_group("pilot" if flies else "shared-builds"))


def pytest_collection_finish(session: pytest.Session) -> None:
    # xdist marks a grouped test by a suffix of its node id; without it the groups would silently mix
    if session.config.getoption("dist", "no") == "loadgroup" and any("@" not in i.nodeid for i in session.items):
        raise pytest.UsageError("pytest-xdist did not group the tests (pytest 9 ignores its node ids): pytest<9")
