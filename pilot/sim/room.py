"""The simulated room as data: geometry, the target, its ArUco plate, furniture, distractors, lights and wind,
and the named scenarios. Nothing here renders or imports MuJoCo (``scene.py`` turns a Scenario into a model), so
the pilot's command line can list the scenarios without the simulator's dependencies.

World frame: x along the room's width, y along its depth, z up, metres; the origin is a floor corner.
A heading (yaw) is measured counter-clockwise from +x, in radians. Everything is drawn from a
``numpy.random.Generator`` seeded from (scenario name, seed): the same pair gives the same room.
"""

from __future__ import annotations

import math
import zlib

import numpy as np

from ..common.errors import ConfigError
from . import everyday, furnish, placement, randomise
from .scenario import Ball, Interval, Light, MarkerPlate, Room, Scenario

BASIC = ("ahead", "behind", "side", "high", "low", "hidden", "distractor")
SCENARIOS = (*BASIC, "cluttered", "red_distractors", "dim", "backlit", "moving_target", "marker_edge", "occluded")
# the target out of the 60-degree view at take-off (8 of the 14): behind, to the side, or anywhere 40-180 degrees off
OUT_OF_VIEW = ("behind", "side", "high", "low", "hidden", "distractor", "cluttered", "red_distractors")
WALLS: tuple[tuple[float, float, float], ...] = ((0.9, 0.88, 0.84), (0.7, 0.7, 0.7), (0.72, 0.42, 0.34))  # painted
# white or grey, bare red brick
FLOORS: tuple[tuple[float, float, float], ...] = ((0.7, 0.68, 0.62), (0.55, 0.5, 0.45), (0.62, 0.62, 0.64))


def _rng(name: str, seed: int) -> np.random.Generator:
    return np.random.default_rng([zlib.crc32(name.encode()), seed])


def _bearing(name: str, rng: np.random.Generator) -> float:
    if name == "behind":
        return math.pi + math.radians(float(rng.uniform(-25.0, 25.0)))
    if name == "side":
        return float(rng.choice([-1.0, 1.0])) * math.radians(float(rng.uniform(70.0, 110.0)))
    if name == "marker_edge":  # at the edge of the 60° view: the marker is cut by the frame's border
        return float(rng.choice([-1.0, 1.0])) * math.radians(float(rng.uniform(24.0, 29.0)))
    if name in OUT_OF_VIEW:
        return float(rng.choice([-1.0, 1.0])) * math.radians(float(rng.uniform(40.0, 180.0)))
    return math.radians(float(rng.uniform(-15.0, 15.0)))


def _lights(name: str, rng: np.random.Generator, noise: bool) -> tuple[tuple[Light, ...], float]:
    """Per-seed intensity, colour temperature (warm to cool) and direction."""
    level = float(rng.uniform(0.7, 1.1)) if noise else 0.9
    if name == "dim":
        level = float(rng.uniform(0.18, 0.3))
    warmth = float(rng.uniform(-1.0, 1.0)) if noise else 0.0
    tint = (1.0 + 0.12 * warmth, 1.0, 1.0 - 0.15 * warmth)
    lights = []
    for k in range(2):
        x = float(rng.uniform(2.0, 8.0))
        y = float(rng.uniform(1.5, 6.5))
        d = (float(rng.uniform(-0.4, 0.4)), float(rng.uniform(-0.4, 0.4)), -1.0)
        gain = level * (0.6 if k else 0.5)
        lights.append(Light(d, (gain * tint[0], gain * tint[1], gain * tint[2]), (x, y, 2.9)))
    return tuple(lights), 0.25 * level


