"""The generated targets. Adding one means a template folder under templates/ and one line here."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    name: str  # the folder of templates under generator/templates/
    out_dir: str  # where its files go, relative to the output folder ("" for the top)
    comment: str  # how its files carry the do-not-edit header: "#", "//", "<!--", or "json" (the template does)


TARGETS: tuple[Target, ...] = (
    Target("python", "python", "#"),
    Target("arduino", "arduino", "//"),
    Target("docs", "docs", "<!--"),
    Target("vectors", "", "json"),
    Target("typescript", "typescript", "json"),  # its templates print their own headers (JSON, //, <!--)
)
