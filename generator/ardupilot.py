"""ArduCopter's side of the link: the parameters that make the flight controller agree with the spec.

The numbers here are ArduPilot's (mode-switch slots, mode numbers, the failsafe range), not the protocol's:
every protocol figure comes from the spec. Reference: ArduCopter's parameter docs (RCMAP_*, RCn_*, FS_THR_*,
FLTMODE*) and RC_Channel::read_6pos_switch."""

from __future__ import annotations

from dataclasses import dataclass

from .model import Spec

# ArduCopter's flight-mode slots: a pulse up to each bound selects slot 1, 2, ... (FLTMODE1..FLTMODE6).
MODE_SLOT_BOUNDS_US = (1230, 1360, 1490, 1620, 1749)
MODE_NUMBERS = {"stabilize": 0, "alt_hold": 2}  # ArduCopter's mode numbers: Stabilize 0, AltHold 2
FS_THR_LAND = 3  # FS_THR_ENABLE: 1 = RTL (climbs to RTL_ALT: never indoors), 3 = always Land
FS_THR_RANGE_US = (910, 1100)  # the range ArduPilot documents for FS_THR_VALUE
RC_RANGE_US = (800, 2200)  # the range ArduPilot documents for RCn_MIN and RCn_MAX: the pulses it reads as sticks
STICKS = ("roll", "pitch", "throttle", "yaw")  # the channels RCMAP_* places
THR_DZ_DEFAULT = 100  # ArduCopter's THR_DZ when the spec says nothing
THR_DZ_RANGE = (0, 300)  # the range ArduPilot documents for THR_DZ


@dataclass(frozen=True)
class Param:
    name: str
    value: int
    source: str  # the spec field it comes from


def mode_slot(pulse_us: int) -> int:
    """1-based flight-mode slot ArduCopter selects for this pulse width."""
    return 1 + sum(1 for bound in MODE_SLOT_BOUNDS_US if pulse_us > bound)


def fs_thr_value(failsafe_us: int, throttle_min_us: int) -> int | None:
    """A FS_THR_VALUE strictly between the failsafe throttle and the throttle minimum, inside ArduPilot's
    range: the middle of what is left, so that neither side sits on the trigger. None when nothing fits."""
    lo = max(failsafe_us + 1, FS_THR_RANGE_US[0])
    hi = min(throttle_min_us - 1, FS_THR_RANGE_US[1])
    return (lo + hi) // 2 if lo <= hi else None


def parameters(spec: Spec) -> tuple[Param, ...]:
    """Every parameter of generated/ardupilot/drone.parm, in file order."""
    wiring = spec.wiring
    channels = {c.name: c for c in spec.channels}
    out = [Param(f"RCMAP_{name.upper()}", wiring.rc_input(name), f"wiring.rc_inputs.{name}: the RC input of {name}")
           for name in STICKS]
    for pin in wiring.rc_inputs:
        channel = channels.get(pin.name)
        if channel is None:
            continue  # the flight-mode output: its pulses are the slots below, not a stick range
        n, where = pin.rc_input, f"channels.{channel.name}.recorded"
        out += [Param(f"RC{n}_MIN", channel.recorded_min, f"{where}[0]"),
                Param(f"RC{n}_MAX", channel.recorded_max, f"{where}[1]"),
                Param(f"RC{n}_TRIM", channel.median, f"{where} (midpoint: the median of Table 4)")]
        if channel.name in spec.flight_controller.reversed:
            out.append(Param(f"RC{n}_REVERSED", 1, f"flight_controller.reversed: {channel.name}"))
    throttle = channels["throttle"]
    fs_value = fs_thr_value(spec.failsafe_throttle_us, throttle.recorded_min)
    assert fs_value is not None, "the spec check (generator/hardware.py) rejects a spec without the gap"
    out += [Param("FS_THR_ENABLE", FS_THR_LAND,
                  "safety.failsafe_throttle_us: the radio failsafe lands (3; RTL would climb indoors)"),
            Param("FS_THR_VALUE", fs_value,
                  "safety.failsafe_throttle_us < FS_THR_VALUE < channels.throttle.recorded[0]")]
    out.append(Param("THR_DZ", spec.flight_controller.throttle_dead_band,
                     "flight_controller.throttle_dead_band: AltHold's dead band around mid-throttle"))
    out.append(Param("FLTMODE_CH", wiring.rc_input("mode"), "wiring.rc_inputs.mode"))
    for name, pulse in (("stabilize", spec.mode_stabilize_us), ("alt_hold", spec.mode_alt_hold_us)):
        slot, mode = mode_slot(pulse), MODE_NUMBERS[name]
        out.append(Param(f"FLTMODE{slot}", mode, f"flight_modes.{name}_us: {pulse} us is slot {slot}, {name} ({mode})"))
    return tuple(out)
