"""The randomised world: every imperfection of a real airframe, flight controller and camera that the simulator
models, drawn once per seed into one frozen ``Effects`` (``draw``), or all off (``IDEAL``, the ``--ideal`` flag).

Each field has a physical range (``RANGES``) checked when an ``Effects`` is made: a value outside it (a negative
mass scale, a negative latency) is refused with one line naming it. ``DRAWN`` holds the narrower ranges a seed
draws from; ``pilot/sim/README.md`` names the source of each figure.
"""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..common.errors import ConfigError
from ..common.ranges import within

# field -> (lowest, highest) physically meaningful value, and the unit in messages
RANGES: dict[str, tuple[float, float, str]] = {
    "mass_scale": (0.1, 10.0, "x the airframe's mass"),
    "thrust_scale": (0.1, 10.0, "x the motors' thrust"),
    "drag_scale": (0.0, 10.0, "x the airframe's drag"),
    "motor_tau_scale": (0.1, 10.0, "x the motors' time constant"),
    "drift_mps": (0.0, 5.0, "m/s"),
    "drift_heading": (-math.pi, math.pi, "rad"),
    "baro_noise_m": (0.0, 2.0, "m"),
    "baro_drift_m": (0.0, 5.0, "m"),
    "ground_effect_m": (0.0, 2.0, "m"),
    "attitude_noise_deg": (0.0, 5.0, "deg"),
    "frame_latency_s": (0.0, 1.0, "s"),
    "frame_drop": (0.0, 0.5, "of the frames"),
    "servo_s_per_60deg": (0.0, 2.0, "s per 60 deg"),
    "ae_tau_s": (0.0, 5.0, "s"),
    "awb_tau_s": (0.0, 10.0, "s"),
    "readout_s": (0.0, 0.1, "s"),
    "shadows": (0.0, 1.0, "(0 off, 1 on)"),
    "picam": (0.0, 1.0, "(0: a USB webcam, 1: the Pi camera)"),
}
# what a seed draws (uniformly) for each field
DRAWN: dict[str, tuple[float, float]] = {
    "mass_scale": (0.8, 1.2),
    "thrust_scale": (0.8, 1.2),
    "drag_scale": (0.8, 1.2),
    "motor_tau_scale": (0.8, 1.2),
    "drift_mps": (0.0, 0.5),
    "drift_heading": (-math.pi, math.pi),
    "baro_noise_m": (0.03, 0.08),
    "baro_drift_m": (0.1, 0.5),
    "ground_effect_m": (0.1, 0.4),
    "attitude_noise_deg": (0.1, 0.3),
    "frame_latency_s": (0.03, 0.12),
    "frame_drop": (0.0, 0.05),
    "servo_s_per_60deg": (0.1, 0.2),
    "ae_tau_s": (0.2, 0.6),
    "awb_tau_s": (0.5, 1.5),
    "readout_s": (0.015, 0.03),
    "shadows": (1.0, 1.0),
    "picam": (0.0, 1.0),  # rounded: half the seeds fly the Pi camera
}


@dataclass(frozen=True)
class Effects:
    """One world's imperfections (zero or 1.0 scale: off). Airframe: scales of the nominal ``arducopter.yaml``
    figures and a level-trim error that drifts the airframe at ``drift_mps`` towards ``drift_heading`` (body
    frame, from the nose, counter-clockwise) with centred sticks. Estimation: AltHold's barometric height errs
    by noise (``baro_noise_m``, standard deviation, correlated over ``BARO_NOISE_TAU_S``), a slow drift reaching
    ``baro_drift_m`` over a minute and a ground effect (``ground_effect_m`` too low on the floor, fading over
    ``GROUND_EFFECT_HEIGHT_M``); attitude noise. Latency: exposure to pilot, dropped frames (each one makes the
    pilot's frame one camera period older), the servos' slew. Camera: auto-exposure and auto-white-balance
    time constants, shadows, and the profile: the Pi camera (``picam`` 1: uncompressed frames, a rolling shutter
    read over ``readout_s``) or a USB webcam (0: MJPEG at the scenario's quality, global shutter)."""

    mass_scale: float = 1.0
    thrust_scale: float = 1.0
    drag_scale: float = 1.0
    motor_tau_scale: float = 1.0
    drift_mps: float = 0.0
    drift_heading: float = 0.0
    baro_noise_m: float = 0.0
    baro_drift_m: float = 0.0
    ground_effect_m: float = 0.0
    attitude_noise_deg: float = 0.0
    frame_latency_s: float = 0.0
    frame_drop: float = 0.0
    servo_s_per_60deg: float = 0.0
    ae_tau_s: float = 0.0
    awb_tau_s: float = 0.0
    readout_s: float = 0.0
    shadows: float = 0.0
    picam: float = 0.0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            lo, hi, unit = RANGES[f.name]
            if not within(value, lo, hi):
                raise ConfigError(f"simulator parameter {f.name} = {value!r}: outside its physical range "
                                  f"{lo:g}..{hi:g} {unit}")

    @property
    def ideal(self) -> bool:
        return self == IDEAL


IDEAL = Effects()
BARO_NOISE_TAU_S = 0.5  # the estimator's smoothing of the barometer's noise
GROUND_EFFECT_HEIGHT_M = 0.5  # about one rotor diameter of a 450 mm frame (10 in props): the wash's reach
CAMERA_FPS = 30.0


def draw(name: str, seed: int, *, ideal: bool = False, overrides: Mapping[str, float] | None = None) -> Effects:
    """The effects of scenario ``name``'s world ``seed`` (the same pair, the same world), or none with ``ideal``;
    ``overrides`` set fields by name (checked like the rest)."""
    values: dict[str, float] = {}
    if not ideal:
        rng = np.random.default_rng([zlib.crc32(name.encode()), seed, 0xEFFEC7])
        values = {name: float(rng.uniform(lo, hi)) for name, (lo, hi) in DRAWN.items()}
        values["picam"] = float(round(values["picam"]))
        values["readout_s"] *= values["picam"]
    for name, value in (overrides or {}).items():
        if name not in RANGES:
            raise ConfigError(f"simulator parameter {name!r}: unknown; known: {', '.join(RANGES)}")
        values[name] = value
    return Effects(**values)
