"""The detectors' rules are judged without a clock: a frame's time budget (``vision.budget_ms``) never runs out in
these tests unless a test gives a detector a clock of its own (test_pilot_budget.py), so a loaded machine cannot
change what a test sees."""

from __future__ import annotations

import pytest

import pilot.vision.budget as budget


@pytest.fixture(autouse=True)
def frozen_budget_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(budget, "CLOCK", lambda: 0.0)
