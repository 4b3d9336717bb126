"""The C++ type of every number the generated code declares, and the check that each value fits its type.

One table: the C++ template prints its constants' types from it (`ctype.NAME`), and the builder rejects any
spec whose value, length or count would not fit, with the location of what the spec wrote. A value that does
not fit is never truncated: C++ would silently print another number than Python (66486 µs becomes 950).
Python ints are unbounded and need no entry.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from .model import Spec
from .records import record


@record
class CType:
    name: str
    minimum: int
    maximum: int

    def __str__(self) -> str:  # templates print `{{ ctype.BAUD }}`
        return self.name


UINT8 = CType("uint8_t", 0, 0xFF)
INT8 = CType("int8_t", -0x80, 0x7F)
UINT16 = CType("uint16_t", 0, 0xFFFF)
UINT32 = CType("uint32_t", 0, 0xFFFFFFFF)

# Scalar constants: C++ name -> (type, the model's attribute, where the spec writes it).
SCALARS: Mapping[str, tuple[CType, str, str]] = MappingProxyType({
    "PROTOCOL_VERSION": (UINT16, "version", "protocol.version"),
    "FRAME_LENGTH": (UINT8, "frame_length", "frame.length"),
    "VALUE_WIDTH": (UINT8, "digits_width", "frame.length"),
    "BAUD": (UINT32, "baud", "link.baud"),
    "INTER_BYTE_TIMEOUT_MS": (UINT16, "inter_byte_timeout_ms", "frame.inter_byte_timeout_ms"),
    "READY_TIMEOUT_MS": (UINT16, "ready_timeout_ms", "link.ready_timeout_ms"),
    "COMMAND_TIMEOUT_MS": (UINT16, "command_timeout_ms", "safety.command_timeout_ms"),
    "FAILSAFE_TIMEOUT_MS": (UINT16, "failsafe_timeout_ms", "safety.failsafe_timeout_ms"),
    "FAILSAFE_THROTTLE_US": (UINT16, "failsafe_throttle_us", "safety.failsafe_throttle_us"),
    "ARMING_HOLD_MS": (UINT16, "arming_hold_ms", "safety.arming_hold_ms"),
    "LANDING_MS": (UINT16, "landing_ms", "safety.landing_ms"),
    "MODE_STABILIZE_US": (UINT16, "mode_stabilize_us", "flight_modes.stabilize_us"),
    "MODE_ALT_HOLD_US": (UINT16, "mode_alt_hold_us", "flight_modes.alt_hold_us"),
    "SPEED_STEP_US": (UINT16, "speed_step_us", "speeds.step_us"),
    "REPLY_MAX_LENGTH": (UINT8, "reply_max_length", "replies"),  # the reply writers count bytes in a uint8_t
})

# Families of numbers. The C++ template must use these types where it declares them.
CTYPES: Mapping[str, CType] = MappingProxyType({
    **{name: ctype for name, (ctype, _, _) in SCALARS.items()},
    "channel": UINT16,  # <CHANNEL>_MIN/_MAX/_MEDIAN/_LOW/_HIGH, ChannelLimits
    "servo": UINT8,  # SERVO_<NAME>_MIN/_MAX/_DEFAULT
    "value": UINT16,  # a command's value, minimum, maximum and default (Command, CommandInfo)
    # CommandId: uint8_t up to 254 commands, uint16_t beyond (the template picks); 94 x 94 codes fit either way
    "command_index": UINT16,
    "count": UINT8,  # CATEGORY_COUNT, CHANNEL_COUNT and the Target and Error enums (with their None)
})


@record
class Constant:
    """A number the C++ target declares: its name there, type, value and where the spec writes it."""

    name: str
    ctype: CType
    value: int
    path: str


def constants(spec: Spec) -> tuple[Constant, ...]:
    """Every named number of the C++ target, in a stable order."""
    out = [Constant(name, ctype, getattr(spec, attr), path) for name, (ctype, attr, path) in SCALARS.items()]
    for c in spec.channels:
        for suffix, value in (("MIN", c.recorded_min), ("MAX", c.recorded_max), ("MEDIAN", c.median),
                              ("LOW", c.low), ("HIGH", c.high)):
            out.append(Constant(f"{c.name.upper()}_{suffix}", CTYPES["channel"], value, f"channels.{c.name}.recorded"))
    for s in spec.servos:
        for suffix, value in (("MIN", s.min_deg), ("MAX", s.max_deg), ("DEFAULT", s.default_deg)):
            out.append(Constant(f"SERVO_{s.name.upper()}_{suffix}", CTYPES["servo"], value, f"servos.{s.name}"))
    count = CTYPES["count"]
    out.append(Constant("COMMAND_COUNT", CTYPES["command_index"], len(spec.commands), "categories"))
    out.append(Constant("CATEGORY_COUNT", count, len(spec.categories), "categories"))
    out.append(Constant("CHANNEL_COUNT", count, len(spec.channels), "channels"))
    return tuple(out)


def overflows(spec: Spec) -> list[tuple[str, str]]:
    """(spec path, message) for every number that would not fit the C++ type it becomes."""
    problems = [(c.path, f"{c.name} = {c.value} does not fit its C++ type {c.ctype} "
                         f"({c.ctype.minimum}..{c.ctype.maximum})")
                for c in constants(spec) if not c.ctype.minimum <= c.value <= c.ctype.maximum]
    value = CTYPES["value"]
    for cmd in spec.commands:
        d = cmd.direction
        for what, number in (("minimum", d.minimum), ("maximum", d.maximum), ("default", d.default)):
            if number is not None and not value.minimum <= number <= value.maximum:
                problems.append((f"categories.{cmd.category.code}.directions.{d.code}",
                                 f"{d.command}'s {what} {number} does not fit its C++ type {value}"))
    # The enums hold every entry and their None (and Target its "both").
    count = CTYPES["count"]
    for path, size in (("errors", len(spec.errors) + 1), ("servos", len(spec.targets) + 1)):
        if size > count.maximum:
            problems.append((path, f"{size - 1} entries do not fit the C++ enum's {count}"))
    return problems
