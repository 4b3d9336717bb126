"""Spec text is inert in the package READMEs (Python, Rust, Arduino, npm): a title and a description full of HTML
and Markdown render, as CommonMark (PyPI's, crates.io's and GitHub's reading), to exactly that text, and add no
element to the page: the same tags, as many of each, as the README of the plain spec."""

from __future__ import annotations

import html
import re
from collections import Counter
from pathlib import Path

import protocol_harness as h
from markdown_it import MarkdownIt

TITLE = "<img src=x onerror=alert(1)> **bold** _it_ [link](javascript:alert(1)) `code` ~~gone~~ | a | b | # not &amp;"
DESCRIPTION = ("- not a list <script>alert(1)</script> <!-- hidden --> ![image](x.png) <https://example.invalid> "
               "*emphasis* 1. two [ref]: /url")
READMES = ("python/README.md", "rust/README.md", "arduino/DroneProtocol/README.md", "typescript/README.md")


def generated(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    tmp_path.mkdir()
    (tmp_path / "drone.yaml").write_text(h.edited_spec(*edits), encoding="utf-8")
    run = h.generate("--spec", tmp_path / "drone.yaml", "--out", tmp_path / "out")
    assert run.code == 0, run.stderr
    return tmp_path / "out"


def tags(rendered: str) -> Counter[str]:
    return Counter(re.findall(r"<([a-z0-9]+)", rendered))


def test_hostile_spec_text_renders_as_itself_in_every_package_readme(tmp_path: Path) -> None:
    plain_out = generated(tmp_path / "plain")
    out = generated(
        tmp_path / "hostile",
        ("  title: Quadrotor drone protocol (Raspberry Pi to Arduino)\n", f"  title: {TITLE!r}\n"),
        ("  description: >-\n    The Raspberry Pi decides",
         f"  description: >-\n    {DESCRIPTION} The Raspberry Pi decides"),
    )
    md = MarkdownIt("commonmark").enable("table").enable("strikethrough")
    for name in READMES:
        rendered = md.render((out / name).read_text(encoding="utf-8"))
        assert tags(rendered) == tags(md.render((plain_out / name).read_text(encoding="utf-8"))), name
        shown = html.unescape(re.sub(r"<[^>]+>", "", rendered))
        assert TITLE in shown, f"{name}: the title is not shown as itself"
        if name.startswith("python/"):
            assert DESCRIPTION in shown, f"{name}: the description is not shown as itself"
