"""The simulated flight controller's parameters and how it reads the RC pulses, as ArduCopter does.

Parameters come from ``arducopter.yaml`` (ArduCopter's names and defaults, plus the airframe), overridden by
the generated parameter file the user loads into the real flight controller
(``generated/ardupilot/arducopter-4/drone.parm``):
so the simulator flies with the same RC ranges, reversals, dead band, failsafe and mode slots.

Stick reading follows ArduPilot's RC_Channel: roll, pitch and yaw are angles in -4500..4500 around the trim
with a dead zone; the throttle is 0..1000 above its minimum plus a dead zone; a reversed channel is mirrored.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import drone_protocol as dp
import yaml

from ..common.errors import ConfigError
from ..common.ranges import within
from .randomise import Effects

HERE = Path(__file__).resolve().parent
PARAMS_YAML = HERE / "arducopter.yaml"
# in the repository, the generated file; installed from a wheel, the copy setup.py put beside this module
REPO_PARM = next((p for p in (HERE / "drone.parm", HERE.parents[1] / "generated" / "ardupilot" / "arducopter-4" /
                  "drone.parm") if p.is_file()), HERE / "drone.parm")
STICKS = (dp.ChannelName.ROLL, dp.ChannelName.PITCH, dp.ChannelName.THROTTLE, dp.ChannelName.YAW)
MODE_SLOT_BOUNDS_US = (1230, 1360, 1490, 1620, 1749)  # ArduPilot's read_6pos_switch
ANGLE_RANGE = 4500.0
THROTTLE_RANGE = 1000.0
# physical ranges, checked at load: the airframe's figures, and ArduCopter's documented ranges of its parameters
AIRFRAME_RANGES: dict[str, tuple[float, float]] = {
    "mass_kg": (0.05, 50.0), "arm_m": (0.02, 2.0), "motor_max_n": (0.1, 500.0), "motor_tau_s": (0.001, 1.0),
    "yaw_moment_m": (0.0, 0.5), "drag_linear": (0.0, 50.0), "drag_quadratic": (0.0, 50.0),
    "rate_gain": (0.1, 200.0), "crash_speed": (0.1, 20.0), "radius_m": (0.02, 2.0),
}
PARAM_RANGES: dict[str, tuple[float, float]] = {
    "ANGLE_MAX": (1000.0, 8000.0), "ATC_INPUT_TC": (0.0, 1.0), "PILOT_Y_RATE": (1.0, 500.0),
    "THR_DZ": (0.0, 300.0), "PILOT_SPEED_UP": (10.0, 1000.0), "PILOT_SPEED_DN": (0.0, 1000.0),
    "PILOT_ACCEL_Z": (50.0, 500.0), "MOT_THST_HOVER": (0.125, 0.6875), "MOT_SPIN_MIN": (0.0, 0.3),
    "LAND_SPEED": (30.0, 200.0), "RC_DZ": (0.0, 200.0), "RC3_DZ": (0.0, 200.0), "ARM_DELAY_S": (0.0, 10.0),
}


@dataclass(frozen=True)
class Airframe:
    mass_kg: float
    arm_m: float
    inertia: tuple[float, float, float]
    motor_max_n: float
    motor_tau_s: float
    yaw_moment_m: float
    drag_linear: float
    drag_quadratic: float
    rate_gain: float
    crash_speed: float
    radius_m: float


@dataclass(frozen=True)
class Channel:
    """One RC input as ArduCopter reads it."""

    minimum: float
    maximum: float
    trim: float
    reversed: bool
    dead_zone: float

    def angle(self, pwm: float) -> float:
        """-4500..4500 around the trim, 0 inside the dead zone (RC_Channel::pwm_to_angle_dz)."""
        if self.reversed:
            pwm = self.trim - (pwm - self.trim)
        hi, lo = self.trim + self.dead_zone, self.trim - self.dead_zone
        if pwm > hi and self.maximum > hi:
            value = ANGLE_RANGE * (pwm - hi) / (self.maximum - hi)
        elif pwm < lo and lo > self.minimum:
            value = ANGLE_RANGE * (pwm - lo) / (lo - self.minimum)
        else:
            value = 0.0
        return max(-ANGLE_RANGE, min(ANGLE_RANGE, value))

    def range(self, pwm: float) -> float:
        """0..1000 above the minimum plus the dead zone (RC_Channel::pwm_to_range_dz)."""
        pwm = max(self.minimum, min(self.maximum, pwm))
        if self.reversed:
            pwm = self.maximum - (pwm - self.minimum)
        low = self.minimum + self.dead_zone
        if pwm <= low:
            return 0.0
        return THROTTLE_RANGE * (pwm - low) / (self.maximum - low)


@dataclass(frozen=True)
class SimParams:
    values: Mapping[str, float]  # ArduCopter's parameters by name
    airframe: Airframe
    sticks: Mapping[dp.ChannelName, Channel]  # roll, pitch, throttle, yaw
    source: str  # where the RC setup came from

    def __getitem__(self, name: str) -> float:
        return self.values[name]

    def varied(self, e: Effects) -> SimParams:
        """The same flight controller on an airframe whose mass, thrust, drag and motor lag the world varies."""
        a = self.airframe
        frame = dataclasses.replace(
            a, mass_kg=a.mass_kg * e.mass_scale, motor_max_n=a.motor_max_n * e.thrust_scale,
            drag_linear=a.drag_linear * e.drag_scale, drag_quadratic=a.drag_quadratic * e.drag_scale,
            motor_tau_s=a.motor_tau_s * e.motor_tau_scale)
        return dataclasses.replace(self, airframe=frame)

    def mode_number(self, pwm: float) -> int:
        """The ArduCopter mode number the flight-mode pulse selects (FLTMODE1..6; 0, Stabilize, by default)."""
        slot = 1 + sum(1 for bound in MODE_SLOT_BOUNDS_US if pwm > bound)
        return int(self.values.get(f"FLTMODE{slot}", 0))


def read_parm(path: Path) -> dict[str, float]:
    """A Mission Planner parameter file: NAME,VALUE lines, # comments."""
    out: dict[str, float] = {}
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        name, sep, value = line.partition(",")
        try:
            out[name.strip()] = float(value)
        except ValueError as exc:
            raise ConfigError(f"{path}:{n}: not a NAME,VALUE line: {line!r}") from exc
        if not sep:
            raise ConfigError(f"{path}:{n}: not a NAME,VALUE line: {line!r}")
    return out


