"""ArduCopter's side of the link: the parameters that make the flight controller agree with the spec, per
firmware line.

The numbers here are ArduPilot's (mode-switch slots, mode numbers, parameter names, types and ranges), not the
protocol's: every protocol figure comes from the spec. Each line was read in that release's own source:
ArduCopter 3.2.1 (`ArduCopter/Parameters.pde`, `radio.pde`, `switches.pde`, `libraries/RC_Channel`,
`AP_RCMapper`) and 4.x (`ArduCopter/Parameters.cpp`, `libraries/RC_Channel`)."""

from __future__ import annotations

from .model import Spec
from .records import record

# ArduCopter's flight-mode slots: a pulse up to each bound selects slot 1, 2, ... (FLTMODE1..FLTMODE6). The same
# in 3.2.1 (readSwitch) and 4.x (read_6pos_switch).
MODE_SLOT_BOUNDS_US = (1230, 1360, 1490, 1620, 1749)
MODE_NUMBERS = {"stabilize": 0, "alt_hold": 2}  # ArduCopter's mode numbers: Stabilize 0, AltHold 2
FS_THR_LAND = 3  # FS_THR_ENABLE: 1 = RTL (climbs to RTL_ALT: never indoors), 3 = always Land (3.2.1 and 4.x)
FS_THR_RANGE_US = (910, 1100)  # the widest range ArduPilot documents for FS_THR_VALUE (a line may narrow it)
RC_RANGE_US = (800, 2200)  # the range ArduPilot documents for RCn_MIN and RCn_MAX: the pulses it reads as sticks
STICKS = ("roll", "pitch", "throttle", "yaw")  # the channels RCMAP_* places, in ArduCopter's default order
THR_DZ_DEFAULT = 100  # ArduCopter's THR_DZ when the spec says nothing
THR_DZ_RANGE = (0, 300)  # the range ArduPilot documents for THR_DZ
# MAVLink's MAV_PARAM_TYPE of ArduPilot's AP_Int8 and AP_Int16: QGroundControl skips a line whose type differs
INT8, INT16 = 2, 4


@record
class FirmwareLine:
    """One ArduCopter release line whose parameter names and behaviour the generator knows."""

    key: str  # what the spec lists in flight_controller.firmware, and the folder name's suffix
    versions: str  # the releases it covers, for people
    boards: str
    reverse_name: str  # RCn_<this>: the input-reversal parameter
    reversed_value: int  # its value for a reversed channel
    fixed_mode_input: int  # the RC input the flight-mode switch is read on; 0: FLTMODE_CH chooses
    rc_by_function: bool  # RC1_..RC4_ calibrate roll, pitch, throttle, yaw whichever input RCMAP_* names
    fs_thr_range_us: tuple[int, int]  # FS_THR_VALUE's documented range

    @property
    def folder(self) -> str:
        return f"arducopter-{self.key}"


LINES = (
    FirmwareLine("3.2", "ArduCopter 3.2.1", "APM 2.5 / 2.6 (3.2.1 is the last release for APM 2.x)",
                 "REV", -1, 5, True, (925, 1100)),
    FirmwareLine("4", "ArduCopter 4.0 to 4.6", "Pixhawk-class boards (ChibiOS)", "REVERSED", 1, 0, False, (910, 1100)),
)
LINE_KEYS = tuple(line.key for line in LINES)


def line(key: str) -> FirmwareLine:
    return next(candidate for candidate in LINES if candidate.key == key)


def supported() -> str:
    """The supported lines, for error messages and docs: `3.2 (ArduCopter 3.2.1), 4 (ArduCopter 4.0 to 4.6)`."""
    return ", ".join(f"{candidate.key} ({candidate.versions})" for candidate in LINES)


@record
class Param:
    name: str
    value: int
    source: str  # the spec field it comes from
    mav_type: int = INT8  # MAV_PARAM_TYPE, for QGroundControl's .params


@record
class LineParams:
    """The parameter file of one firmware line."""

    line: FirmwareLine
    params: tuple[Param, ...]


def mode_slot(pulse_us: int) -> int:
    """1-based flight-mode slot ArduCopter selects for this pulse width."""
    return 1 + sum(1 for bound in MODE_SLOT_BOUNDS_US if pulse_us > bound)


