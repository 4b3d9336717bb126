"""A kinematic drone model driven by the RC pulses the virtual drone outputs.

It stands in for ArduCopter plus the airframe, in the simplest form that still makes the pilot's
job real. It reads the pulses only, as the flight controller does (not the firmware's own idea of
being armed). Each stick is read against its Table 4 median (from ``drone_protocol.CHANNELS``):

* arming, as ArduCopter's stick arming: on the ground, throttle at its minimum and yaw full right
  (within ``stick_margin_us`` of the recorded extremes) held for ``arm_hold_s``; disarming: throttle
  minimum and yaw full left for the same time, on the ground only (ArduCopter refuses it in flight);

* a dead band of ``dead_band_us`` (default 12 µs) either side of the median is "centred";
* pitch above its median flies forward, roll above its median slides right, throttle above its
  median climbs, yaw above its median turns right (clockwise seen from above) — the senses of
  Tables 2 and 3;
* outside the dead band a stick commands a velocity proportional to its offset: ``speed_per_100us``
  (m/s per 100 µs) for pitch and roll, ``climb_per_100us`` for throttle, ``yaw_deg_per_100us``
  for yaw, clamped to ``max_speed``/``max_climb``/``max_yaw_deg``; the airframe follows with
  a first-order lag (``tau_xy``, ``tau_z``, ``tau_yaw`` seconds);
* throttle below the channel's recorded minimum (only the firmware's failsafe throttle goes there)
  descends at ``land_speed``;
* disarmed: the motors stop; touching down faster than ``crash_speed`` counts as a crash;
* airborne, the scenario's steady wind (none by default) drifts it;
* the room's walls, floor and ceiling stop it: touching a wall (within ``radius`` of it) counts as a
  wall hit; the floor is where it lands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .room import Room


@dataclass(frozen=True)
class StickCentres:
    roll: int
    pitch: int
    throttle: int
    yaw: int
    throttle_minimum: int  # the recorded minimum: below it only the failsafe's throttle goes
    yaw_minimum: int
    yaw_maximum: int

    @staticmethod
    def from_protocol() -> StickCentres:
        import drone_protocol as dp

        ch = dp.CHANNELS
        return StickCentres(
            roll=int(ch[dp.ChannelName.ROLL].median),
            pitch=int(ch[dp.ChannelName.PITCH].median),
            throttle=int(ch[dp.ChannelName.THROTTLE].median),
            yaw=int(ch[dp.ChannelName.YAW].median),
            throttle_minimum=int(ch[dp.ChannelName.THROTTLE].minimum),
            yaw_minimum=int(ch[dp.ChannelName.YAW].minimum),
            yaw_maximum=int(ch[dp.ChannelName.YAW].maximum),
        )


@dataclass(frozen=True)
class ModelParams:
    dead_band_us: float = 12.0
    speed_per_100us: float = 0.8
    climb_per_100us: float = 0.6
    yaw_deg_per_100us: float = 60.0
    max_speed: float = 2.5
    max_climb: float = 1.5
    max_yaw_deg: float = 180.0
    tau_xy: float = 0.25
    tau_z: float = 0.25
    tau_yaw: float = 0.12
    land_speed: float = 0.8
    crash_speed: float = 2.0
    stick_margin_us: float = 50.0
    arm_hold_s: float = 1.5  # ArduCopter: about 2 s; shorter than the firmware's hold, so that it always suffices
    radius: float = 0.25


@dataclass(frozen=True)
class Outputs:
    """What the virtual drone's pins say at one moment."""

    roll: int
    pitch: int
    throttle: int
    yaw: int
    mode: int
    pan: float
    tilt: float
    laser: bool
    armed: bool


@dataclass
class DroneState:
    x: float
    y: float
    z: float = 0.0
    heading: float = 0.0
    v_forward: float = 0.0
    v_right: float = 0.0
    v_up: float = 0.0
    yaw_rate: float = 0.0  # rad/s, counter-clockwise positive
    wall_hits: int = 0
    crashes: int = 0
    touching: bool = field(default=False)
    armed: bool = False  # the flight controller's arming, from the sticks
    arm_timer: float = 0.0
    disarm_timer: float = 0.0


