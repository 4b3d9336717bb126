"""What every section of the protocol benchmarks returns: one table row each, and the run's settings."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Row:
    section: str
    measure: str
    subject: str
    baseline: str
    ratio: str
    target: str
    verdict: str


@dataclass(frozen=True)
class Settings:
    quick: bool
    build: Path
