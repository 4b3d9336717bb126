"""Jinja filters that spell model values safely in each target language."""

from __future__ import annotations

import json
import re
import textwrap
from collections.abc import Callable
from typing import Any

from .model import check_text
from .names import pascal


class Safe(str):
    """Text a filter already made safe for its target (e.g. Markdown code): not escaped again."""


def _escape(text: str) -> str:
    """html.escape(text, quote=False), without importing html's table of 2,000 entities on every run."""
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def html_text(value: object) -> object:
    """Jinja's finalize for Markdown: spec text never becomes HTML (`<img onerror=...>` prints as text)."""
    if isinstance(value, str) and not isinstance(value, Safe):
        return _escape(value)
    return value


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


# -- Rust and C99 targets -------------------------------------------------------------------------------------
RUST_KEYWORDS = frozenset(
    """as async await break const continue crate dyn else enum extern false fn for if impl in let loop match mod
    move mut pub ref return static struct trait true type unsafe use where while abstract become box do final
    macro override priv try typeof unsized virtual yield gen""".split()
)


def rust_ident(name: str) -> str:
    """A Rust identifier for a spec name: a keyword becomes a raw identifier (`r#move`)."""
    return f"r#{name}" if name in RUST_KEYWORDS else name


def rust_byte(code: str) -> str:
    """A Rust byte literal for one ASCII character."""
    return "b'\\''" if code == "'" else "b'\\\\'" if code == "\\" else f"b'{code}'"


def rust_string(text: str) -> str:
    """A Rust string literal of printable ASCII text (and newlines)."""
    return cpp_string(text)


def check_hex(text: str) -> str:
    """The crc8 integrity check of ASCII text, as the two hex digits the wire carries."""
    return check_text(text.encode("ascii"))


def initials(name: str) -> str:
    """The C99 target's prefix of a snake_case name: drone_protocol -> dp."""
    return "".join(part[0] for part in name.split("_") if part)


def md_cell(text: str) -> str:
    return text.replace("|", "\\|")


_MD_PUNCTUATION = re.compile(r"([\\`*_\[\]#|~])")
_MD_LINE_START = re.compile(r"^(\d*)([-+=.)])")  # a list item, a setext underline or a thematic break


def md_text(text: str) -> str:
    """Spec text inert in a package README (CommonMark, as PyPI, crates.io, npm and GitHub render it): HTML's
    & < > become entities, and every character Markdown reads as syntax (emphasis, links, images, code, headings,
    tables, strikethrough; lists and rules at the start) gets a backslash, which CommonMark drops when it shows
    the text. The text is one line (the reader joins a value's whitespace)."""
    escaped = _escape(text)
    escaped = _MD_PUNCTUATION.sub(r"\\\1", escaped)
    return Safe(_MD_LINE_START.sub(r"\1\\\2", escaped))


def md_code(text: str) -> str:
    """Inline Markdown code that survives backticks and surrounding spaces."""
    return Safe(f"`` {text} ``" if "`" in text or text != text.strip() else f"`{text}`")


def frame_text(frame: bytes) -> str:
    """A frame for prose: printable ASCII as is, anything else as \\xNN."""
    return "".join(chr(b) if 0x20 <= b < 0x7F else f"\\x{b:02x}" for b in frame)


def regex_class(characters: str) -> str:
    """The inside of a regular expression's [...] for a set of letters, digits and '_': runs become ranges."""
    codes = sorted(set(map(ord, characters)))
    assert all(chr(c).isalnum() or chr(c) == "_" for c in codes), characters
    out, start = [], 0
    for i in range(1, len(codes) + 1):
        if i == len(codes) or codes[i] != codes[i - 1] + 1:
            run = codes[start:i]
            out.append(f"{chr(run[0])}-{chr(run[-1])}" if len(run) > 2 else "".join(map(chr, run)))
            start = i
    return "".join(out)


def block_comment(text: str) -> str:
    """Text for a C or JSDoc block comment: a frame's codes may be `*` then `/` (the comment would end) or `/`
    then `*` (GCC's -Wcomment); each gets the backslash JSDoc uses, shown as is in C."""
    return text.replace("*/", "*\\/").replace("/*", "/\\*")


def wrap(text: str, width: int = 100, prefix: str = "") -> str:
    """Text wrapped to `width` columns, every line after the first starting with `prefix`."""
    return textwrap.fill(text, width=width, subsequent_indent=prefix, break_on_hyphens=False)


def one_in(p: float) -> str:
    """A small probability as "1 in N" (N rounded to 3 significant digits), or "never"."""
    return "never" if p == 0 else f"1 in {float(f'{1 / p:.3g}'):,.0f}"


# json.dumps(v, sort_keys=True), without making an encoder for each of the 2,800 values the templates print
_TO_JSON = json.JSONEncoder(sort_keys=True)

ALL: dict[str, Callable[..., Any]] = {
    "cpp_char": cpp_char,
    "cpp_string": cpp_string,
    "py_string": py_string,
    "py_bytes": py_bytes,
    "docstring": docstring,
    "rust_ident": rust_ident,
    "rust_byte": rust_byte,
    "rust_string": rust_string,
    "initials": initials,
    "check_hex": check_hex,
    "md_cell": md_cell,
    "md_code": md_code,
    "md_text": md_text,
    "one_in": one_in,
    "pascal": pascal,
    "upper": str.upper,
    "frame_text": frame_text,
    "wrap": wrap,
    "block_comment": block_comment,
    "regex_class": regex_class,
    "tojson": _TO_JSON.encode,
    "add_suffix": lambda text, suffix: f"{text}{suffix}",
}
