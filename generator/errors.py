"""Spec errors as values: every problem, with where it is and what to do about it."""

from __future__ import annotations

from .records import record


@record
class Location:
    file: str
    line: int  # 1-based
    column: int  # 1-based

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


@record
class SpecError:
    location: Location
    path: str  # dotted path inside the spec, e.g. categories.m.directions.f.default
    message: str
    hint: str = ""

    def __str__(self) -> str:
        where = f"{self.location}: {self.path}: " if self.path else f"{self.location}: "
        hint = f" (hint: {self.hint})" if self.hint else ""
        return f"{where}{self.message}{hint}"


class SpecInvalid(Exception):
    """Raised with every error found in a spec; nothing has been written."""

    def __init__(self, errors: list[SpecError]) -> None:
        self.errors = sorted(errors, key=lambda e: (e.location.line, e.location.column, e.path, e.message))
        super().__init__("\n".join(str(e) for e in self.errors))
