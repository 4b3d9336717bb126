"""generated/ardupilot/drone.parm: read by pymavlink's parameter-file reader (what MAVProxy's `param load` uses)
and by a strict parser of the format, every value checked against the spec; and the spec checks behind it
(the failsafe gap, the wiring, the flight-mode slots) reject a spec with file:line:column."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path
from typing import Any

import drone_protocol as dp
import protocol_harness as h
import pytest
import yaml
from pymavlink import mavparm

PARM = h.GENERATED / "ardupilot" / "drone.parm"
# ArduCopter's flight-mode switch: the highest PWM of slots 1-5 (slot 6 above), from its parameter docs.
SLOT_TOPS = (1230, 1360, 1490, 1620, 1749)
FS_THR_VALUE_RANGE = (910, 1100)
_LINE = re.compile(r"(?P<name>[A-Z][A-Z0-9_]{0,15}),(?P<value>-?\d+(\.\d+)?)")


def strict_parse(text: str) -> dict[str, tuple[float, str]]:
    """NAME,VALUE lines, each right after a `# <spec field> ...` line; '#' comments; no blank lines."""
    params: dict[str, tuple[float, str]] = {}
    previous = ""
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("#"):
            previous = line
            continue
        match = _LINE.fullmatch(line)
        assert match, f"line {number} is not NAME,VALUE: {line!r}"
        assert match["name"] not in params, f"line {number}: {match['name']} set twice"
        assert previous.startswith("# "), f"line {number}: {match['name']} has no comment naming its spec field"
        params[match["name"]] = (float(match["value"]), previous[2:])
        previous = ""
    return params


def spec_field(spec: dict[str, Any], comment: str) -> object:
    """The spec value a comment's first word names, e.g. channels.roll.recorded[0] (KeyError if none)."""
    path = comment.split()[0].rstrip(":")
    node: Any = spec
    for part in re.findall(r"[^.\[\]]+|\[\d+\]", path):
        node = node[int(part[1:-1])] if part.startswith("[") else node[part]
    return node


def slot(pulse_us: int) -> int:
    return next((i + 1 for i, top in enumerate(SLOT_TOPS) if pulse_us <= top), len(SLOT_TOPS) + 1)


def expected(spec: dict[str, Any]) -> dict[str, float]:
    """What the parameters must be, from the spec and the generated Python module."""
    order = list(spec["wiring"]["rc_inputs"])
    want: dict[str, float] = {f"RCMAP_{n.upper()}": order.index(n) + 1 for n in ("roll", "pitch", "throttle", "yaw")}
    for name in spec["channels"]:
        n = order.index(name) + 1
        channel = dp.CHANNELS[name]
        want |= {f"RC{n}_MIN": channel.minimum, f"RC{n}_MAX": channel.maximum, f"RC{n}_TRIM": channel.median}
    for name in spec.get("flight_controller", {}).get("reversed", []):
        want[f"RC{order.index(name) + 1}_REVERSED"] = 1
    want["THR_DZ"] = spec.get("flight_controller", {}).get("throttle_dead_band", 100)  # ArduCopter's default
    modes = spec["flight_modes"]
    want |= {"FS_THR_ENABLE": 3, "FLTMODE_CH": order.index("mode") + 1,
             f"FLTMODE{slot(modes['stabilize_us'])}": 0, f"FLTMODE{slot(modes['alt_hold_us'])}": 2}
    return want


def test_the_parameter_file_matches_the_spec() -> None:
    spec = yaml.safe_load(h.spec_text())
    params = strict_parse(PARM.read_text(encoding="utf-8"))
    for _, comment in params.values():
        spec_field(spec, comment)  # every comment names a field of the spec (KeyError otherwise)
    fs_value = params.pop("FS_THR_VALUE")[0]
    assert {name: value for name, (value, _) in params.items()} == expected(spec)
    assert spec["safety"]["failsafe_throttle_us"] < fs_value < dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    assert FS_THR_VALUE_RANGE[0] <= fs_value <= FS_THR_VALUE_RANGE[1]


def test_pymavlink_reads_every_parameter() -> None:
    parm = mavparm.MAVParmDict()
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert parm.load(str(PARM))
    assert "Invalid line" not in printed.getvalue(), printed.getvalue()
    strict = strict_parse(PARM.read_text(encoding="utf-8"))
    assert dict(parm) == {name: value for name, (value, _) in strict.items()}


def generate(tmp_path: Path, *edits: tuple[str, str]) -> tuple[h.Run, str, Path]:
    text = h.edited_spec(*edits)
    spec = tmp_path / "drone.yaml"
    spec.write_text(text, encoding="utf-8")
    return h.generate("--spec", spec, "--out", tmp_path / "out"), text, spec


def test_the_smallest_failsafe_gap_gives_the_value_in_it(tmp_path: Path) -> None:
    minimum = dp.CHANNELS[dp.ChannelName.THROTTLE].minimum
    run, _, _ = generate(tmp_path, ("failsafe_throttle_us: 950", f"failsafe_throttle_us: {minimum - 2}"))
    assert run.code == 0, run.stderr
    params = strict_parse((tmp_path / "out" / "ardupilot" / "drone.parm").read_text(encoding="utf-8"))
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
    params = strict_parse((tmp_path / "out" / "ardupilot" / "drone.parm").read_text(encoding="utf-8"))
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
