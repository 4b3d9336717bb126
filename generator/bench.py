"""The docs' bench table: what the firmware puts on each RC output at each step of a props-off bench test.

Each row names the generated C++ constants the firmware drives in that state (firmware/drone/drone_logic.cpp:
Drone::begin, enter, enter_failsafe); their values are read from the generated C++ header rendered in the same
run, never typed here, so the table prints what the firmware outputs. tests/firmware/test_firmware_bench_table.py
runs the firmware through the same steps and compares every cell."""

from __future__ import annotations

import re

from .model import Spec
from .records import record

_CONSTANT = re.compile(r"^constexpr\s+\w+\s+([A-Z][A-Z0-9_]*)\s*=\s*(\d+);", re.MULTILINE)
KEPT = ""  # a cell the step leaves as it was


@record
class Step:
    when: str  # the row's first cell; {ARMING_HOLD_MS} and the like are filled from the header
    changes: tuple[tuple[str, str], ...]  # (channel or "mode", constant) where the step differs from neutral


STEPS = (
    Step("powered up, disarmed (until the first arming: a boot may be a reset in flight)",
         (("throttle", "FAILSAFE_THROTTLE_US"), ("mode", "MODE_STABILIZE_US"))),
    Step("arming (for {ARMING_HOLD_MS} ms)",
         (("throttle", "THROTTLE_MIN"), ("yaw", "YAW_MAX"), ("mode", "MODE_STABILIZE_US"))),
    Step("armed, on the ground", (("throttle", "THROTTLE_MIN"), ("mode", "MODE_STABILIZE_US"))),
    Step("disarming (for {ARMING_HOLD_MS} ms)",
         (("throttle", "THROTTLE_MIN"), ("yaw", "YAW_MIN"), ("mode", "MODE_STABILIZE_US"))),
    Step("the Pi silent for {FAILSAFE_TIMEOUT_MS} ms (failsafe)",
         (("throttle", "FAILSAFE_THROTTLE_US"), ("mode", KEPT))),
)


@record
class Row:
    when: str
    cells: tuple[str, ...]  # one per spec channel, then the mode: a pulse width in us, or "kept"


def constants(header: str) -> dict[str, int]:
    """Every `constexpr <type> NAME = <number>;` of the generated C++ header."""
    return {name: int(value) for name, value in _CONSTANT.findall(header)}


def table(spec: Spec, header: str) -> tuple[Row, ...]:
    values = constants(header)
    rows = []
    for step in STEPS:
        wanted = {name: f"{name.upper()}_MEDIAN" for name in (c.name for c in spec.channels)} | dict(step.changes)
        cells = [str(values[wanted[c.name]]) for c in spec.channels]
        cells.append(str(values[wanted["mode"]]) if wanted["mode"] else "kept")
        rows.append(Row(step.when.format(**values), tuple(cells)))
    return tuple(rows)
