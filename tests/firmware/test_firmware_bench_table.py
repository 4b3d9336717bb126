"""The docs' bench table (generated/docs/protocol.md, "Bench test, propellers off") says what the firmware
outputs: the virtual drone (the firmware's own sources, host build) is run through the table's steps and every
cell compared with its RC outputs; and each constant the table's rows name is one the firmware's logic uses."""

from __future__ import annotations

import re

import drone_protocol as dp
import fwsupport as fw
import pytest

from generator import bench

DOCS = fw.ROOT / "generated" / "docs" / "protocol.md"
LOGIC = fw.ROOT / "firmware" / "drone" / "drone_logic.cpp"


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


def bench_table() -> list[list[str]]:
    text = DOCS.read_text(encoding="utf-8")
    section = text[text.index("### Bench test, propellers off"):]
    rows = [line for line in section.splitlines() if line.startswith("| ")]
    header = [cell.strip() for cell in rows[0].strip("|").split("|")]
    assert header == ["when", *dp.CHANNELS, "mode"], header
    return [[cell.strip() for cell in row.strip("|").split("|")] for row in rows[1:len(bench.STEPS) + 1]]


def keep_alive(script: fw.Script, ms: int) -> fw.Script:
    """Let `ms` pass while the Pi keeps the link alive (servo_reset changes nothing: the servos are at rest)."""
    for _ in range(ms // 200):
        script.step(200).send(dp.servo_reset())
    return script.step(5)


def test_every_cell_is_what_the_firmware_outputs_at_that_step() -> None:
    script = fw.Script().step(100)
    boot_ms = script.t_ms
    script.arm()  # sends the arm frame, then keep-alives past the arming hold
    arming_ms = 1 + dp.ARMING_HOLD_MS // 2
    armed_ms = script.t_ms
    script.send(dp.disarm()).step(1)
    disarming_ms = script.t_ms + dp.ARMING_HOLD_MS // 2
    keep_alive(script, dp.ARMING_HOLD_MS + 400)
    script.arm()
    silent_from = script.t_ms
    script.step(dp.FAILSAFE_TIMEOUT_MS + 100)  # the Pi goes silent
    trace = script.run()
    assert trace.state_at(armed_ms)["state"] == "armed" and trace.state_at(disarming_ms)["state"] == "disarming"
    failsafe = trace.first_change(silent_from, state="failsafe")
    moments = [boot_ms, 100 + arming_ms, armed_ms, disarming_ms, failsafe["t_ms"]]
    rows = bench_table()
    assert len(rows) == len(moments) == len(bench.STEPS)
    for row, t_ms in zip(rows, moments, strict=True):
        outputs = trace.state_at(t_ms)
        want = [str(outputs[name]) for name in dp.CHANNELS]
        want.append("kept" if row[-1] == "kept" else str(outputs["mode"]))
        assert row[1:] == want, (row[0], outputs)
    assert rows[0][1 + list(dp.CHANNELS).index("throttle")] == str(dp.FAILSAFE_THROTTLE_US)


def test_the_constants_the_rows_name_are_the_firmwares() -> None:
    logic = LOGIC.read_text(encoding="utf-8")
    used = set(re.findall(r"dp::([A-Z][A-Z0-9_]+)", logic))
    named = {constant for step in bench.STEPS for _, constant in step.changes if constant}
    assert named <= used, named - used
