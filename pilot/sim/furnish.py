"""Furniture, clutter and distractors for a scenario, placed so that none of them sits on the start, the target
or the straight line between them (they may stand beside it, in view: that is their point)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import scenario as r

WALL_TEXTURES = ("brick",)  # textures.SURFACES: photographs drawn at their real scale
FLOOR_TEXTURES = ("gravel",)
POSTERS = ("astronaut", "coffee", "chelsea", "rocket", "hubble_deep_field", "immunohistochemistry", "camera")
FURNITURE_RGB: tuple[r.RGB, ...] = ((0.45, 0.32, 0.2), (0.55, 0.55, 0.52), (0.2, 0.25, 0.35), (0.7, 0.68, 0.6))
# not the target, but near its hue: orange, pink, red-brown, and pure reds
RED_THINGS: tuple[r.RGB, ...] = ((0.85, 0.1, 0.08), (0.75, 0.05, 0.1), (0.62, 0.28, 0.18), (0.95, 0.45, 0.05),
                                 (0.95, 0.45, 0.6))
OTHER_BALLS: tuple[r.RGB, ...] = ((1.0, 0.55, 0.0), (0.12, 0.35, 0.8), (0.2, 0.67, 0.2), (0.9, 0.82, 0.0),
                                  (0.6, 0.24, 0.6))


@dataclass
class Placement:
    width: float
    depth: float
    start: tuple[float, float]
    target: tuple[float, float]
    rng: np.random.Generator

    def clear(self, x: float, y: float, radius: float) -> bool:
        """Inside the room, off the start and the target, and off the straight path between them."""
        if not (0.2 + radius <= x <= self.width - 0.2 - radius and 0.2 + radius <= y <= self.depth - 0.2 - radius):
            return False
        (sx, sy), (tx, ty) = self.start, self.target
        if math.dist((x, y), (sx, sy)) < 1.2 + radius or math.dist((x, y), (tx, ty)) < 0.8 + radius:
            return False
        dx, dy = tx - sx, ty - sy
        length = math.hypot(dx, dy)
        along = ((x - sx) * dx + (y - sy) * dy) / length
        across = abs(-(x - sx) * dy + (y - sy) * dx) / length
        return not (-0.5 < along < length + 0.5 and across < 0.9 + radius)

    def spot(self, radius: float, near_view: bool = False) -> tuple[float, float] | None:
        """A clear floor spot; ``near_view``: within the cone the drone looks through on its way."""
        (sx, sy), (tx, ty) = self.start, self.target
        for _ in range(200):
            if near_view:
                d = float(self.rng.uniform(1.5, math.dist((sx, sy), (tx, ty)) + 2.0))
                b = math.atan2(ty - sy, tx - sx) + math.radians(float(self.rng.uniform(-35.0, 35.0)))
                x, y = sx + d * math.cos(b), sy + d * math.sin(b)
            else:
                x, y = float(self.rng.uniform(0.0, self.width)), float(self.rng.uniform(0.0, self.depth))
            if self.clear(x, y, radius):
                return x, y
        return None

    def wall_spot(self) -> tuple[float, float, float]:
        """A point on a wall (x, y) and the heading into the room."""
        wall = int(self.rng.integers(0, 4))
        u = float(self.rng.uniform(0.15, 0.85))
        return [(u * self.width, 0.0, math.pi / 2), (self.width, u * self.depth, math.pi),
                (u * self.width, self.depth, -math.pi / 2), (0.0, u * self.depth, 0.0)][wall]


def _pick(rng: np.random.Generator, options: tuple[r.RGB, ...]) -> r.RGB:
    return options[int(rng.integers(0, len(options)))]


def furniture(p: Placement, crowded: bool) -> tuple[r.Prop, ...]:
    """Tables, cabinets and boxes on the floor, and photographs on the walls (more of both when crowded)."""
    rng = p.rng
    out: list[r.Prop] = []
    for _ in range(int(rng.integers(6, 10)) if crowded else int(rng.integers(2, 4))):
        half = (float(rng.uniform(0.2, 0.6)), float(rng.uniform(0.2, 0.5)), float(rng.uniform(0.2, 0.55)))
        spot = p.spot(max(half[0], half[1]), near_view=crowded)
        if spot is not None:
            out.append(r.Prop("box", (spot[0], spot[1], half[2]), half, _pick(rng, FURNITURE_RGB),
                              yaw=float(rng.uniform(0.0, math.pi))))
    for _ in range(int(rng.integers(4, 7)) if crowded else int(rng.integers(2, 4))):
        x, y, facing = p.wall_spot()
        half = (float(rng.uniform(0.35, 0.7)), float(rng.uniform(0.3, 0.5)), 0.0)
        photo = POSTERS[int(rng.integers(0, len(POSTERS)))]
        out.append(r.Prop("poster", (x, y, float(rng.uniform(1.1, 1.9))), half, (1.0, 1.0, 1.0), facing, photo))
    return tuple(out)


def coloured_balls(p: Placement) -> tuple[r.Prop, ...]:
    """Balls of other colours in view (today's `distractor` scenario)."""
    out = []
    for k in range(3):
        radius = float(p.rng.uniform(0.12, 0.3))
        spot = p.spot(radius, near_view=True)
        if spot is not None:
            z = float(p.rng.uniform(0.6, 2.0))
            out.append(r.Prop("sphere", (spot[0], spot[1], z), (radius, 0.0, 0.0), OTHER_BALLS[k], distractor=True))
    return tuple(out)


def red_things(p: Placement) -> tuple[r.Prop, ...]:
    """Red, orange, pink and red-brown things that are not the target: a box, a pot, a ball, a poster."""
    rng = p.rng
    out: list[r.Prop] = []
    half = (float(rng.uniform(0.15, 0.3)), float(rng.uniform(0.15, 0.3)), float(rng.uniform(0.15, 0.35)))
    spot = p.spot(0.4, near_view=True)
    if spot is not None:  # a red box
        out.append(r.Prop("box", (spot[0], spot[1], half[2]), half, _pick(rng, RED_THINGS[:2]), distractor=True))
    spot = p.spot(0.3, near_view=True)
    if spot is not None:  # a terracotta pot
        height = float(rng.uniform(0.2, 0.35))
        out.append(r.Prop("cylinder", (spot[0], spot[1], height), (float(rng.uniform(0.15, 0.25)), height, 0.0),
                          RED_THINGS[2], distractor=True))
    spot = p.spot(0.3, near_view=True)
    if spot is not None:  # an orange or pink ball, the target's size
        out.append(r.Prop("sphere", (spot[0], spot[1], float(rng.uniform(0.8, 1.8))), (0.15, 0.0, 0.0),
                          _pick(rng, RED_THINGS[3:]), distractor=True))
    x, y, facing = p.wall_spot()  # a red poster
    out.append(r.Prop("poster", (x, y, float(rng.uniform(1.0, 1.8))), (0.4, 0.3, 0.0), _pick(rng, RED_THINGS[:2]),
                      facing, distractor=True))
    return tuple(out)


def occluder(p: Placement, target: r.Vec3, radius: float) -> tuple[r.Prop, ...]:
    """A thin panel standing between the start and the target that covers about 30 % of the ball from the start."""
    (sx, sy), (tx, ty, tz) = p.start, target
    heading = math.atan2(ty - sy, tx - sx)
    back = 0.6  # in front of the target, along the line of sight
    cx, cy = tx - back * math.cos(heading), ty - back * math.sin(heading)
    side = float(p.rng.choice([-1.0, 1.0]))
    # the panel's inner edge reaches 0.3 of the ball's diameter in from its side, scaled to the panel's range
    dist = math.dist((sx, sy), (tx, ty))
    scale = (dist - back) / dist
    edge = (radius - 0.6 * radius) * scale * side
    half_w = 0.3
    offset = edge + side * half_w
    px, py = cx - offset * math.sin(heading), cy + offset * math.cos(heading)
    top = tz + 0.4  # a room divider standing on the floor, its top 0.4 m above the ball's centre
    return (r.Prop("box", (px, py, top / 2.0), (0.02, half_w, top / 2.0), (0.5, 0.5, 0.5), heading),)
