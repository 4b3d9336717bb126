"""Codes that spell a block comment's ends: a category `/` with a direction `*` gives the frame `/*0000`, a category
`*` with a direction `/` the frame `*/0000`. The spec accepts any printable code, and the C header and the
TypeScript package print frames inside block comments: both must still compile (a spec mutation found the C header
broken and TypeScript's `tsc` failing on them)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import targets_harness as t
import yaml

from generator.cli import main as generate


@pytest.fixture(scope="module")
def tree() -> Path:
    spec = yaml.safe_load((t.ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    for code, direction, name in (("/", "*", "slash"), ("*", "/", "star")):
        spec["categories"][code] = {"name": name, "hardware": "Test", "description": "A code test", "field": "zero",
                                    "directions": {direction: {"name": f"{name}_go", "description": "Go"}}}
    out = t.BUILD / "comment_codes"
    out.mkdir(parents=True, exist_ok=True)
    (out / "drone.yaml").write_text(yaml.safe_dump(spec, allow_unicode=True, sort_keys=False), encoding="utf-8")
    shutil.rmtree(out / "generated", ignore_errors=True)  # a fresh codec: no earlier run's contract to rise from
    assert generate(["--spec", str(out / "drone.yaml"), "--out", str(out / "generated")]) == 0
    return out / "generated"


def test_the_c_codec_compiles_with_its_strict_flags(tree: Path) -> None:
    header = (tree / "c" / "drone_protocol.h").read_text(encoding="utf-8")
    assert "/* /\\*0000 */" in header and "/* *\\/0000 */" in header  # shown with JSDoc's backslash
    t.run(["gcc", *t.CFLAGS, "-c", str(tree / "c" / "drone_protocol.c"), "-o", str(tree / "c" / "codec.o")])


def test_the_cpp_library_compiles_with_its_strict_flags(tree: Path) -> None:
    source = tree / "use.cpp"
    source.write_text('#include "DroneProtocol.h"\nint main() { return drone_protocol::FRAME_LENGTH == 6 ? 0 : 1; }\n')
    t.run(["g++", *t.CXXFLAGS, f"-I{tree / 'arduino' / 'DroneProtocol' / 'src'}", str(source), "-o",
           str(tree / "use")])
    t.run([str(tree / "use")])


def test_the_typescript_package_type_checks(tree: Path) -> None:
    t.run([str(t.tsc()), "--noEmit", "-p", str(tree / "typescript" / "tsconfig.json")])
