"""The Rust and C usage examples of the README, of the generated docs and of the C codec's own README compile
(strict flags) and run."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import targets_harness as t

DOCS = (t.ROOT / "README.md", t.GENERATED / "docs" / "protocol.md")
C_README = t.C_DIR / "README.md"


def blocks(language: str, docs: tuple[Path, ...] = DOCS) -> list[tuple[str, str]]:
    """(where, code) of every fenced block of `language` in the docs."""
    out = []
    for path in docs:
        for i, match in enumerate(re.finditer(rf"^```{language}\n(.*?)^```$", path.read_text(), re.M | re.S)):
            out.append((f"{path.relative_to(t.ROOT)}#{i}", match.group(1)))
    return out


def test_both_documents_carry_a_rust_and_a_c_example_of_at_most_five_lines() -> None:
    for language in ("rust", "c"):
        found = blocks(language)
        assert {where.split("#")[0] for where, _ in found} == {str(p.relative_to(t.ROOT)) for p in DOCS}, language
        assert all(len(code.strip().splitlines()) <= 5 for _, code in found), language


@pytest.mark.parametrize(("where", "code"), blocks("rust"))
def test_the_rust_example_runs(where: str, code: str, tmp_path: Path) -> None:
    source = tmp_path / "example.rs"
    source.write_text("fn main() {\n" + code + "}\n")
    t.run([str(t.rustc_program(source, f"example_rs_{where.replace('#', '_').replace('/', '_')}", ("-D", "warnings")))])


@pytest.mark.parametrize(("where", "code"), blocks("c", (*DOCS, C_README)))
def test_the_c_example_runs(where: str, code: str, tmp_path: Path) -> None:
    source = tmp_path / "example.c"
    source.write_text('#include <assert.h>\n#include <stddef.h>\n#include <stdint.h>\n#include <string.h>\n'
                      '#include "drone_protocol.h"\n\n'
                      "int main(void) {\n" + code + "  return 0;\n}\n")
    exe = tmp_path / "example"
    t.run(["gcc", *t.CFLAGS, f"-I{t.C_DIR}", str(source), *map(str, t.c_sources()), "-o", str(exe)])
    t.run([str(exe)])
