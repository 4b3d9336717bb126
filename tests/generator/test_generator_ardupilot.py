"""generated/ardupilot/arducopter-<line>/drone.parm and drone.params, per ArduCopter line: the .parm read by
pymavlink's parameter-file reader (what MAVProxy's `param load` uses) and a strict parser, the .params by a reader
following QGroundControl's rules; every value checked against the spec and every name against what that
release knows; and the spec checks behind them (the failsafe gap, the wiring, the flight-mode slots, the lines)
reject a spec with file:line:column."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path
from typing import Any

import drone_protocol as dp
import param_readers as pr
import protocol_harness as h
import pytest
import yaml
from pymavlink import mavparm

LINES = ("3.2", "4")
PARM = {key: h.GENERATED / "ardupilot" / f"arducopter-{key}" / "drone.parm" for key in LINES}
PARAMS = {key: path.with_suffix(".params") for key, path in PARM.items()}
# ArduCopter's flight-mode switch: the highest PWM of slots 1-5 (slot 6 above), from its parameter docs.
SLOT_TOPS = (1230, 1360, 1490, 1620, 1749)
FS_THR_VALUE_RANGE = {"3.2": (925, 1100), "4": (910, 1100)}
STICKS = ("roll", "pitch", "throttle", "yaw")


def strict_parse(text: str) -> dict[str, tuple[float, str]]:
    return pr.strict_parm(text)


def spec_field(spec: dict[str, Any], comment: str) -> object:
    """The spec value a comment's first word names, e.g. channels.roll.recorded[0] (KeyError if none)."""
    path = comment.split()[0].rstrip(":")
    node: Any = spec
    for part in re.findall(r"[^.\[\]]+|\[\d+\]", path):
        node = node[int(part[1:-1])] if part.startswith("[") else node[part]
    return node


def slot(pulse_us: int) -> int:
    return next((i + 1 for i, top in enumerate(SLOT_TOPS) if pulse_us <= top), len(SLOT_TOPS) + 1)


def expected(spec: dict[str, Any], line: str) -> dict[str, float]:
    """What the parameters must be, from the spec and the generated Python module. In 3.2.1 RC1_..RC4_ belong to
    roll, pitch, throttle and yaw (radio.pde feeds g.rc_1 from rcmap.roll()), reversal is RCn_REV = -1 and the mode
    switch is always input 5; in 4.x RCn_ is input n, RCn_REVERSED = 1 and FLTMODE_CH names the mode input."""
    order = list(spec["wiring"]["rc_inputs"])
    want: dict[str, float] = {f"RCMAP_{n.upper()}": order.index(n) + 1 for n in STICKS}
    number = {name: (STICKS.index(name) if line == "3.2" else order.index(name)) + 1 for name in spec["channels"]}
    for name in spec["channels"]:
        channel = dp.CHANNELS[name]
        n = number[name]
        want |= {f"RC{n}_MIN": channel.minimum, f"RC{n}_MAX": channel.maximum, f"RC{n}_TRIM": channel.median}
    for name in spec.get("flight_controller", {}).get("reversed", []):
        want |= {f"RC{number[name]}_REV": -1} if line == "3.2" else {f"RC{number[name]}_REVERSED": 1}
    want["THR_DZ"] = spec.get("flight_controller", {}).get("throttle_dead_band", 100)  # ArduCopter's default
    modes = spec["flight_modes"]
    want |= {"FS_THR_ENABLE": 3, f"FLTMODE{slot(modes['stabilize_us'])}": 0, f"FLTMODE{slot(modes['alt_hold_us'])}": 2}
    if line != "3.2":
        want["FLTMODE_CH"] = order.index("mode") + 1
    return want


@pytest.mark.parametrize("line", LINES)
def test_the_parameter_file_matches_the_spec(line: str) -> None:
    spec = yaml.safe_load(h.SPEC.read_text(encoding="utf-8"))
    params = strict_parse(PARM[line].read_text(encoding="utf-8"))
    for _, comment in params.values():
        spec_field(spec, comment)  # every comment names a field of the spec (KeyError otherwise)
    fs_value = params.pop("FS_THR_VALUE")[0]
    assert {name: value for name, (value, _) in params.items()} == expected(spec, line)
    assert spec["safety"]["failsafe_throttle_us"] < fs_value < dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert FS_THR_VALUE_RANGE[line][0] <= fs_value <= FS_THR_VALUE_RANGE[line][1]


