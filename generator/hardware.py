"""The spec's hardware sections (`project`, `wiring`) and the checks that tie them to the flight controller.

Called from one line of build.py; kept apart so that the ArduPilot-facing rules stay in one small place."""

from __future__ import annotations

from . import ardupilot as ap
from .ardupilot import FS_THR_RANGE_US, STICKS, THR_DZ_DEFAULT, THR_DZ_RANGE, fs_thr_value, mode_slot
from .errors import SpecError
from .model import Channel, FlightControllerSetup, Project, WiredPin, Wiring
from .reader import Reader, is_int, kind_name
from .source import Node

PIN_RANGE = (2, 19)  # digital pins of an Uno (A0-A5 are 14-19); 0 and 1 are the USB serial port
MODE_OUTPUT = "mode"  # the RC output that carries the flight-mode pulses (spec section flight_modes)


def read(top: Reader, channels: dict[str, Channel], servo_names: list[str], failsafe_throttle_us: int,
         mode_pulses_us: tuple[int, int]) -> tuple[Project, Wiring]:
    """Read `project` and `wiring`, and check the flight controller can be set up for this spec."""
    project = _project(top.section("project"))
    wiring = _wiring(top.section("wiring"), list(channels), servo_names)
    _check_failsafe_gap(top, channels, failsafe_throttle_us)
    _check_mode_slots(top, mode_pulses_us)
    return project, wiring


def flight_controller(top: Reader, channels: dict[str, Channel], wiring: Wiring, failsafe_us: int,
                      step_us: int) -> FlightControllerSetup:
    """The optional `flight_controller` section: ArduCopter's defaults and every supported line when absent."""
    node = top.child("flight_controller", required=False)
    if node is None:
        step_node = top.node.children["speeds"].children.get("step_us") if top.ok and "speeds" in top.node.children \
            else None
        if step_node is not None:
            _check_dead_band(top, step_node, "speeds.step_us", THR_DZ_DEFAULT, channels, step_us)
        return FlightControllerSetup((), THR_DZ_DEFAULT, _lines(top, None, None, channels, wiring, failsafe_us))
    r = Reader(node, "flight_controller", top.errors)
    names: list[str] = []
    listed = r.child("reversed", required=False)
    if listed is not None:
        if not isinstance(listed.value, list):
            r.error(listed, f"expected a list of channel names, found {listed.value!r}", path=r.sub("reversed"))
        for item in listed.items:
            if not isinstance(item.value, str):
                r.error(item, f"expected a channel name, found {kind_name(item.value)}",
                        "known: " + ", ".join(channels), path=r.sub("reversed"))
            elif item.value not in channels or item.value in names:
                what = "listed twice" if item.value in names else "is not a channel"
                r.error(item, f"'{item.value}' {what}", "known: " + ", ".join(channels), path=r.sub("reversed"))
            else:
                names.append(str(item.value))
    dead_band = r.integer("throttle_dead_band", THR_DZ_DEFAULT)
    dz_node = r.node.children.get("throttle_dead_band") if r.ok else None
    if is_int(dz_node) and not THR_DZ_RANGE[0] <= dead_band <= THR_DZ_RANGE[1]:
        assert dz_node is not None
        r.error(dz_node, f"throttle_dead_band {dead_band} is not in {THR_DZ_RANGE[0]}..{THR_DZ_RANGE[1]}",
                "ArduCopter's THR_DZ range", path=r.sub("throttle_dead_band"))
    elif is_int(dz_node):
        assert dz_node is not None
        _check_dead_band(r, dz_node, r.sub("throttle_dead_band"), dead_band, channels, step_us)
    firmware = _lines(top, r, r.child("firmware", required=False), channels, wiring, failsafe_us)
    r.finish()
    return FlightControllerSetup(tuple(names), dead_band, firmware)


