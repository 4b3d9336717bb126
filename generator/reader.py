"""Typed, error-collecting access to the mappings of a loaded spec."""

from __future__ import annotations

import re
from typing import TypeVar

from .errors import SpecError
from .names import close_matches
from .source import INVALID, Node

T = TypeVar("T")

# what would break out of a string or comment of a target: controls, a backslash, a trigraph, a docstring's end, and
# a block comment's ends (the C and TypeScript targets print descriptions inside /* */)
_BAD_TEXT = re.compile(r"[\x00-\x1f\x7f\\]|\?\?|\"\"\"|/\*|\*/")
MAX_TEXT = 2000  # characters of one text value: a paragraph (and wrapping it stays instant)


class Reader:
    """Typed access to one mapping of the spec; records errors instead of raising."""

    def __init__(self, node: Node, path: str, errors: list[SpecError]) -> None:
        self.node, self.path, self.errors = node, path, errors
        self.seen: set[str] = set()
        self.ok = isinstance(node.value, dict)
        if not self.ok and node.value is not INVALID:
            self.error(node, f"expected a mapping, found {kind_name(node.value)}")

    def sub(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def error(self, node: Node, message: str, hint: str = "", path: str | None = None) -> None:
        self.errors.append(SpecError(node.location, self.path if path is None else path, message, hint))

    def child(self, key: str, required: bool = True) -> Node | None:
        self.seen.add(key)
        if not self.ok:
            return None
        node = self.node.children.get(key)
        if node is None and required:
            self.error(self.node, f"missing key '{key}'", path=self.sub(key))
        return node

    def get(self, key: str, kind: type[T], default: T | None = None, required: bool = True) -> T | None:
        node = self.child(key, required and default is None)
        if node is None:
            return default
        value = node.value
        if value is INVALID:
            return default
        if (kind is int and isinstance(value, bool)) or not isinstance(value, kind):
            self.error(node, f"expected {type_name(kind)}, found {kind_name(value)} {value!r}", path=self.sub(key))
            return default
        if isinstance(value, str) and kind is str:
            problem = text_problem(value)
            if problem:
                self.error(node, problem, "write plain text; it is printed into the code of every target",
                           path=self.sub(key))
                return default
        return value  # type: ignore[return-value]  # isinstance(value, kind) was checked above

    def text(self, key: str, default: str | None = None) -> str:
        value = self.get(key, str, default)
        return " ".join(value.split()) if value is not None else ""

    def integer(self, key: str, default: int | None = None) -> int:
        value = self.get(key, int, default)
        return value if value is not None else 0

    def section(self, key: str) -> Reader:
        """A required mapping; when it is missing (reported once), a reader that yields defaults silently."""
        node = self.child(key)
        if node is None:
            node = Node(INVALID, self.node.location, self.node.location)
        return Reader(node, self.sub(key), self.errors)

    def entries(self, key: str) -> list[tuple[str, Node]]:
        node = self.child(key)
        if node is None:
            return []
        if not isinstance(node.value, dict):
            if node.value is not INVALID:
                self.error(node, f"expected a mapping, found {kind_name(node.value)}", path=self.sub(key))
            return []
        if not node.children:
            self.error(node, "must not be empty", path=self.sub(key))
        return list(node.children.items())

    def finish(self) -> None:
        """Report keys nobody asked for, with the nearest known key as a hint."""
        if not self.ok:
            return
        for key, node in self.node.children.items():
            if key not in self.seen:
                near = close_matches(key, sorted(self.seen))
                hint = f"did you mean '{near[0]}'?" if near else "known keys: " + ", ".join(sorted(self.seen))
                self.errors.append(SpecError(node.key_location, self.sub(key), f"unknown key '{key}'", hint))


def text_problem(value: str) -> str | None:
    if len(value) > MAX_TEXT:
        return f"text of {len(value)} characters is longer than {MAX_TEXT}"
    bad = _BAD_TEXT.search(value.replace("\n", " "))
    if bad is None:
        # Unicode format and separator characters (bidi overrides, U+2028...) can hide or reorder code
        hidden = next((c for c in value if not c.isprintable() and c != "\n"), None)
        return None if hidden is None else f"text contains U+{ord(hidden):04X}, an invisible or control character"
    return f"text contains {bad.group()!r}, which could break out of a comment or string in generated code"


def kind_name(value: object) -> str:
    if value is None:
        return "nothing"
    return {bool: "a boolean", int: "an integer", float: "a number", str: "text", list: "a list",
            dict: "a mapping"}.get(type(value), type(value).__name__)


def type_name(kind: type) -> str:
    return {int: "an integer", str: "text", bool: "a boolean", list: "a list", dict: "a mapping"}[kind]


def is_int(node: Node | None) -> bool:
    return node is not None and isinstance(node.value, int) and not isinstance(node.value, bool)


def is_code(code: str) -> bool:
    """One printable ASCII character other than a space: what a category, direction or error code may be."""
    return len(code) == 1 and 0x21 <= ord(code) <= 0x7E


def is_letter_code(code: str) -> bool:
    """One ASCII letter or digit: what an error, state or laser code of a reply may be."""
    return is_code(code) and code.isalnum()


def unique_code(r: Reader, kind: str, name: str, codes: dict[str, str]) -> str | None:
    """The `code` of entry `name` if it is one letter or digit that no other entry of `codes` took (then it is
    recorded there); otherwise None, with the error reported at the code."""
    code = r.text("code")
    if not is_letter_code(code):
        r.error(r.node.children.get("code", r.node), f"{kind} code {code!r} is not one letter or digit",
                path=r.sub("code"))
        return None
    if code in codes:
        r.error(r.node.children["code"], f"{kind} code '{code}' is already used by {codes[code]}",
                path=r.sub("code"))
        return None
    codes[code] = name
    return code
