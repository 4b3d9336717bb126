"""Groups for pytest-xdist (`make test` runs `-n 2 --dist loadgroup --no-loadscope-reorder`): every test outside
tests/pilot shares the build folders of the repo (firmware/build, build/tests, build/targets) and so runs in one
group, in turn, on one worker; the pilot's tests build their own virtual drone in a temporary folder and share
nothing, so each of their files is a group of its own that either worker takes when it runs out of work. The
groups start longest first: the closed-loop flights (a fifth of a run) on one worker, the shared builds (the
largest group) on the other, then the pilot's files that take longest (LONGEST_FIRST), then the rest; a worker
that started the flights last would finish minutes after the other."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
FIRST = "test_pilot_closed_loop.py"
LONGEST_FIRST = ("test_pilot_hsv_hollow.py", "test_pilot_safety.py",
                 "test_pilot_exits.py", "test_pilot_hsv_inside.py", "test_pilot_hsv_measured_again.py")


def pytest_configure(config: pytest.Config) -> None:
    # a shell starts a background job (`make test &`, nohup) with SIGINT ignored, and every child inherits that; the
    # pilot's tests deliver SIGINT to it, in the worker itself and to the pilot's own processes, and would wait in vain
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the groups
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        folder = item.path.resolve().relative_to(TESTS).parts[0]
        group = f"pilot-{item.path.stem}" if folder == "pilot" else "shared-builds"
        item.add_marker(pytest.mark.xdist_group(group))

    def rank(item: pytest.Item) -> int:  # a stable sort: within a rank, the order pytest collected
        name = item.path.name
        if name == FIRST:
            return 0
        if not name.startswith("test_pilot_"):
            return 1
        return 2 + (LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST))

    items.sort(key=rank)


def pytest_collection_finish(session: pytest.Session) -> None:
    # xdist marks a grouped test by a suffix of its node id; without it the groups would silently mix
    if session.config.getoption("dist", "no") == "loadgroup" and any("@" not in i.nodeid for i in session.items):
        raise pytest.UsageError("pytest-xdist did not group the tests (pytest 9 ignores its node ids): pytest<9")
