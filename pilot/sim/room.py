"""The simulated room: geometry, the target, an ArUco marker plate, distractors, and named scenarios.

World frame: x along the room's width, y along its depth, z up, metres; the origin is a floor corner.
A heading (yaw) is measured counter-clockwise from +x, in radians. Everything is drawn from a
``numpy.random.Generator`` seeded from (scenario name, seed): the same pair gives the same room.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError

Vec3 = tuple[float, float, float]
BGR = tuple[int, int, int]

TARGET_RED: BGR = (30, 30, 205)
DISTRACTOR_COLOURS: tuple[BGR, ...] = ((0, 140, 255), (200, 90, 30), (50, 170, 50), (0, 210, 230), (150, 60, 150))


@dataclass(frozen=True)
class Room:
    width: float = 10.0  # x
    depth: float = 8.0  # y
    height: float = 3.0  # z

    def inside(self, x: float, y: float, margin: float) -> bool:
        return margin <= x <= self.width - margin and margin <= y <= self.depth - margin


@dataclass(frozen=True)
class Ball:
    """A sphere on a thin pole standing on the floor: the target or a distractor."""

    position: Vec3
    radius: float
    colour: BGR


@dataclass(frozen=True)
class MarkerPlate:
    """A vertical square ArUco plate (with its white border) facing ``facing`` (a heading, radians)."""

    centre: Vec3
    facing: float
    side: float  # black-bordered marker side, metres
    marker_id: int
    dictionary: str = "DICT_4X4_50"


@dataclass(frozen=True)
class Interval:
    start: float
    end: float

    def contains(self, t: float) -> bool:
        return self.start <= t < self.end


@dataclass(frozen=True)
class Scenario:
    name: str
    seed: int
    room: Room
    start: Vec3  # x, y, heading
    target: Ball
    marker: MarkerPlate | None
    distractors: tuple[Ball, ...] = ()
    hidden: tuple[Interval, ...] = ()  # times (s) when the target (and its marker) is covered
    light_gain: float = 1.0  # mean lighting gain
    light_wobble: float = 0.0  # amplitude of a slow lighting change
    noise_sigma: float = 0.0  # Gaussian pixel noise
    wind: tuple[float, float] = (0.0, 0.0)  # steady drift of the airborne drone, m/s along x and y
    time_budget_s: float = 60.0
    wall_margin: float = field(default=0.25)  # the drone's radius

    def target_visible(self, t: float) -> bool:
        return not any(iv.contains(t) for iv in self.hidden)


SCENARIOS = ("ahead", "behind", "side", "high", "low", "hidden", "distractor")


def _rng(name: str, seed: int) -> np.random.Generator:
    return np.random.default_rng([zlib.crc32(name.encode()), seed])


def make_scenario(
    name: str, seed: int, *, noise: bool = True, marker: bool = True, max_wind: float = 0.0
) -> Scenario:
    """A named scenario; ``seed`` varies the start pose, the target's bearing, distance and height,
    with ``noise`` the lighting and the pixel noise, and with ``max_wind`` (m/s) a steady wind up to it
    (off by default: the pilot has no position hold while the target is out of sight, see README)."""
    if name not in SCENARIOS:
        raise ConfigError(f"unknown scenario {name!r}; known: {', '.join(SCENARIOS)}")
    rng = _rng(name, seed)
    room = Room()
    for _ in range(1000):
        sx = float(rng.uniform(1.5, room.width - 1.5))
        sy = float(rng.uniform(1.5, room.depth - 1.5))
        heading = float(rng.uniform(-math.pi, math.pi))
        if name in ("ahead", "hidden", "distractor", "high", "low"):
            bearing = math.radians(float(rng.uniform(-15.0, 15.0)))
        elif name == "behind":
            bearing = math.pi + math.radians(float(rng.uniform(-25.0, 25.0)))
        else:  # side
            bearing = float(rng.choice([-1.0, 1.0])) * math.radians(float(rng.uniform(70.0, 110.0)))
        distance = float(rng.uniform(3.5, 6.0))
        tx = sx + distance * math.cos(heading + bearing)
        ty = sy + distance * math.sin(heading + bearing)
        if room.inside(tx, ty, 1.0):
            break
    else:  # pragma: no cover - the ranges above always leave room
        raise ConfigError(f"scenario {name!r} seed {seed}: no valid placement")
    if name == "high":
        tz = float(rng.uniform(2.1, 2.4))
    elif name == "low":
        tz = float(rng.uniform(0.3, 0.5))
    else:
        tz = float(rng.uniform(1.0, 1.6))
    target = Ball((tx, ty, tz), 0.15, TARGET_RED)
    facing = math.atan2(sy - ty, sx - tx)  # the plate faces the start
    # the plate hangs on the target's pole, below the ball (above it for a low target)
    plate_z = tz - 0.45 if tz >= 1.0 else tz + 0.45
    plate = MarkerPlate((tx, ty, plate_z), facing, 0.3, 7) if marker else None
    distractors: list[Ball] = []
    if name == "distractor":
        for k in range(3):
            for _ in range(100):
                d = float(rng.uniform(1.5, distance + 1.5))
                b = heading + bearing + math.radians(float(rng.uniform(-35.0, 35.0)))
                dx, dy = sx + d * math.cos(b), sy + d * math.sin(b)
                # keep them out of the straight path to the target so they never block it for good
                along = (dx - sx) * math.cos(heading + bearing) + (dy - sy) * math.sin(heading + bearing)
                across = -(dx - sx) * math.sin(heading + bearing) + (dy - sy) * math.cos(heading + bearing)
                if room.inside(dx, dy, 0.6) and (abs(across) > 0.8 or along > distance + 0.6):
                    break
            distractors.append(
                Ball((dx, dy, float(rng.uniform(0.6, 2.0))), float(rng.uniform(0.12, 0.3)),
                     DISTRACTOR_COLOURS[k % len(DISTRACTOR_COLOURS)])
            )
    hidden: tuple[Interval, ...] = ()
    if name == "hidden":
        start = float(rng.uniform(8.0, 11.0))
        hidden = (Interval(start, start + float(rng.uniform(1.5, 3.0))),)
    wind_speed = float(rng.uniform(0.0, 1.0)) * max_wind
    wind_dir = float(rng.uniform(-math.pi, math.pi))
    return Scenario(
        name=name,
        seed=seed,
        room=room,
        start=(sx, sy, heading),
        target=target,
        marker=plate,
        distractors=tuple(distractors),
        hidden=hidden,
        light_gain=float(rng.uniform(0.75, 1.2)) if noise else 1.0,
        light_wobble=float(rng.uniform(0.0, 0.15)) if noise else 0.0,
        noise_sigma=float(rng.uniform(2.0, 6.0)) if noise else 0.0,
        wind=(wind_speed * math.cos(wind_dir), wind_speed * math.sin(wind_dir)),
    )