def _from_spec() -> dict[str, float]:
    """Without a parameter file: the RC ranges from the codec's tables (the spec's recorded extremes)."""
    out: dict[str, float] = {}
    for n, name in enumerate(STICKS, 1):
        ch = dp.CHANNELS[name]
        out |= {f"RCMAP_{name.value.upper()}": n, f"RC{n}_MIN": ch.minimum, f"RC{n}_MAX": ch.maximum,
                f"RC{n}_TRIM": ch.median}
    return out


def load(parm: Path | None = REPO_PARM, overrides: Mapping[str, float] | None = None) -> SimParams:
    """The parameters of ``parm`` over ArduCopter's defaults; ``parm=None``: the codec's channel table only. A
    parameter file that is missing is an error, never a quiet fallback to another flight controller."""
    data: dict[str, Any] = yaml.safe_load(PARAMS_YAML.read_text(encoding="utf-8"))
    values: dict[str, float] = {k: float(v) for k, v in data["arducopter"].items()}
    if parm is not None:
        if not parm.is_file():
            raise ConfigError(f"simulator parameters: the flight controller's parameter file {parm} is missing "
                              "(in a checkout, `python -m generator` writes it; a wheel carries it)")
        values |= read_parm(parm)
        source = str(parm)
    else:
        values |= _from_spec()
        source = "the codec's channel table (no parameter file)"
    values |= dict(overrides or {})
    frame: dict[str, Any] = {k: (tuple(float(x) for x in v) if isinstance(v, list) else float(v))
                             for k, v in data["airframe"].items()}
    airframe = Airframe(**frame)
    _check(values, airframe, source)
    sticks: dict[dp.ChannelName, Channel] = {}
    for name in STICKS:
        n = int(values.get(f"RCMAP_{name.value.upper()}", STICKS.index(name) + 1))
        try:
            lo, hi = values[f"RC{n}_MIN"], values[f"RC{n}_MAX"]
        except KeyError as exc:
            raise ConfigError(f"simulator parameters: no {exc.args[0]} for the {name.value} input") from exc
        trim = values.get(f"RC{n}_TRIM", (lo + hi) / 2.0)
        dz = values["RC3_DZ"] if name is dp.ChannelName.THROTTLE else values["RC_DZ"]
        sticks[name] = Channel(lo, hi, trim, bool(values.get(f"RC{n}_REVERSED", 0)), dz)
    return SimParams(values, airframe, sticks, source)


def _check(values: Mapping[str, float], frame: Airframe, source: str) -> None:
    """A figure outside its physical range (a negative mass, a dead band over the stick's travel) is refused."""
    checks = [(f"airframe.{k}", getattr(frame, k), lo, hi, str(PARAMS_YAML)) for k, (lo, hi) in AIRFRAME_RANGES.items()]
    checks += [(k, values[k], lo, hi, f"{PARAMS_YAML} or {source}") for k, (lo, hi) in PARAM_RANGES.items()
               if k in values]
    checks += [(f"airframe.inertia[{i}]", v, 1e-5, 100.0, str(PARAMS_YAML)) for i, v in enumerate(frame.inertia)]
    for name, value, lo, hi, where in checks:
        if not within(value, lo, hi):
            raise ConfigError(f"simulator parameter {name} = {value:g} ({where}): outside its physical range "
                              f"{lo:g}..{hi:g}")