@pytest.mark.parametrize("line", LINES)
def test_every_name_is_one_that_line_knows(line: str) -> None:
    names = set(strict_parse(PARM[line].read_text(encoding="utf-8")))
    assert names <= set(pr.KNOWN[line]), names - set(pr.KNOWN[line])


def test_the_apm_line_reverses_pitch_the_way_3_2_1_reads_it() -> None:
    old = strict_parse(PARM["3.2"].read_text(encoding="utf-8"))
    assert old["RC2_REV"][0] == -1 and "RC2_REVERSED" not in old and "FLTMODE_CH" not in old


@pytest.mark.parametrize("line", LINES)
def test_pymavlink_reads_every_parameter(line: str) -> None:
    parm = mavparm.MAVParmDict()
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert parm.load(str(PARM[line]))
    assert "Invalid line" not in printed.getvalue(), printed.getvalue()
    strict = strict_parse(PARM[line].read_text(encoding="utf-8"))
    assert dict(parm) == {name: value for name, (value, _) in strict.items()}


@pytest.mark.parametrize("line", LINES)
def test_qgroundcontrols_reader_loads_every_parameter_of_the_params_file(line: str) -> None:
    load = pr.qgc_read(PARAMS[line].read_text(encoding="utf-8"), pr.KNOWN[line])
    assert not (load.ignored or load.missing or load.type_errors or load.refused), load
    parm = strict_parse(PARM[line].read_text(encoding="utf-8"))
    assert {name: float(value) for name, value in load.loaded.items()} == {n: v for n, (v, _) in parm.items()}


def test_qgroundcontrols_reader_skips_every_line_of_a_parm_file() -> None:
    """Why the .params file exists: QGroundControl up to 4.x loads nothing from NAME,VALUE lines, silently."""
    load = pr.qgc_read(PARM["4"].read_text(encoding="utf-8"), pr.KNOWN["4"])
    assert load.loaded == {} and len(load.ignored) == len(strict_parse(PARM["4"].read_text(encoding="utf-8")))


def test_a_params_file_for_another_vehicle_id_is_refused_by_the_reader() -> None:
    load = pr.qgc_read(PARAMS["4"].read_text(encoding="utf-8"), pr.KNOWN["4"], vehicle_id=2)
    assert load.refused and not load.loaded


def generate(tmp_path: Path, *edits: tuple[str, str]) -> tuple[h.Run, str, Path]:
    text = h.edited_spec(*edits)
    spec = tmp_path / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    return h.generate("--spec", spec, "--out", tmp_path / "out"), text, spec


def test_the_smallest_failsafe_gap_gives_the_value_in_it(tmp_path: Path) -> None:
    minimum = dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    run, _, _ = generate(tmp_path, ("failsafe_throttle_us: 950", f"failsafe_throttle_us: {minimum - 2}"))
    assert run.code == 0, run.stderr
    params = strict_parse((tmp_path / "out" / "ardupilot" / "arducopter-4" / "drone.parm").read_text(encoding="utf-8"))
    assert params["FS_THR_VALUE"][0] == minimum - 1


@pytest.mark.parametrize("failsafe", [0, 1, 100])  # offsets from the throttle minimum - 1
def test_a_spec_without_a_failsafe_gap_is_rejected_where_the_failsafe_throttle_is(tmp_path: Path,
                                                                                  failsafe: int) -> None:
    value = dp.CHANNELS[dp.ChannelName.THROTTLE].minimum - 1 + failsafe
    run, text, spec = generate(tmp_path, ("failsafe_throttle_us: 950", f"failsafe_throttle_us: {value}"))
    assert run.code == 2
    where = h.location(text, f"failsafe_throttle_us: {value}")
    line, column = where.split(":")
    assert run.stderr.splitlines()[1].startswith(
        f"{spec}:{line}:{int(column) + len('failsafe_throttle_us: ')}: safety.failsafe_throttle_us: no "
        f"flight-controller FS_THR_VALUE fits strictly between failsafe_throttle_us {value} and the throttle "
        f"minimum {dp.CHANNELS['throttle'].minimum}")
    assert not (tmp_path / "out").exists()


