"""Load YAML safely into plain values while remembering where every key and value was written.

PyYAML's own constructors lose positions and silently keep the last of two duplicate keys, so we walk the
composed node tree ourselves (still through SafeLoader: no arbitrary tags are ever constructed).
Mapping keys are kept as the text written, so `y:` or `0:` name a direction instead of becoming a boolean or
an int.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import yaml

from .errors import Location, SpecError


class Invalid:
    """The value of a node whose error was already reported: readers skip it without a second error."""

    def __repr__(self) -> str:
        return "<invalid>"


INVALID = Invalid()

Plain = None | bool | int | float | str | list["Plain"] | dict[str, "Plain"] | Invalid


@dataclass
class Node:
    """A plain value with the location of its value and, for mapping entries, of its key."""

    value: Plain
    location: Location
    key_location: Location
    children: dict[str, Node] = field(default_factory=dict)
    items: list[Node] = field(default_factory=list)


def _location(file: str, mark: yaml.Mark) -> Location:
    return Location(file, mark.line + 1, mark.column + 1)


def load(text: str, file: str) -> tuple[Node | None, list[SpecError]]:
    """Parse `text`; return the root node, or None and the syntax error."""
    loader = yaml.SafeLoader(text)
    try:
        root = loader.get_single_node()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        loc = _location(file, mark) if mark else Location(file, 1, 1)
        return None, [SpecError(loc, "", f"YAML syntax error: {exc.problem or exc.context}")]
    finally:
        loader.dispose()
    if root is None:
        return None, [SpecError(Location(file, 1, 1), "", "the spec is empty")]
    errors: list[SpecError] = []
    node = _convert(yaml.SafeLoader(""), root, file, "", _location(file, root.start_mark), errors)
    return node, errors


def _convert(
    loader: yaml.SafeLoader, ynode: yaml.Node, file: str, path: str, key_loc: Location, errors: list[SpecError]
) -> Node:
    loc = _location(file, ynode.start_mark)
    if ynode.tag not in _PLAIN_TAGS:
        errors.append(SpecError(loc, path, f"unsupported YAML tag {ynode.tag}"))
        return Node(INVALID, loc, key_loc)
    if isinstance(ynode, yaml.MappingNode):
        children: dict[str, Node] = {}
        for key_node, value_node in ynode.value:
            kloc = _location(file, key_node.start_mark)
            if not isinstance(key_node, yaml.ScalarNode):
                errors.append(SpecError(kloc, path, "a key must be plain text"))
                continue
            key = str(key_node.value)
            sub = f"{path}.{key}" if path else key
            if key in children:
                first = children[key].key_location
                errors.append(SpecError(kloc, sub, f"duplicate key '{key}' (first defined at line {first.line})"))
                continue
            children[key] = _convert(loader, value_node, file, sub, kloc, errors)
        return Node({k: v.value for k, v in children.items()}, loc, key_loc, children=children)
    if isinstance(ynode, yaml.SequenceNode):
        items = [
            _convert(loader, item, file, f"{path}[{i}]", _location(file, item.start_mark), errors)
            for i, item in enumerate(ynode.value)
        ]
        return Node([i.value for i in items], loc, key_loc, items=items)
    value = loader.construct_object(ynode, deep=True)
    return Node(value, loc, key_loc)


_PLAIN_TAGS = {
    "tag:yaml.org,2002:null",
    "tag:yaml.org,2002:bool",
    "tag:yaml.org,2002:int",
    "tag:yaml.org,2002:float",
    "tag:yaml.org,2002:str",
    "tag:yaml.org,2002:map",
    "tag:yaml.org,2002:seq",
}
