"""A scenario's start and target checked against the room before anything flies: a spawn point or a target
inside a wall or a piece of furniture is a scenario error (named, with the position), never a flight."""

from __future__ import annotations

import math

from ..common.errors import ConfigError
from .scenario import Prop, Scenario, Vec3

SPAWN_HALF_HEIGHT = 0.05  # the airframe's collision box rests on the floor (physics.BODY_HALF_HEIGHT)


def clearance(p: Prop, point: Vec3) -> float:
    """Distance (m) from ``point`` to the solid prop ``p``'s surface; 0 inside it."""
    x, y, z = (point[i] - p.position[i] for i in range(3))
    if p.shape == "sphere":
        return max(0.0, math.sqrt(x * x + y * y + z * z) - p.size[0])
    if p.shape == "cylinder":  # upright: radius, half-height
        radial = max(0.0, math.hypot(x, y) - p.size[0])
        return math.hypot(radial, max(0.0, abs(z) - p.size[1]))
    c, s = math.cos(p.yaw), math.sin(p.yaw)  # box: into its own axes
    local = (c * x + s * y, -s * x + c * y, z)
    return math.sqrt(sum(max(0.0, abs(v) - h) ** 2 for v, h in zip(local, p.size)))


def check(sc: Scenario) -> None:
    """Raise ConfigError when the drone's spawn point or the target lies in a wall or in a solid prop."""
    where = f"scenario {sc.name!r} seed {sc.seed}"
    room = sc.room
    sx, sy, _ = sc.start
    r = sc.wall_margin
    spawn = (sx, sy, SPAWN_HALF_HEIGHT)
    if not room.inside(sx, sy, r):
        raise ConfigError(f"{where}: the spawn point ({sx:.2f}, {sy:.2f}) is within the drone's radius {r:g} m "
                          f"of a wall or outside the {room.width:g} x {room.depth:g} m room")
    tx, ty, tz = sc.target.position
    tr = sc.target.radius
    if not (room.inside(tx, ty, tr) and tr <= tz <= room.height - tr):
        raise ConfigError(f"{where}: the target at ({tx:.2f}, {ty:.2f}, {tz:.2f}) lies in a wall, the floor or "
                          "the ceiling")
    for i, p in enumerate(sc.props):
        if p.shape == "poster":
            continue  # a picture on a wall: seen, never touched
        name = f"{'distractor' if p.distractor else 'prop'}_{i} ({p.shape} at {p.position[0]:.2f}, " \
               f"{p.position[1]:.2f})"
        # the spawn's footprint: the airframe's box, approximated by a disc of its radius at its centre height
        if clearance(p, spawn) < r:
            raise ConfigError(f"{where}: the spawn point ({sx:.2f}, {sy:.2f}) lies inside {name}")
        if clearance(p, sc.target.position) < tr:
            raise ConfigError(f"{where}: the target at ({tx:.2f}, {ty:.2f}, {tz:.2f}) lies inside {name}")
