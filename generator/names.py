"""Which names are usable as identifiers in every target language, and how each target spells them."""

from __future__ import annotations

import keyword
import pkgutil
import re
import sys
import sysconfig
from collections.abc import Iterable
from pathlib import Path

IDENTIFIER = re.compile(r"^[a-z][a-z0-9]*(_[a-z0-9]+)*$")

CPP_KEYWORDS = frozenset(
    """alignas alignof and and_eq asm auto bitand bitor bool break case catch char char16_t char32_t class
    compl const constexpr const_cast continue decltype default delete do double dynamic_cast else enum explicit
    export extern false float for friend goto if inline int long mutable namespace new noexcept not not_eq
    nullptr operator or or_eq private protected public register reinterpret_cast return short signed sizeof
    static static_assert static_cast struct switch template this thread_local throw true try typedef typeid
    typename union unsigned using virtual void volatile wchar_t while xor xor_eq final override""".split()
)

# Macros of the Arduino core and avr-libc that would silently rewrite a generated name.
ARDUINO_MACROS = frozenset(
    """min max abs constrain round radians degrees sq interrupts noInterrupts clockCyclesPerMicrosecond
    lowByte highByte bitRead bitSet bitClear bitWrite bit cli sei F isnan isinf putc getc""".split()
)

# Builtins the generated Python module calls: a module-level command function of the same name would replace them.
PYTHON_BUILTINS_USED = frozenset(
    """bool bytearray bytes chr dict float int isinstance iter len list next object ord property range repr
    sorted str super tuple type""".split()
)

# Names the generated code itself defines or uses at module or namespace level: a command function of the
# same name would replace them.
GENERATED_NAMES = frozenset(
    """encode decode dispatch command_info command_name channel_limits error_name error_code parse_reply
    ready_line accepted_line rejected_line failsafe_line write_ready write_accepted write_rejected
    write_failsafe stream_parser stream_decoder command category direction value name error reply time
    dataclass annotations detail find_command find_command_by_name command_default missing_value command_min
    command_max command_target command_sense state_code state_name state_armed""".split()
) | PYTHON_BUILTINS_USED

MAX_NAME = 40  # a name becomes a file name, a C++ macro prefix and a Python identifier: keep it readable

# The protocol's name is also a Python package (it must not shadow a standard module: `import os` would
# load the generated codec), a C++ namespace and, in PascalCase, an Arduino library and its header file
# (it must not replace the core's or a bundled library's header).
if sys.version_info >= (3, 10):
    STDLIB_MODULES = frozenset(sys.stdlib_module_names)
else:  # Python 3.9: the modules in the standard library's folders and those built into the interpreter
    _STDLIB_DIRS = [sysconfig.get_path("stdlib"), str(Path(sysconfig.get_path("platstdlib")) / "lib-dynload")]
    STDLIB_MODULES = frozenset(m.name for m in pkgutil.iter_modules(_STDLIB_DIRS)) | frozenset(sys.builtin_module_names)
PROTOCOL_RESERVED = STDLIB_MODULES | frozenset(
    """std posix detail arduino eeprom hid keyboard mouse servo software_serial spi wire stepper ethernet sd
    generator pilot drone_sim""".split()
)

RESERVED = frozenset(keyword.kwlist) | frozenset(keyword.softkwlist) | CPP_KEYWORDS | ARDUINO_MACROS


def identifier_problem(name: str, python_only: bool = False) -> str | None:
    """Why `name` cannot be used as a generated identifier, or None.

    `python_only` is for names printed only into Python (argument names: C++ takes a `value`)."""
    if len(name) > MAX_NAME:
        return f"'{name[:MAX_NAME]}...' is longer than {MAX_NAME} characters"
    if not IDENTIFIER.match(name):
        return f"'{name}' is not a lower_snake_case identifier (letters, digits, single underscores)"
    if python_only:
        return f"'{name}' is a Python keyword" if keyword.iskeyword(name) or keyword.issoftkeyword(name) else None
    if name in RESERVED:
        return f"'{name}' is a reserved word in a target language"
    if name in GENERATED_NAMES:
        return f"'{name}' clashes with a name the generated code defines"
    return None


def protocol_name_problem(name: str) -> str | None:
    """Why `name` cannot name the protocol (its Python package, C++ namespace and Arduino library), or None."""
    problem = identifier_problem(name)
    if problem is None and name in PROTOCOL_RESERVED:
        problem = f"'{name}' would shadow a standard Python module or an Arduino library of that name"
    return problem


def pascal(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("_"))


def upper(name: str) -> str:
    return name.upper()


_UNSAFE_IN_NAME = re.compile(r"[^A-Za-z0-9._+-]|-(?=-)")


def safe_file_name(path: Path) -> str:
    """The spec's base name as printed into generated files: only characters inert in every target's comments
    and strings (no newline, quote, `*/`, `-->`); anything else becomes '_'."""
    return _UNSAFE_IN_NAME.sub("_", path.name)[:64] or "spec"


def close_matches(word: str, options: Iterable[str]) -> list[str]:
    """The option nearest to a misspelt `word`, if one is near enough (difflib, imported only for a bad spec)."""
    import difflib

    return difflib.get_close_matches(word, list(options), n=1)