def _lines(top: Reader, r: Reader | None, listed: Node | None, channels: dict[str, Channel], wiring: Wiring,
           failsafe_us: int) -> tuple[str, ...]:
    """`flight_controller.firmware`: the ArduCopter lines to write parameter files for, each able to fly the spec
    (every supported line when the key is absent)."""
    path = "flight_controller.firmware"
    items: list[tuple[str, Node | None]] = [(key, None) for key in ap.LINE_KEYS]
    if listed is not None and r is not None:
        if not isinstance(listed.value, list) or not listed.items:
            r.error(listed, f"expected a list of ArduCopter lines, found {listed.value!r}",
                    "supported: " + ap.supported(), path=path)
            return ()
        items = []
        for item in listed.items:
            key = str(item.value) if isinstance(item.value, (str, int, float)) and item.value is not True else ""
            if key not in ap.LINE_KEYS or any(key == seen for seen, _ in items):
                what = "is listed twice" if key in ap.LINE_KEYS else "is not a supported ArduCopter line"
                r.error(item, f"{item.value!r} {what}", "supported: " + ap.supported(), path=path)
            else:
                items.append((key, item))
    throttle = channels.get("throttle")
    if throttle is None or failsafe_us <= 0 or any(e.path.startswith("wiring.") for e in top.errors):
        return tuple(key for key, _ in items)  # reported where they are wrong
    for key, at in items:
        for problem in ap.problems(ap.line(key), wiring.rc_input("mode"), failsafe_us, throttle.recorded_min):
            where = at if at is not None else top.node.children.get("flight_controller", top.node)
            top.error(where, f"ArduCopter {key}: {problem}", "remove the line from flight_controller.firmware, or "
                      "change the spec; supported: " + ap.supported(), path)
    return tuple(key for key, _ in items)


