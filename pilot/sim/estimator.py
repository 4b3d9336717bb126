"""What the emulated flight controller believes, not what is: its attitude and height estimates.

ArduCopter's AltHold holds the EKF's height, which indoors rests on the barometer: it wanders (correlated noise
and a slow drift) and, near the floor, reads too low in the rotors' wash (ground effect, which ArduCopter's
``GND_EFFECT_COMP`` and the EKF's ``EK3_GND_EFF_DZ`` exist for). A level-trim error (the accelerometers' level
off by a fraction of a degree, ``AHRS_TRIM_X/Y``) makes "level" a small lean, so centred sticks drift. The
figures are drawn per seed in ``randomise.py``; ``README.md`` names their sources.
"""

from __future__ import annotations

import math

import numpy as np

from .randomise import BARO_NOISE_TAU_S, GROUND_EFFECT_HEIGHT_M, Effects

GRAVITY = 9.81
DRIFT_WINDOW_S = 60.0  # the drift's random walk reaches baro_drift_m (one standard deviation) in this time
BLOCK = 4096  # normal draws made at once (one numpy call per draw costs more than the physics step's share)


class _Normals:
    """Standard normal numbers from a seeded generator, drawn in blocks."""

    def __init__(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._block: list[float] = []

    def next(self) -> float:
        if not self._block:
            self._block = self._rng.standard_normal(BLOCK).tolist()
        return self._block.pop()


def trim_error(e: Effects, mass_kg: float, drag_linear: float, drag_quadratic: float) -> tuple[float, float]:
    """The attitude offsets (roll, pitch; rad, ArduCopter's senses) whose "level" drifts the airframe at
    ``drift_mps`` towards ``drift_heading``: the lean whose thrust's horizontal part balances the drag there."""
    v = e.drift_mps
    lean = math.atan((drag_linear * v + drag_quadratic * v * v) / (mass_kg * GRAVITY))
    # the airframe leans towards its drift: nose down (pitch < 0) forward, roll left (roll < 0) to the left;
    # the controller levels the *sensed* attitude, so the sensor reads the opposite of that lean as level
    return lean * math.sin(e.drift_heading), lean * math.cos(e.drift_heading)


class Estimator:
    """The flight controller's estimates from the true state, per physics step."""

    def __init__(self, e: Effects, seed: int, mass_kg: float, drag_linear: float, drag_quadratic: float) -> None:
        self.e = e
        self._n = _Normals(np.random.default_rng([seed, 0xE57]))
        self.trim_roll, self.trim_pitch = trim_error(e, mass_kg, drag_linear, drag_quadratic)
        self._att_sigma = math.radians(e.attitude_noise_deg)
        self._noise = 0.0  # the height estimate's correlated noise, m
        self._drift = 0.0  # its random walk, m
        self.height_error = 0.0  # the last estimate minus the truth, m

    def attitude(self, roll: float, pitch: float) -> tuple[float, float]:
        if self._att_sigma == 0.0:
            return roll + self.trim_roll, pitch + self.trim_pitch
        n, sigma = self._n, self._att_sigma
        return roll + self.trim_roll + sigma * n.next(), pitch + self.trim_pitch + sigma * n.next()

    def height(self, true_height: float, motors_on: bool, dt: float) -> float:
        """The barometric height AltHold holds: correlated noise, drift, and ground effect with the motors on."""
        e = self.e
        if e.baro_noise_m > 0.0:  # Ornstein-Uhlenbeck: standard deviation baro_noise_m, memory BARO_NOISE_TAU_S
            a = dt / BARO_NOISE_TAU_S
            self._noise += -a * self._noise + e.baro_noise_m * math.sqrt(2.0 * a) * self._n.next()
        if e.baro_drift_m > 0.0:
            self._drift += e.baro_drift_m * math.sqrt(dt / DRIFT_WINDOW_S) * self._n.next()
        ground = 0.0
        if motors_on and true_height < GROUND_EFFECT_HEIGHT_M:
            ground = -e.ground_effect_m * (1.0 - true_height / GROUND_EFFECT_HEIGHT_M)
        self.height_error = self._noise + self._drift + ground
        return true_height + self.height_error
