"""A throttle dead band as wide as the speed step or wider is a spec error, located where the band (or, with no
flight_controller section, ArduCopter's default band) meets the step: every climb and descent would be swallowed."""

from __future__ import annotations

from pathlib import Path

import protocol_harness as h
import pytest


def generate(tmp_path: Path, *edits: tuple[str, str]) -> tuple[h.Run, str, Path]:
    text = h.edited_spec(*edits)
    spec = tmp_path / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    return h.generate("--spec", spec, "--out", tmp_path / "out"), text, spec


@pytest.mark.parametrize("edits,anchor,message", [
    ((("throttle_dead_band: 10", "throttle_dead_band: 102"),), "102",
     "flight_controller.throttle_dead_band: throttle_dead_band 102 is 100 µs of the throttle's 983 µs, as wide as the "
     "speed step (100 µs) or wider: a move up or down at the step, and the landing routine's descent, would not move "
     "the drone (hint: set flight_controller.throttle_dead_band to at most 101 (ArduCopter's THR_DZ), or raise "
     "speeds.step_us)"),
    ((("throttle_dead_band: 10", "throttle_dead_band: 100"), ("step_us: 100", "step_us: 70")), "100",
     "flight_controller.throttle_dead_band: throttle_dead_band 100 is 98 µs of the throttle's 983 µs, as wide as the "
     "speed step (70 µs) or wider: a move up or down at the step, and the landing routine's descent, would not move "
     "the drone (hint: set flight_controller.throttle_dead_band to at most 71 (ArduCopter's THR_DZ), or raise "
     "speeds.step_us)"),
])
def test_a_dead_band_that_swallows_the_step_is_an_error_where_it_is(tmp_path: Path, edits: tuple[tuple[str, str], ...],
                                                                    anchor: str, message: str) -> None:
    run, text, spec = generate(tmp_path, *edits)
    assert run.code == 2, run.stdout
    lines = run.stderr.splitlines()
    assert lines[0] == f"{spec}: 1 error; nothing was written", run.stderr
    line = h.location(text, edits[0][1]).split(":")[0]
    column = text.splitlines()[int(line) - 1].index(anchor) + 1
    assert lines[1] == f"{spec}:{line}:{column}: {message}", run.stderr
    assert "Traceback" not in run.stderr and not (tmp_path / "out").exists()


def test_without_the_section_arducopters_default_band_is_checked_against_the_step(tmp_path: Path) -> None:
    text = h.spec_text()
    start = text.index("# How ArduCopter must read the sticks")
    end = text.index("throttle_dead_band: 10\n") + len("throttle_dead_band: 10\n")
    text = (text[:start] + text[end:]).replace("step_us: 100", "step_us: 90")
    spec = tmp_path / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    run = h.generate("--spec", spec, "--out", tmp_path / "out")
    assert run.code == 2, run.stdout
    line = h.location(text, "step_us: 90").split(":")[0]
    assert f"{spec}:{line}:12: speeds.step_us: ArduCopter's default" in run.stderr, run.stderr
    assert "speeds.step_us: ArduCopter's default throttle dead band 100 is 98 µs" in run.stderr, run.stderr


@pytest.mark.parametrize("band,step", [(101, 100), (10, 70), (10, 150), (0, 70)])
def test_a_band_narrower_than_the_step_is_accepted(tmp_path: Path, band: int, step: int) -> None:
    run, _, _ = generate(tmp_path, ("throttle_dead_band: 10", f"throttle_dead_band: {band}"),
                         ("step_us: 100", f"step_us: {step}"))
    assert run.code == 0, run.stderr
