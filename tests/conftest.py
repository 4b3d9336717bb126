"""Two groups for pytest-xdist (`make test` runs `-n 2 --dist loadgroup`): the pilot's tests, which fly the
simulator and build their own virtual drone in a temporary folder, on one worker; everything else, whose
tests share the build folders of the repo (firmware/build, build/tests, build/targets), on the other, in turn."""

from __future__ import annotations

from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        folder = item.path.resolve().relative_to(TESTS).parts[0]
        item.add_marker(pytest.mark.xdist_group("pilot" if folder == "pilot" else "shared-builds"))