def _check_dead_band(r: Reader, node: Node, path: str, dead_band: int, channels: dict[str, Channel],
                     step_us: int) -> None:
    """AltHold's throttle dead band (THR_DZ, 0-1000 of the throttle's range) must be narrower than the speed step:
    a climb or descent at the step would not move the drone, nor would the landing routine's descent."""
    throttle = channels.get("throttle")
    if throttle is None or step_us <= 0:
        return
    span = throttle.recorded_max - throttle.recorded_min
    dead_us = dead_band * span / 1000.0
    if dead_us >= step_us:
        widest = max(0, -(-step_us * 1000 // span) - 1)  # the widest band still narrower than the step
        default = path == "speeds.step_us"
        what = f"ArduCopter's default throttle dead band {dead_band}" if default else f"throttle_dead_band {dead_band}"
        r.error(node, f"{what} is {dead_us:.0f} µs of the throttle's {span} µs, as wide as the speed step "
                f"({step_us} µs) or wider: a move up or down at the step, and the landing routine's descent, would "
                "not move the drone",
                f"set flight_controller.throttle_dead_band to at most {widest} (ArduCopter's THR_DZ), or raise "
                "speeds.step_us", path=path)


def _project(r: Reader) -> Project:
    project = Project(r.text("author"), r.text("maintainer"), r.text("url"))
    if project.url and not project.url.startswith(("https://", "http://")):
        r.error(r.node.children["url"], f"url '{project.url}' is not an http(s) address", path=r.sub("url"))
    r.finish()
    return project


def _wiring(r: Reader, channel_names: list[str], servo_names: list[str]) -> Wiring:
    used: dict[int, str] = {}
    rc = [WiredPin(name, pin, i + 1) for i, (name, pin) in
          enumerate(_pins(r, "rc_inputs", [*channel_names, MODE_OUTPUT], used))]
    servos = [WiredPin(name, pin, 0) for name, pin in _pins(r, "servos", servo_names, used)]
    laser = WiredPin("laser", _pin(r, "laser", used), 0)
    # The PPM-sum line may replace an RC output (they are never driven together), nothing else.
    ppm = WiredPin("ppm", _pin(r, "ppm", {p: n for p, n in used.items() if not n.startswith("rc_inputs.")}), 0)
    r.finish()
    return Wiring(tuple(rc), tuple(servos), laser, ppm)


def _pins(r: Reader, key: str, known: list[str], used: dict[int, str]) -> list[tuple[str, int]]:
    """The entries of one pin mapping, in order; every known name wired exactly once."""
    out: list[tuple[str, int]] = []
    for name, node in r.entries(key):
        if name not in known:
            r.errors.append(SpecError(node.key_location, f"{r.sub(key)}.{name}", f"unknown output '{name}'",
                                      "known: " + ", ".join(known)))
            continue
        out.append((name, _pin_value(r, node, f"{r.sub(key)}.{name}", used)))
    mapping = r.node.children.get(key) if r.ok else None
    if mapping is not None and isinstance(mapping.value, dict):
        for name in known:
            if name not in mapping.children:
                r.errors.append(SpecError(mapping.location, f"{r.sub(key)}.{name}", f"output '{name}' has no pin",
                                          "the firmware drives every channel, the mode output and every servo"))
    return out


def _pin(r: Reader, key: str, used: dict[int, str]) -> int:
    node = r.child(key)
    return 0 if node is None else _pin_value(r, node, r.sub(key), used)


def _pin_value(r: Reader, node: Node, path: str, used: dict[int, str]) -> int:
    if not is_int(node):
        r.errors.append(SpecError(node.location, path, f"expected a pin number, found {node.value!r}"))
        return 0
    pin = int(node.value)  # type: ignore[arg-type]  # is_int checked it
    if not PIN_RANGE[0] <= pin <= PIN_RANGE[1]:
        r.errors.append(SpecError(node.location, path, f"pin {pin} is not in {PIN_RANGE[0]}..{PIN_RANGE[1]}",
                                  "0 and 1 are the USB serial port; the Uno has digital pins up to 19 (A5)"))
    elif pin in used:
        r.errors.append(SpecError(node.location, path, f"pin {pin} is already used by {used[pin]}"))
    else:
        used[pin] = path.removeprefix("wiring.")
    return pin


def _check_failsafe_gap(top: Reader, channels: dict[str, Channel], failsafe_us: int) -> None:
    # A well-formed spec has every stick channel (build.py reports a missing or broken one itself).
    missing = [name for name in STICKS if name not in channels]
    safety = top.node.children.get("safety")
    node = safety.children.get("failsafe_throttle_us") if safety is not None else None
    if missing or node is None or not is_int(node) or failsafe_us <= 0:
        if missing and "channels" in top.node.children:
            top.error(top.node.children["channels"], "no channel named " + ", ".join(missing),
                      "the flight controller's sticks are roll, pitch, throttle and yaw", "channels")
        return
    throttle_min = channels["throttle"].recorded_min
    if fs_thr_value(failsafe_us, throttle_min) is None:
        top.error(node, f"no flight-controller FS_THR_VALUE fits strictly between failsafe_throttle_us "
                  f"{failsafe_us} and the throttle minimum {throttle_min} (channels.throttle.recorded) inside "
                  f"ArduPilot's {FS_THR_RANGE_US[0]}..{FS_THR_RANGE_US[1]}",
                  "the failsafe throttle must sit at least 2 us below the throttle minimum and above "
                  f"{FS_THR_RANGE_US[0] - 1}", "safety.failsafe_throttle_us")


def _check_mode_slots(top: Reader, pulses_us: tuple[int, int]) -> None:
    modes = top.node.children.get("flight_modes")
    node = modes.children.get("alt_hold_us") if modes is not None else None
    if node is not None and all(p > 0 for p in pulses_us) and mode_slot(pulses_us[0]) == mode_slot(pulses_us[1]):
        top.error(node, f"stabilize_us {pulses_us[0]} and alt_hold_us {pulses_us[1]} select the same "
                  f"flight-mode slot ({mode_slot(pulses_us[0])}) on the flight controller",
                  "ArduCopter's slots end at 1230, 1360, 1490, 1620 and 1749 us", "flight_modes.alt_hold_us")
