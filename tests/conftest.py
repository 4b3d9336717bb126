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


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        folder = item.path.resolve().relative_to(TESTS).parts[0]
        item.add_marker(pytest.mark.xdist_group("pilot" if folder == "pilot" else "shared-builds"))


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
