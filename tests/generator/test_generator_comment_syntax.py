"""Each generated file carries its do-not-edit header in the comment syntax of its own format (issue 10: the
Arduino IDE refused library.properties when it got the C++ files' `//`)."""

from __future__ import annotations

import re
from pathlib import PurePosixPath

import protocol_harness as h
import pytest

from generator.build import load_spec
from generator.render import header_lines, render_all
from generator.targets import comment_style

# What each format accepts as a comment: the header's first line must start with it.
OPENERS = {".properties": "# ", ".txt": "# ", ".parm": "# ", ".params": "# ", ".py": "# ", ".typed": "# ", ".h": "// ",
           ".ino": "// ", ".md": "<!--\n", ".c": "// ", ".rs": "// ", ".toml": "# ", ".lock": "# ", ".ts": "// ",
           ".mjs": "// ", ".html": "<!--", ".svg": "<!--\n"}


def test_every_generated_file_opens_with_its_own_formats_comment() -> None:
    spec = load_spec(h.SPEC)
    files = render_all(spec)
    notice = header_lines(spec)[0]
    seen = set()
    for path, content in files.items():
        text = content.decode("utf-8")
        suffix = PurePosixPath(path).suffix
        if PurePosixPath(path).name == "LICENSE":  # no comment syntax: the license text as checkers read it
            continue
        if suffix == ".json":
            assert text.lstrip().startswith("{") and notice in text, path  # the template prints it as a member
            continue
        seen.add(suffix)
        assert text.startswith(OPENERS[suffix]), path
        assert notice in text.splitlines()[0] + text.splitlines()[1], path
    assert {".properties", ".txt", ".parm", ".params", ".h", ".ino", ".py", ".md"} <= seen


def test_library_properties_has_only_hash_comments_and_key_value_lines() -> None:
    props = (h.GENERATED / "arduino" / "DroneProtocol" / "library.properties").read_text(encoding="utf-8")
    for line in props.splitlines():
        assert line.startswith("#") or ("=" in line and not line.startswith("=")), line


def test_keywords_are_tab_separated_and_name_what_the_header_defines() -> None:
    library = h.GENERATED / "arduino" / "DroneProtocol"
    header = h.header_text(library / "src")
    kinds = set()
    for line in (library / "keywords.txt").read_text(encoding="utf-8").splitlines():
        if not line or line.startswith("#"):
            continue
        name, kind = line.split("\t")
        kinds.add(kind)
        assert kind in ("KEYWORD1", "KEYWORD2", "LITERAL1"), line
        assert name.isidentifier() and re.search(rf"\b{name}\b", header), f"{name} is not in DroneProtocol.h"
    assert kinds == {"KEYWORD1", "KEYWORD2", "LITERAL1"}


@pytest.mark.parametrize(("path", "style"), [("a/library.properties", "#"), ("a/keywords.txt", "#"),
                                             ("x.ino", "//"), ("x.rs", "//"), ("p/pyproject.toml", "#"),
                                             ("d/index.html", "<!--"), ("vectors.json", "json"),
                                             ("rust/LICENSE", "")])
def test_comment_style_is_decided_by_file_name(path: str, style: str) -> None:
    assert comment_style(path) == style


def test_an_unknown_format_is_an_error_not_a_guess() -> None:
    with pytest.raises(ValueError, match=re.escape("no comment syntax known for generated file 'notes.adoc'")):
        comment_style("notes.adoc")