def fs_thr_value(failsafe_us: int, throttle_min_us: int,
                 fs_range_us: tuple[int, int] = FS_THR_RANGE_US) -> int | None:
    """A FS_THR_VALUE strictly between the failsafe throttle and the throttle minimum, inside the line's range:
    the middle of what is left, so that neither side sits on the trigger. None when nothing fits."""
    lo = max(failsafe_us + 1, fs_range_us[0])
    hi = min(throttle_min_us - 1, fs_range_us[1])
    return (lo + hi) // 2 if lo <= hi else None


def problems(fw: FirmwareLine, mode_input: int, failsafe_us: int, throttle_min_us: int) -> list[str]:
    """Why this line cannot do what the spec needs (empty when it can). A failsafe gap that no line could fill is
    the spec check's to report (hardware.py), not each line's."""
    out = []
    if fw.fixed_mode_input and mode_input != fw.fixed_mode_input:
        out.append(f"{fw.versions} reads the flight mode on RC input {fw.fixed_mode_input} only (it has no "
                   f"FLTMODE_CH), but wiring.rc_inputs.mode is input {mode_input}")
    if fs_thr_value(failsafe_us, throttle_min_us) is not None and \
            fs_thr_value(failsafe_us, throttle_min_us, fw.fs_thr_range_us) is None:
        out.append(f"{fw.versions} takes FS_THR_VALUE in {fw.fs_thr_range_us[0]}..{fw.fs_thr_range_us[1]}: none "
                   f"fits strictly between safety.failsafe_throttle_us {failsafe_us} and the throttle minimum "
                   f"{throttle_min_us}")
    return out


def parameters(spec: Spec, fw: FirmwareLine) -> tuple[Param, ...]:
    """Every parameter of the line's parameter files, in file order."""
    wiring = spec.wiring
    channels = {c.name: c for c in spec.channels}
    out = [Param(f"RCMAP_{name.upper()}", wiring.rc_input(name), f"wiring.rc_inputs.{name}: the RC input of {name}")
           for name in STICKS]
    for pin in wiring.rc_inputs:
        channel = channels.get(pin.name)
        if channel is None:
            continue  # the flight-mode output: its pulses are the slots below, not a stick range
        n = STICKS.index(channel.name) + 1 if fw.rc_by_function else pin.rc_input
        where = f"channels.{channel.name}.recorded"
        out += [Param(f"RC{n}_MIN", channel.recorded_min, f"{where}[0]", INT16),
                Param(f"RC{n}_MAX", channel.recorded_max, f"{where}[1]", INT16),
                Param(f"RC{n}_TRIM", channel.median, f"{where} (midpoint: the median of Table 4)", INT16)]
        if channel.name in spec.flight_controller.reversed:
            out.append(Param(f"RC{n}_{fw.reverse_name}", fw.reversed_value,
                             f"flight_controller.reversed: {channel.name}"))
    fs_value = fs_thr_value(spec.failsafe_throttle_us, channels["throttle"].recorded_min, fw.fs_thr_range_us)
    assert fs_value is not None, "the spec check (generator/hardware.py) rejects a line without the gap"
    out += [Param("FS_THR_ENABLE", FS_THR_LAND,
                  "safety.failsafe_throttle_us: the radio failsafe lands (3; RTL would climb indoors)"),
            Param("FS_THR_VALUE", fs_value,
                  "safety.failsafe_throttle_us < FS_THR_VALUE < channels.throttle.recorded[0]", INT16),
            Param("THR_DZ", spec.flight_controller.throttle_dead_band,
                  "flight_controller.throttle_dead_band: AltHold's dead band around mid-throttle", INT16)]
    if not fw.fixed_mode_input:
        out.append(Param("FLTMODE_CH", wiring.rc_input("mode"), "wiring.rc_inputs.mode"))
    for name, pulse in (("stabilize", spec.mode_stabilize_us), ("alt_hold", spec.mode_alt_hold_us)):
        slot, mode = mode_slot(pulse), MODE_NUMBERS[name]
        out.append(Param(f"FLTMODE{slot}", mode, f"flight_modes.{name}_us: {pulse} us is slot {slot}, {name} ({mode})"))
    return tuple(out)


def parameter_files(spec: Spec) -> tuple[LineParams, ...]:
    """The parameters of every line the spec lists, in the spec's order."""
    return tuple(LineParams(line(key), parameters(spec, line(key))) for key in spec.flight_controller.firmware)


def pilot_parameters(files: tuple[LineParams, ...]) -> tuple[Param, ...]:
    """The parameters the pilot's stick model reads: the newest listed line's (its names are today's)."""
    newest = [lp for lp in files if lp.line == LINES[-1]] or list(files[-1:])
    return newest[0].params if newest else ()
