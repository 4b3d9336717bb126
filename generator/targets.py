"""The generated targets. Adding one means a template folder under templates/ and one line here."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    name: str  # the folder of templates under generator/templates/
    out_dir: str  # where its files go, relative to the output folder ("" for the top)
    comment: str  # how its files carry the do-not-edit header: "#", "//", "<!--", or "json" (the template does)
    # "html": every printed value is HTML-escaped (& < >) unless a filter already made it safe (filters.Safe)
    escape: str = ""


TARGETS: tuple[Target, ...] = (
    Target("python", "python", "#"),
    Target("arduino", "arduino", "//"),
    Target("docs", "docs", "<!--", escape="html"),
    Target("vectors", "", "json"),
    Target("contract", "", "json"),  # what a peer relies on: the previous version for the breaking-change check
)
