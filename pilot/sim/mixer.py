"""The motor mixer with ArduCopter's priorities (AP_MotorsMatrix::output_armed_stabilizing), in newtons.

Roll and pitch come first; yaw gets the headroom they leave, but at least ``MOT_YAW_HEADROOM``; roll, pitch and
yaw are scaled down together only when even that does not fit; the collective goes last, moved as close to the
demand as the motors allow. A plain inverse of the mixing matrix clipped per motor has no priorities: a yaw
demand past the motors' yaw authority (a wall touch spins the airframe) then takes the roll and pitch authority
with it and the airframe flips.
"""

from __future__ import annotations

from .scene import MOTOR_SPIN, motor_positions

HEADROOM_SCALE = 1000.0  # MOT_YAW_HEADROOM is in PWM microseconds of the 1000 µs output range


class Mixer:
    def __init__(self, arm_m: float, yaw_moment_m: float, floor_n: float, top_n: float,
                 yaw_headroom: float) -> None:
        """``yaw_headroom`` is MOT_YAW_HEADROOM (0..1000)."""
        n = len(MOTOR_SPIN)
        # thrust of each motor per unit of torque: an X frame shares each torque equally over its four motors
        positions = motor_positions(arm_m)
        self._roll = [y / sum(py * py for _, py in positions) for _, y in positions]
        self._pitch = [-x / sum(px * px for px, _ in positions) for x, _ in positions]
        self._yaw = [s / (n * yaw_moment_m) for s in MOTOR_SPIN]
        self._n, self._floor, self._span = n, floor_n, top_n - floor_n
        self._yaw_min = yaw_headroom / HEADROOM_SCALE * self._span  # newtons per motor always left to yaw

    def thrusts(self, force: float, roll: float, pitch: float, yaw: float) -> list[float]:
        """Motor thrusts (N) for a collective force (N) and body torques (N m, FLU)."""
        span = self._span
        throttle = min(max(force / self._n - self._floor, 0.0), span)  # above the armed floor
        rp = [r * roll + p * pitch for r, p in zip(self._roll, self._pitch)]
        # the yaw that fits around roll and pitch with the throttle at its best point for attitude
        best = min(span / 2.0, throttle)
        room = float("inf")
        for share, y in zip(rp, self._yaw):
            up = span - (best + share) if y * yaw > 0.0 else best + share
            room = min(room, max(up, 0.0) / abs(y))
        room = max(room, self._yaw_min / abs(self._yaw[0]))
        yaw = min(max(yaw, -room), room)
        out = [share + yaw * y for share, y in zip(rp, self._yaw)]
        low, high = min(out), max(out)
        scale = 1.0
        if high - low > span:
            scale = span / (high - low)
        if throttle + low < 0.0:  # near the floor attitude gives way rather than the motors stopping
            scale = min(scale, -throttle / low)
        low, high = low * scale, high * scale
        best = -low
        adjust = throttle - best
        if scale < 1.0 or adjust < 0.0:
            adjust = 0.0
        elif adjust > span - (best + high):
            adjust = span - (best + high)
        return [self._floor + best + adjust + scale * o for o in out]