def test_a_failsafe_below_ardupilots_range_is_rejected(tmp_path: Path) -> None:
    run, _, _ = generate(tmp_path, ("failsafe_throttle_us: 950", "failsafe_throttle_us: 800"),
                         ("recorded: [1029, 2012]", "recorded: [905, 2012]"))
    assert run.code == 2 and "safety.failsafe_throttle_us: no flight-controller FS_THR_VALUE" in run.stderr


@pytest.mark.parametrize(("edits", "anchor", "message"), [
    ((("    pitch: 3\n", "    pitch: 2\n"),), "2\n    throttle: 4", "wiring.rc_inputs.pitch: pin 2 is already used by "
                                                                   "rc_inputs.roll"),
    ((("    tilt: 10\n", "    tilt: 1\n"),), "1\n  laser", "wiring.servos.tilt: pin 1 is not in 2..19 (hint: 0 and 1"),
    ((("    mode: 6\n", "    mode: 6\n    aux: 7\n"),), "aux: 7", "wiring.rc_inputs.aux: unknown output 'aux'"),
    ((("    yaw: 5\n", ""),), "roll: 2", "wiring.rc_inputs.yaw: output 'yaw' has no pin"),
    ((("  ppm: 2\n", "  ppm: 9\n"),), "9\n\n", "wiring.ppm: pin 9 is already used by servos.pan"),
    ((("alt_hold_us: 1425", "alt_hold_us: 1200"),), "1200", "flight_modes.alt_hold_us: stabilize_us 1165 and "
                                                             "alt_hold_us 1200 select the same flight-mode slot (1)"),
    ((("  url: https://", "  url: ftp://"),), "ftp://", "project.url: url 'ftp://"),
])
def test_wiring_and_mode_mistakes_are_reported_where_they_are(tmp_path: Path, edits: tuple[tuple[str, str], ...],
                                                              anchor: str, message: str) -> None:
    run, text, spec = generate(tmp_path, *edits)
    assert run.code == 2
    lines = run.stderr.splitlines()
    assert lines[0] == f"{spec}: 1 error; nothing was written", run.stderr
    assert lines[1].startswith(f"{spec}:{h.location(text, anchor)}: {message}"), lines[1]


def test_without_a_flight_controller_section_the_parameters_keep_arducopters_defaults(tmp_path: Path) -> None:
    text = h.spec_text()
    start = text.index("# How ArduCopter must read the sticks")
    end = text.index("throttle_dead_band: 10\n") + len("throttle_dead_band: 10\n")
    spec = tmp_path / "drone.yaml"
    spec.write_text(text[:start] + text[end:], encoding="utf-8")
    run = h.generate("--spec", spec, "--out", tmp_path / "out")
    assert run.code == 0, run.stderr
    params = strict_parse((tmp_path / "out" / "ardupilot" / "arducopter-4" / "drone.parm").read_text(encoding="utf-8"))
    assert params["THR_DZ"][0] == 100 and not any(name.endswith("_REVERSED") for name in params)


@pytest.mark.parametrize("edit,message", [
    (("reversed: [pitch]", "reversed: [pitch, wings]"), "flight_controller.reversed: 'wings' is not a channel"),
    (("reversed: [pitch]", "reversed: [pitch, pitch]"), "flight_controller.reversed: 'pitch' listed twice"),
    (("reversed: [pitch]", "reversed: pitch"), "flight_controller.reversed: expected a list of channel names"),
    (("reversed: [pitch]", "reversed: [[pitch], {yaw: 1}]"),  # found by mutating the spec: it raised a TypeError
     "flight_controller.reversed: expected a channel name, found a list"),
    (("throttle_dead_band: 10", "throttle_dead_band: 301"),
     "flight_controller.throttle_dead_band: throttle_dead_band 301 is not in 0..300"),
    (("throttle_dead_band: 10", "throttle_dead_bnd: 10"), "flight_controller.throttle_dead_bnd: unknown key"),
])
def test_a_bad_flight_controller_section_is_rejected_where_it_is(tmp_path: Path, edit: tuple[str, str],
                                                                 message: str) -> None:
    run, text, spec = generate(tmp_path, edit)
    assert run.code == 2, run.stdout
    line = h.location(text, edit[1]).split(":")[0]
    assert f"{spec}:{line}:" in run.stderr and message in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and not (tmp_path / "out").exists()


