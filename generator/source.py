"""Load YAML safely into plain values while remembering where every key and value was written.

PyYAML's own constructors lose positions and silently keep the last of two duplicate keys, so we walk the
composed node tree ourselves (still through SafeLoader: no arbitrary tags are ever constructed).
Mapping keys are kept as the text written, so `y:` or `0:` name a direction instead of becoming a boolean or
an int.

A spec is untrusted input: reading is bounded before anything is parsed (size, NUL bytes, UTF-8), and
composing refuses anchors and aliases (a few kilobytes of aliases expand to billions of nodes) and nesting
deeper than any spec needs (the composer recurses once per level).

libyaml's parser (when PyYAML has it) reads a valid spec about 25 times faster than PyYAML's own; any text it
does not accept is read again by PyYAML's, whose messages and locations are the ones reported.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import yaml

from .errors import Location, SpecError

MAX_BYTES = 256 * 1024  # the shipped spec is about 11 kB
MAX_DEPTH = 16  # the shipped spec nests 5 deep
MAX_KEY = 64  # keys are names and codes


def display_path(path: Path | str) -> str:
    """`path` as printable text for messages: undecodable bytes and control characters escaped."""
    text = os.fsencode(path).decode("utf-8", "backslashreplace")
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def _location_of_byte(file: str, data: bytes, offset: int) -> Location:
    """The line and column (in characters) of byte `offset` of `data`, valid UTF-8 up to there."""
    before = data[:offset].decode("utf-8", "replace")
    return Location(file, before.count("\n") + 1, len(before) - (before.rfind("\n") + 1) + 1)


def read(path: Path) -> tuple[str | None, list[SpecError]]:
    """The text of the spec at `path`, or None and why not (located; a FIFO or a huge file never blocks)."""
    file = display_path(path)
    start = Location(file, 1, 1)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        return None, [SpecError(start, "", f"cannot read the spec: {reason}")]
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None, [SpecError(start, "", "cannot read the spec: not a regular file")]
        data = b""
        while len(data) <= MAX_BYTES:
            chunk = os.read(fd, MAX_BYTES + 1 - len(data))
            if not chunk:
                break
            data += chunk
    except OSError as exc:
        return None, [SpecError(start, "", f"cannot read the spec: {exc.strerror}")]
    finally:
        os.close(fd)
    if len(data) > MAX_BYTES:
        return None, [SpecError(start, "", f"the spec is larger than {MAX_BYTES} bytes",
                                "a spec is a few kilobytes of text")]
    nul = data.find(b"\0")
    try:
        text = data.decode("utf-8")
        bad = -1
    except UnicodeDecodeError as exc:
        text, bad = "", exc.start
    if nul >= 0 and (bad < 0 or nul < bad):
        return None, [SpecError(_location_of_byte(file, data, nul), "", "the spec contains a NUL byte",
                                "a spec is plain text")]
    if bad >= 0:
        return None, [SpecError(_location_of_byte(file, data, bad), "",
                                f"the spec is not UTF-8 text (byte 0x{data[bad]:02x})", "save the file as UTF-8")]
    return text, []


class Invalid:
    """The value of a node whose error was already reported: readers skip it without a second error."""

    def __repr__(self) -> str:
        return "<invalid>"


INVALID = Invalid()

Plain = Union[None, bool, int, float, str, list["Plain"], dict[str, "Plain"], Invalid]


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


class _Refused(Exception):
    def __init__(self, event: yaml.Event, message: str, hint: str) -> None:
        super().__init__(message)
        mark = event.start_mark
        self.line, self.column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        self.message, self.hint = message, hint


class _Bounded(yaml.composer.Composer):
    """A composer refusing anchors, aliases and deep nesting as it meets them (one pass)."""

    depth = 0
    peek_event: Callable[[], yaml.Event]  # the parser's, PyYAML's or libyaml's

    def compose_node(self, parent: yaml.Node | None, index: int) -> yaml.Node | None:
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:
            raise _Refused(event, "YAML anchors and aliases are not supported",
                           "write every value out; an alias can expand to billions of nodes")
        if not isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            return super().compose_node(parent, index)
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise _Refused(event, f"the spec nests deeper than {MAX_DEPTH} levels",
                               "a spec is a few levels of mappings")
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


class _BoundedLoader(_Bounded, yaml.SafeLoader):
    """SafeLoader, bounded."""


# Where the two parsers were seen to differ (libyaml takes a tab where PyYAML refuses it, and reads a byte-order
# mark inside a key differently) or might (other line breaks): such a text is PyYAML's alone.
_NOT_FAST = re.compile("[\t\r\x85\u2028\u2029\ufeff]")
_FAST: type[yaml.CSafeLoader] | None = None
if yaml.__with_libyaml__:
    class _FastLoader(_Bounded, yaml.CSafeLoader):
        """libyaml's parser under the same bounded composer, constructor and resolver (CSafeLoader composes in C,
        this in Python)."""

        def __init__(self, stream: str) -> None:
            yaml.CSafeLoader.__init__(self, stream)
            _Bounded.__init__(self)

    _FAST = _FastLoader


def _fast_root(text: str) -> yaml.Node | None:
    """The composed tree by libyaml, or None if libyaml is missing or did not accept every bit of `text`."""
    if _FAST is None or _NOT_FAST.search(text):
        return None
    loader = _FAST(text)
    try:
        root: yaml.Node | None = loader.get_single_node()
    except (_Refused, yaml.YAMLError, RecursionError):
        return None
    finally:
        loader.dispose()
    return root


def load(text: str, file: str) -> tuple[Node | None, list[SpecError]]:
    """Parse `text`; return the root node, or None and the syntax error."""
    fast = _fast_root(text)
    if fast is not None:
        return _converted(fast, file)
    loader: _BoundedLoader | None = None
    try:
        loader = _BoundedLoader(text)  # its reader checks every character at once
        root = loader.get_single_node()
    except _Refused as exc:
        return None, [SpecError(Location(file, exc.line, exc.column), "", exc.message, exc.hint)]
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        loc = _location(file, mark) if mark else Location(file, 1, 1)
        return None, [SpecError(loc, "", f"YAML syntax error: {exc.problem or exc.context}")]
    except yaml.reader.ReaderError as exc:  # a character YAML does not allow
        before = text[:exc.position]
        loc = Location(file, before.count("\n") + 1, exc.position - (before.rfind("\n") + 1) + 1)
        return None, [SpecError(loc, "", f"character U+{exc.character:04X} is not allowed in YAML",
                                "a spec is plain text")]
    finally:
        if loader is not None:
            loader.dispose()
    return _converted(root, file)


def _converted(root: yaml.Node | None, file: str) -> tuple[Node | None, list[SpecError]]:
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
            if len(key) > MAX_KEY:
                errors.append(SpecError(kloc, path, f"a key of {len(key)} characters is longer than {MAX_KEY}"))
                continue
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
    try:
        value = loader.construct_object(ynode, deep=True)
    except (ValueError, yaml.YAMLError) as exc:  # e.g. an integer of more digits than Python converts
        errors.append(SpecError(loc, path, f"unreadable value: {str(exc).splitlines()[0][:80]}"))
        return Node(INVALID, loc, key_loc)
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
