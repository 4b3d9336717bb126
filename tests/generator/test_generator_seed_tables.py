"""Every figure of the seed document's Table 4 comes out of the spec's formula, on every target."""

from __future__ import annotations

import re

import drone_protocol as p
import protocol_harness as h
import pytest

# The seed's Table 4, copied as printed (its "Maximum"/"Minimum" rows are swapped: min/max below are by value).
SEED_TABLE_4 = {
    "yaw": {"min": 1035, "max": 2012, "median": 1524, "low": 1424, "high": 1624},
    "roll": {"min": 1000, "max": 2000, "median": 1500, "low": 1400, "high": 1600},
    "pitch": {"min": 1000, "max": 2000, "median": 1500, "low": 1400, "high": 1600},
    "throttle": {"min": 1029, "max": 2012, "median": 1521, "low": 1421, "high": 1621},
}
DOC_ROWS = {"min": "Minimum speed recorded", "max": "Maximum speed recorded", "median": "Median of recorded speeds",
            "low": "40 % speed", "high": "60 % speed"}


def docs_table_4() -> dict[str, dict[str, int]]:
    docs = (h.GENERATED / "docs" / "protocol.md").read_text()
    section = docs.split("## Table 4", 1)[1].split("\n## ", 1)[0]
    rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in section.splitlines()
            if line.startswith("|")]
    header = [c.lower() for c in rows[0][1:]]
    table: dict[str, dict[str, int]] = {name: {} for name in header}
    for key, label in DOC_ROWS.items():
        row = next(r for r in rows if r[0].startswith(label))
        for name, cell in zip(header, row[1:], strict=True):
            table[name][key] = int(cell)
    return table


def test_the_docs_reproduce_table_4() -> None:
    assert docs_table_4() == SEED_TABLE_4


def test_the_python_module_reproduces_table_4() -> None:
    assert {name: {"min": c.minimum, "max": c.maximum, "median": c.median, "low": c.low, "high": c.high}
            for name, c in p.CHANNELS.items()} == SEED_TABLE_4


def test_the_cpp_header_reproduces_table_4() -> None:
    header = h.header_text()
    for channel, figures in SEED_TABLE_4.items():
        for key, value in figures.items():
            pattern = rf"constexpr uint16_t {channel.upper()}_{key.upper()} = (\d+);"
            match = re.search(pattern, header)
            assert match is not None and int(match[1]) == value, (channel, key)


@pytest.mark.parametrize(("command", "channel", "speed"), [
    ("move_forward", "pitch", "high"), ("move_backward", "pitch", "low"), ("move_left", "roll", "low"),
    ("move_right", "roll", "high"), ("move_up", "throttle", "high"), ("move_down", "throttle", "low"),
    ("turn_left", "yaw", "low"), ("turn_right", "yaw", "high"),
])
def test_default_speeds_and_ranges_come_from_table_4(command: str, channel: str, speed: str) -> None:
    spec = p.COMMANDS[command]
    figures = SEED_TABLE_4[channel]
    assert (spec.default, spec.minimum, spec.maximum, spec.target) == (figures[speed], figures["min"],
                                                                      figures["max"], channel)
