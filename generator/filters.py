"""Jinja filters that spell model values safely in each target language."""

from __future__ import annotations

import json
import textwrap
from collections.abc import Callable
from typing import Any

from .names import pascal


def cpp_char(code: str) -> str:
    """A C++ character literal for one printable ASCII character."""
    return "'\\''" if code == "'" else "'\\\\'" if code == "\\" else f"'{code}'"


def cpp_string(text: str) -> str:
    """A C++ string literal of printable ASCII text (and newlines)."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def py_string(text: str) -> str:
    """A double-quoted Python literal (JSON escapes are valid Python escapes)."""
    return json.dumps(text)


def py_bytes(text: str) -> str:
    """A Python bytes literal of ASCII text."""
    return repr(text.encode("ascii"))


def docstring(text: str) -> str:
    """Text safe inside a triple-quoted docstring: codes may be a backslash or a quote."""
    return text.replace("\\", "\\\\").replace('"', '\\"')


def md_cell(text: str) -> str:
    return text.replace("|", "\\|")


def md_code(text: str) -> str:
    """Inline Markdown code that survives backticks and surrounding spaces."""
    return f"`` {text} ``" if "`" in text or text != text.strip() else f"`{text}`"


def frame_text(frame: bytes) -> str:
    """A frame for prose: printable ASCII as is, anything else as \\xNN."""
    return "".join(chr(b) if 0x20 <= b < 0x7F else f"\\x{b:02x}" for b in frame)


def wrap(text: str, width: int = 100, prefix: str = "") -> str:
    """Text wrapped to `width` columns, every line after the first starting with `prefix`."""
    return textwrap.fill(text, width=width, subsequent_indent=prefix, break_on_hyphens=False)


ALL: dict[str, Callable[..., Any]] = {
    "cpp_char": cpp_char,
    "cpp_string": cpp_string,
    "py_string": py_string,
    "py_bytes": py_bytes,
    "docstring": docstring,
    "md_cell": md_cell,
    "md_code": md_code,
    "pascal": pascal,
    "upper": str.upper,
    "frame_text": frame_text,
    "wrap": wrap,
    "tojson": lambda v: json.dumps(v, sort_keys=True),
}
