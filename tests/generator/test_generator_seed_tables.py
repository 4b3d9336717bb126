"""The seed document's Tables 1-6, pinned on purpose against the LIVE spec and every target generated from it.

This is the one test file that fails when spec/drone.yaml changes what the seed says a frame means (every
other generator test works on a frozen copy, tests/generator/specs/drone.yaml). Adding commands, categories or
errors leaves it green; changing a seed code, name, range or speed makes it fail with the table it pins:
change it together with the spec.
"""

from __future__ import annotations

import re

import drone_protocol as p
import protocol_harness as h
import pytest


def pins(table: int) -> str:
    return f"this pins the seed's Table {table}; change it together with the spec"


# Table 4, copied as printed (its "Maximum"/"Minimum" rows are swapped: min/max below are by value).
SEED_TABLE_4 = {
    "yaw": {"min": 1035, "max": 2012, "median": 1524, "low": 1424, "high": 1624},
    "roll": {"min": 1000, "max": 2000, "median": 1500, "low": 1400, "high": 1600},
    "pitch": {"min": 1000, "max": 2000, "median": 1500, "low": 1400, "high": 1600},
    "throttle": {"min": 1029, "max": 2012, "median": 1521, "low": 1421, "high": 1621},
}
DOC_ROWS = {"min": "Minimum speed recorded", "max": "Maximum speed recorded", "median": "Median of recorded speeds",
            "low": "40 % speed", "high": "60 % speed"}
# Table 1: first byte -> hardware.
SEED_TABLE_1 = {"m": "Motors/Propellers", "s": "Servos", "l": "Laser", "t": "Motors/Propellers", "i": "*"}
# Tables 2 and 3 (with the spec's Settled: decisions): frame prefix -> (direction word, speed, channel).
SEED_MOVES = {
    2: {"mf": ("forward", 1600, "pitch"), "mb": ("backward", 1400, "pitch"), "ml": ("left", 1400, "roll"),
        "mr": ("right", 1600, "roll"), "mu": ("up", 1621, "throttle"), "md": ("down", 1421, "throttle")},
    3: {"tl": ("left", 1424, "yaw"), "tr": ("right", 1624, "yaw")},
}
# Table 5: prefix -> (servo, range); sx resets both.
SEED_TABLE_5 = {"su": ("tilt", 1, 180), "sd": ("tilt", 1, 180), "sl": ("pan", 1, 180), "sr": ("pan", 1, 180),
                "sx": ("both", 0, 0)}
# Table 6: prefix -> the firmware routine.
SEED_TABLE_6 = {"ia": "arm()", "ik": "disarm()", "is": "setAltitude()", "it": "firstTest()"}


def by_prefix(prefix: str, table: int) -> p.CommandSpec:
    found = [s for s in p.COMMANDS.values() if s.prefix == prefix.encode()]
    assert len(found) == 1, f"no command {prefix}: {pins(table)}"
    return found[0]


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


def test_table_1_categories() -> None:
    docs = (h.GENERATED / "docs" / "protocol.md").read_text()
    for code, hardware in SEED_TABLE_1.items():
        assert any(c.value == code for c in p.Category), f"category {code!r} is gone: {pins(1)}"
        assert re.search(rf"\| `{re.escape(code)}` \| {re.escape(hardware)} \|", docs), \
            f"category {code!r} is not {hardware}: {pins(1)}"


@pytest.mark.parametrize("table", sorted(SEED_MOVES))
def test_tables_2_and_3_movements_and_turns(table: int) -> None:
    for prefix, (word, speed, channel) in SEED_MOVES[table].items():
        spec = by_prefix(prefix, table)
        assert spec.name.endswith(word), f"{prefix} is {spec.name}, the seed's {word}: {pins(table)}"
        assert (spec.default, spec.target) == (speed, channel), f"{prefix}: {pins(table)}"


def test_the_docs_reproduce_table_4() -> None:
    assert docs_table_4() == SEED_TABLE_4, pins(4)


def test_the_python_module_reproduces_table_4() -> None:
    assert {name: {"min": c.minimum, "max": c.maximum, "median": c.median, "low": c.low, "high": c.high}
            for name, c in p.CHANNELS.items() if name in SEED_TABLE_4} == SEED_TABLE_4, pins(4)


def test_the_cpp_header_reproduces_table_4() -> None:
    header = h.header_text()
    for channel, figures in SEED_TABLE_4.items():
        for key, value in figures.items():
            match = re.search(rf"constexpr uint16_t {channel.upper()}_{key.upper()} = (\d+);", header)
            assert match is not None and int(match[1]) == value, f"{channel} {key}: {pins(4)}"


def test_move_and_turn_ranges_are_the_recorded_extremes_of_table_4() -> None:
    for prefix, (_, _, channel) in (SEED_MOVES[2] | SEED_MOVES[3]).items():
        spec = by_prefix(prefix, 4)
        figures = SEED_TABLE_4[channel]
        assert (spec.minimum, spec.maximum) == (figures["min"], figures["max"]), f"{prefix}: {pins(4)}"


def test_table_5_servos() -> None:
    for prefix, (servo, lo, hi) in SEED_TABLE_5.items():
        spec = by_prefix(prefix, 5)
        assert (spec.target, spec.minimum, spec.maximum) == (servo, lo, hi), f"{prefix}: {pins(5)}"
    assert p.decode(b"sr0045").value == 45, pins(5)


def test_the_laser_frame() -> None:
    assert p.decode(b"l00000").category.value == "l", "l00000 is the seed's laser toggle: " + pins(1)


def test_table_6_routines() -> None:
    docs = (h.GENERATED / "docs" / "protocol.md").read_text()
    for prefix, routine in SEED_TABLE_6.items():
        spec = by_prefix(prefix, 6)
        # the seed's frame (value 0) stays valid; hold_altitude also takes form 1, the pilot's safe keep-alive
        # (spec fields.form: no single corrupted byte turns is0001 into another command)
        assert spec.minimum == 0 and p.decode(prefix.encode() + b"0000").value == 0, f"{prefix}: {pins(6)}"
        assert spec.maximum == (1 if spec.name == "hold_altitude" else 0), f"{prefix}: {pins(6)}"
        assert f"`{routine}`" in docs, f"{prefix} no longer calls {routine}: {pins(6)}"
