"""Which names are usable as identifiers in every target language, and how each target spells them."""

from __future__ import annotations

import keyword
import re

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
    dataclass annotations detail""".split()
) | PYTHON_BUILTINS_USED

RESERVED = frozenset(keyword.kwlist) | frozenset(keyword.softkwlist) | CPP_KEYWORDS | ARDUINO_MACROS


def identifier_problem(name: str, python_only: bool = False) -> str | None:
    """Why `name` cannot be used as a generated identifier, or None.

    `python_only` is for names printed only into Python (argument names: C++ takes a `value`)."""
    if not IDENTIFIER.match(name):
        return f"'{name}' is not a lower_snake_case identifier (letters, digits, single underscores)"
    if python_only:
        return f"'{name}' is a Python keyword" if keyword.iskeyword(name) or keyword.issoftkeyword(name) else None
    if name in RESERVED:
        return f"'{name}' is a reserved word in a target language"
    if name in GENERATED_NAMES:
        return f"'{name}' clashes with a name the generated code defines"
    return None


def pascal(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("_"))


def upper(name: str) -> str:
    return name.upper()
