"""The spec's two YAML parsers: libyaml reads a spec it accepts into exactly the tree PyYAML's parser reads
(values, locations of keys and values); a text it may read differently, or does not accept, is PyYAML's alone."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from generator import source
from generator.source import Node

SPEC = Path(__file__).resolve().parents[2] / "spec" / "drone.yaml"
UNICODE = 'a: "é€𝄞x"\nb: [1, "ü", 3]\n  # c\n"ké": {x: é, "𝄞": 2, y: [null, true, 0x1F, 1.5e3]}\n'
needs_libyaml = pytest.mark.skipif(not yaml.__with_libyaml__, reason="PyYAML without libyaml")


def _tree(node: Node | None) -> Any:
    if node is None:
        return None
    leaf = None if isinstance(node.value, (list, dict)) else repr(node.value)
    return (leaf, node.location, node.key_location, {k: _tree(v) for k, v in node.children.items()},
            [_tree(i) for i in node.items])


def _pure(text: str) -> tuple[Node | None, list[str]]:
    loader = source._BoundedLoader(text)
    try:
        root = loader.get_single_node()
    finally:
        loader.dispose()
    node, errors = source._converted(root, "f")
    return node, [str(e) for e in errors]


@needs_libyaml
@pytest.mark.parametrize("text", [SPEC.read_text(encoding="utf-8"), UNICODE], ids=["shipped", "unicode"])
def test_libyaml_reads_the_tree_pyyaml_reads(text: str) -> None:
    fast = source._fast_root(text)
    assert fast is not None  # libyaml read it: the fast path is the one taken
    node, errors = source._converted(fast, "f")
    want, want_errors = _pure(text)
    assert _tree(node) == _tree(want) and [str(e) for e in errors] == want_errors


@needs_libyaml
@pytest.mark.parametrize("text", ["a:\tb\n", "a: b\r\nc: d\n", "a\ufeffb: c\n", "a: [b\n", "a: &x b\n"])
def test_a_text_libyaml_may_read_otherwise_is_left_to_pyyaml(text: str) -> None:
    assert source._fast_root(text) is None