def make_scenario(
    name: str, seed: int, *, noise: bool = True, marker: bool = True, max_wind: float = 0.0, gusts: float = 0.0,
    ideal: bool = False,
) -> Scenario:
    """A named scenario; ``seed`` varies the start pose, the target's bearing, distance and height, the
    furniture, with ``noise`` the lighting, the sensor noise and the compression, and with ``max_wind`` (m/s) a
    steady wind up to it and ``gusts`` (m/s) random gusts (both off by default: still air). ``ideal`` turns the
    randomised world's effects off (``randomise.py``), the sensor noise too."""
    if name not in SCENARIOS:
        raise ConfigError(f"unknown scenario {name!r}; known: {', '.join(SCENARIOS)}")
    effects = randomise.draw(name, seed, ideal=ideal)
    noise = noise and not ideal
    rng = _rng(name, seed)
    room = Room()
    for _ in range(1000):
        sx = float(rng.uniform(1.5, room.width - 1.5))
        sy = float(rng.uniform(1.5, room.depth - 1.5))
        heading = float(rng.uniform(-math.pi, math.pi))
        bearing = _bearing(name, rng)
        distance = float(rng.uniform(3.5, 6.0))
        tx = sx + distance * math.cos(heading + bearing)
        ty = sy + distance * math.sin(heading + bearing)
        if room.inside(tx, ty, 1.0):
            break
    else:  # pragma: no cover - the ranges above always leave room
        raise ConfigError(f"scenario {name!r} seed {seed}: no valid placement")
    tz = {"high": (2.0, 2.3), "low": (0.35, 0.5)}.get(name, (1.0, 1.6))
    # a ball sold as 30 cm (27-33 cm as bought and inflated), of a red between crimson and tomato
    shade = (float(rng.uniform(0.7, 0.9)), float(rng.uniform(0.04, 0.14)), float(rng.uniform(0.04, 0.12)))
    target = Ball((tx, ty, float(rng.uniform(*tz))), float(rng.uniform(0.135, 0.165)), shade)
    facing = math.atan2(sy - ty, sx - tx)  # the plate faces the start
    # the plate hangs on the target's pole, below the ball (above it for a low target)
    plate_z = target.position[2] - 0.45 if target.position[2] >= 1.0 else target.position[2] + 0.45
    plate = MarkerPlate((tx, ty, plate_z), facing, 0.3, 7) if marker else None
    place = furnish.Placement(room.width, room.depth, (sx, sy), (tx, ty), rng)
    props = furnish.furniture(place, crowded=name == "cluttered")
    if name == "distractor":
        props += furnish.coloured_balls(place)
    if name == "red_distractors":
        props += furnish.red_things(place)
    if name == "occluded":
        props += furnish.occluder(place, target.position, target.radius)
    props += everyday.near_target(place, int(rng.integers(2, 4)))
    hidden: tuple[Interval, ...] = ()
    if name == "hidden":
        begin = float(rng.uniform(8.0, 11.0))
        hidden = (Interval(begin, begin + float(rng.uniform(1.5, 3.0))),)
    motion = (0.0, 0.0, 1.0)
    if name == "moving_target":  # sways across the view, up to 0.15 m/s
        across = heading + bearing + math.pi / 2.0
        amp = float(rng.uniform(0.3, 0.5))
        motion = (amp * math.cos(across), amp * math.sin(across), float(rng.uniform(16.0, 22.0)))
    lights, ambient = _lights(name, rng, noise)
    wind_speed = float(rng.uniform(0.0, 1.0)) * max_wind
    wind_dir = float(rng.uniform(-math.pi, math.pi))
    dim = name == "dim"
    built = Scenario(
        name=name,
        seed=seed,
        room=room,
        start=(sx, sy, heading),
        target=target,
        marker=plate,
        props=props,
        hidden=hidden,
        target_motion=motion,
        lights=lights,
        ambient=ambient,
        wall_texture=str(rng.choice(furnish.WALL_TEXTURES)),
        floor_texture=str(rng.choice(furnish.FLOOR_TEXTURES)),
        wall_rgb=WALLS[int(rng.integers(0, len(WALLS)))],
        floor_rgb=FLOORS[int(rng.integers(0, len(FLOORS)))],
        window=name == "backlit",
        # indoors under room light a camera's auto-exposure sits at 1/120-1/40 s (1/30 s when dim)
        exposure_s=(1.0 / 30.0 if dim else float(rng.uniform(1.0 / 120.0, 1.0 / 40.0))) if noise else 1.0 / 500.0,
        noise_sigma=(float(rng.uniform(2.0, 5.0)) if noise else 0.0) * (2.5 if dim else 1.0),
        jpeg_quality=int(rng.integers(70, 95)) if noise else 95,
        wind=(wind_speed * math.cos(wind_dir), wind_speed * math.sin(wind_dir)),
        gusts=gusts,
        effects=effects,
    )
    placement.check(built)
    return built
