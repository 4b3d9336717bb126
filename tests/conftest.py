"""Two groups for pytest-xdist (`make test` runs `-n 2 --dist loadgroup`): the pilot's tests, which fly the
simulator and build their own virtual drone in a temporary folder, on one worker; everything else, whose
tests share the build folders of the repo (firmware/build, build/tests, build/targets), on the other, in turn.
And a retry of exec on ETXTBSY, which running two workers made possible (below)."""

from __future__ import annotations

import errno
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

TESTS = Path(__file__).resolve().parent


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the groups
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        folder = item.path.resolve().relative_to(TESTS).parts[0]
        item.add_marker(pytest.mark.xdist_group("pilot" if folder == "pilot" else "shared-builds"))



def pytest_collection_finish(session: pytest.Session) -> None:
    # xdist marks a grouped test by a suffix of its node id; without it the groups would silently mix
    if session.config.getoption("dist", "no") == "loadgroup" and any("@" not in i.nodeid for i in session.items):
        raise pytest.UsageError("pytest-xdist did not group the tests (pytest 9 ignores its node ids): pytest<9")

_popen_init = subprocess.Popen.__init__


def _popen_init_again_if_text_file_busy(self: subprocess.Popen[Any], *args: Any, **kwargs: Any) -> None:
    """Tests run binaries the build has just linked; on a loaded machine (pytest on both cores) Linux can still
    count the linker's write hold on the file when exec comes, and exec fails with ETXTBSY ("Text file busy").
    Popen starts again then, for up to a second: nothing was started, and Popen closed what it had opened."""
    for attempt in range(20):
        try:
            _popen_init(self, *args, **kwargs)
            return
        except OSError as exc:
            if exc.errno != errno.ETXTBSY or attempt == 19:
                raise
            time.sleep(0.05)


subprocess.Popen.__init__ = _popen_init_again_if_text_file_busy  # type: ignore[method-assign]