class DroneModel:
    def __init__(
        self,
        room: Room,
        start: tuple[float, float, float],
        centres: StickCentres,
        params: ModelParams | None = None,
        wind: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        self.room = room
        self.wind = wind
        self.centres = centres
        self.p = params or ModelParams()
        self.state = DroneState(x=start[0], y=start[1], heading=start[2])

    def _stick(self, pulse: int, centre: int) -> float:
        """Offset beyond the dead band, in units of 100 µs."""
        off = pulse - centre
        band = self.p.dead_band_us
        if abs(off) <= band:
            return 0.0
        return (off - math.copysign(band, off)) / 100.0

    def _arming(self, out: Outputs, dt: float, airborne: bool) -> None:
        p, s, c = self.p, self.state, self.centres
        throttle_low = out.throttle <= c.throttle_minimum + p.stick_margin_us
        yaw_right = out.yaw >= c.yaw_maximum - p.stick_margin_us
        yaw_left = out.yaw <= c.yaw_minimum + p.stick_margin_us
        if not airborne and throttle_low and yaw_right and not s.armed:
            s.arm_timer += dt
            if s.arm_timer >= p.arm_hold_s - 1e-9:
                s.armed = True
        else:
            s.arm_timer = 0.0
        if not airborne and throttle_low and yaw_left and s.armed:
            s.disarm_timer += dt
            if s.disarm_timer >= p.arm_hold_s - 1e-9:
                s.armed = False
        else:
            s.disarm_timer = 0.0

    def step(self, out: Outputs, dt: float) -> None:
        p, s, c = self.p, self.state, self.centres
        airborne = s.z > 1e-6
        self._arming(out, dt, airborne)
        if not s.armed:
            want_f = want_r = want_yaw = 0.0
            want_up = -2.0 * p.crash_speed if airborne else 0.0  # motors off in the air (only if forced): it falls
        else:
            want_f = max(-p.max_speed, min(p.max_speed, p.speed_per_100us * self._stick(out.pitch, c.pitch)))
            want_r = max(-p.max_speed, min(p.max_speed, p.speed_per_100us * self._stick(out.roll, c.roll)))
            want_yaw = -math.radians(
                max(-p.max_yaw_deg, min(p.max_yaw_deg, p.yaw_deg_per_100us * self._stick(out.yaw, c.yaw)))
            )
            if out.throttle < c.throttle_minimum:
                want_up = -p.land_speed
            else:
                want_up = max(-p.max_climb, min(p.max_climb, p.climb_per_100us * self._stick(out.throttle, c.throttle)))
            if not airborne and want_up <= 0.0:  # on the ground: no sliding, no turning
                want_f = want_r = want_yaw = want_up = 0.0
        a_xy = 1.0 - math.exp(-dt / p.tau_xy)
        a_z = 1.0 - math.exp(-dt / p.tau_z)
        a_yaw = 1.0 - math.exp(-dt / p.tau_yaw)
        s.v_forward += (want_f - s.v_forward) * a_xy
        s.v_right += (want_r - s.v_right) * a_xy
        s.v_up += (want_up - s.v_up) * (1.0 if not s.armed else a_z)
        s.yaw_rate += (want_yaw - s.yaw_rate) * a_yaw
        s.heading = (s.heading + s.yaw_rate * dt + math.pi) % (2.0 * math.pi) - math.pi
        ch, sh = math.cos(s.heading), math.sin(s.heading)
        # forward along the heading, right is the heading turned clockwise
        nx = s.x + (s.v_forward * ch + s.v_right * sh) * dt
        ny = s.y + (s.v_forward * sh - s.v_right * ch) * dt
        if airborne:  # the wind drifts it; nothing holds position but the pilot's corrections
            nx += self.wind[0] * dt
            ny += self.wind[1] * dt
        nz = s.z + s.v_up * dt
        r = p.radius
        touching = False
        if nx < r or nx > self.room.width - r:
            nx = min(max(nx, r), self.room.width - r)
            touching = True
        if ny < r or ny > self.room.depth - r:
            ny = min(max(ny, r), self.room.depth - r)
            touching = True
        if nz > self.room.height - 0.1:
            nz = self.room.height - 0.1
            touching = True
        if nz <= 0.0:
            if airborne and -s.v_up > p.crash_speed:
                s.crashes += 1
            nz = 0.0
            s.v_up = 0.0
            if s.z <= 0.0:
                s.v_forward = s.v_right = s.yaw_rate = 0.0
        if touching and not s.touching:
            s.wall_hits += 1
        s.touching = touching
        s.x, s.y, s.z = nx, ny, nz