FIRMWARE_LINE = "  throttle_dead_band: 10\n"
SUPPORTED = "supported: 3.2 (ArduCopter 3.2.1), 4 (ArduCopter 4.0 to 4.6)"


@pytest.mark.parametrize(("listed", "message"), [
    ('["3.5"]', "flight_controller.firmware: '3.5' is not a supported ArduCopter line"),
    ("[4, 4]", "flight_controller.firmware: 4 is listed twice"),
    ("3.2", "flight_controller.firmware: expected a list of ArduCopter lines, found 3.2"),
])
def test_an_unsupported_firmware_line_is_refused_with_the_supported_ones(tmp_path: Path, listed: str,
                                                                         message: str) -> None:
    run, text, spec = generate(tmp_path, (FIRMWARE_LINE, f"{FIRMWARE_LINE}  firmware: {listed}\n"))
    assert run.code == 2, run.stdout
    line = h.location(text, f"firmware: {listed}").split(":")[0]
    assert f"{spec}:{line}:" in run.stderr and message in run.stderr and SUPPORTED in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and not (tmp_path / "out").exists()


def test_only_the_listed_lines_are_written(tmp_path: Path) -> None:
    run, _, _ = generate(tmp_path, (FIRMWARE_LINE, f'{FIRMWARE_LINE}  firmware: ["3.2"]\n'))
    assert run.code == 0, run.stderr
    assert sorted(p.name for p in (tmp_path / "out" / "ardupilot").iterdir()) == ["arducopter-3.2"]


def test_a_line_that_cannot_fly_the_spec_is_refused_where_it_is_listed(tmp_path: Path) -> None:
    """ArduCopter 3.2.1 has no FLTMODE_CH: it reads the mode switch on input 5 only. Wired to input 6, its
    file would silently fly in whatever mode input 5 selects."""
    run, text, spec = generate(tmp_path, (FIRMWARE_LINE, f'{FIRMWARE_LINE}  firmware: ["4", "3.2"]\n'),
                               ("    yaw: 5\n    mode: 6\n", "    mode: 5\n    yaw: 6\n"))
    assert run.code == 2, run.stdout
    where = h.location(text, '"3.2"]')
    assert run.stderr.splitlines()[1] == (
        f"{spec}:{where}: flight_controller.firmware: ArduCopter 3.2: ArduCopter 3.2.1 reads "
        "the flight mode on RC input 5 only (it has no FLTMODE_CH), but wiring.rc_inputs.mode is input 4 (hint: "
        f"remove the line from flight_controller.firmware, or change the spec; {SUPPORTED})")
    run, _, _ = generate(tmp_path, (FIRMWARE_LINE, f'{FIRMWARE_LINE}  firmware: ["4"]\n'),
                         ("    yaw: 5\n    mode: 6\n", "    mode: 5\n    yaw: 6\n"))
    assert run.code == 0, run.stderr


def test_a_failsafe_gap_outside_the_apm_lines_range_refuses_that_line(tmp_path: Path) -> None:
    """FS_THR_VALUE is 925..1100 in 3.2.1 and 910..1100 in 4.x: a gap at 911..919 fits 4.x only."""
    run, _, _ = generate(tmp_path, ("failsafe_throttle_us: 950", "failsafe_throttle_us: 905"),
                         ("recorded: [1029, 2012]", "recorded: [920, 2012]"))
    assert run.code == 2 and "ArduCopter 3.2: ArduCopter 3.2.1 takes FS_THR_VALUE in 925..1100" in run.stderr
    run, _, _ = generate(tmp_path, ("failsafe_throttle_us: 950", "failsafe_throttle_us: 905"),
                         ("recorded: [1029, 2012]", "recorded: [920, 2012]"),
                         (FIRMWARE_LINE, f"{FIRMWARE_LINE}  firmware: [4]\n"))
    assert run.code == 0, run.stderr
    params = strict_parse((tmp_path / "out" / "ardupilot" / "arducopter-4" / "drone.parm").read_text("utf-8"))
    assert 910 <= params["FS_THR_VALUE"][0] < 920
