"""The virtual drone built from packaged sources: a machine without a C++ compiler gets one line naming what to
install, and a failed build names the compiler's first error (the install tests build it for real)."""

from __future__ import annotations

from pathlib import Path

import pytest

from pilot.common.errors import SimulatorError
from pilot.sim import drone_build


def test_without_a_compiler_the_error_names_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CXX", raising=False)
    monkeypatch.setenv("PATH", "")
    with pytest.raises(SimulatorError, match=r"needs a C\+\+ compiler: install g\+\+"):
        drone_build.build()


def test_a_failed_build_names_the_compiler_and_leaves_no_executable(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    sources = tmp_path / "src"
    for name in drone_build.SOURCES:
        (sources / name).parent.mkdir(parents=True, exist_ok=True)
        (sources / name).write_text("this is not C++\n", encoding="utf-8")
    with pytest.raises(SimulatorError, match=r"building the virtual drone with .* failed: .*error"):
        drone_build.build(sources)
    assert [p.name for p in (tmp_path / "cache" / "drone-protocol-tools").iterdir()] == []
