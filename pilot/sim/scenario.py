"""The simulated room's data types: geometry, the target, its ArUco plate, props, lights and the scenario that
holds them. ``room.py`` draws a scenario from a seed; nothing here renders or imports MuJoCo.

World frame: x along the room's width, y along its depth, z up, metres; the origin is a floor corner. A heading
(yaw) is measured counter-clockwise from +x, in radians."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .randomise import IDEAL, Effects

Vec3 = tuple[float, float, float]
RGB = tuple[float, float, float]
BGR = tuple[int, int, int]

TARGET_RGB: RGB = (0.80, 0.08, 0.07)


@dataclass(frozen=True)
class Room:
    width: float = 10.0  # x
    depth: float = 8.0  # y
    height: float = 3.0  # z

    def inside(self, x: float, y: float, margin: float) -> bool:
        return margin <= x <= self.width - margin and margin <= y <= self.depth - margin


@dataclass(frozen=True)
class Ball:
    """The target: a sphere on a thin pole standing on the floor."""

    position: Vec3
    radius: float
    rgb: RGB = TARGET_RGB

    @property
    def colour(self) -> BGR:
        return (int(self.rgb[2] * 255), int(self.rgb[1] * 255), int(self.rgb[0] * 255))


@dataclass(frozen=True)
class Prop:
    """Furniture, clutter or a distractor: a box, sphere or cylinder standing in the room, or a poster (a
    plane) on a wall. ``size`` is MuJoCo's: half-extents (box), radius (sphere), radius and half-height
    (cylinder), half-width and half-height (poster). ``texture`` names a photograph (``textures.py``)."""

    shape: str  # box, sphere, cylinder, poster
    position: Vec3
    size: Vec3
    rgb: RGB
    yaw: float = 0.0  # heading of the prop's +x axis (a poster's normal, into the room)
    texture: str = ""
    distractor: bool = False  # target-like colour: detecting it is a false detection

    @property
    def radius(self) -> float:
        return max(self.size[0], self.size[1]) if self.shape != "sphere" else self.size[0]

    @property
    def colour(self) -> BGR:
        return (int(self.rgb[2] * 255), int(self.rgb[1] * 255), int(self.rgb[0] * 255))


@dataclass(frozen=True)
class MarkerPlate:
    """A vertical square ArUco plate (with its white border) facing ``facing`` (a heading, radians)."""

    centre: Vec3
    facing: float
    side: float  # black-bordered marker side, metres
    marker_id: int
    dictionary: str = "DICT_4X4_50"


@dataclass(frozen=True)
class Light:
    direction: Vec3  # where it shines
    rgb: RGB  # colour times intensity
    position: Vec3 = (5.0, 4.0, 2.9)


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
    props: tuple[Prop, ...] = ()
    hidden: tuple[Interval, ...] = ()  # times (s) when the target (and its marker) is covered
    target_motion: Vec3 = (0.0, 0.0, 1.0)  # amplitude (m) along x, along y, period (s): a moving target
    lights: tuple[Light, ...] = ()
    ambient: float = 0.3
    wall_texture: str = "brick"  # a photograph of textures.SURFACES, drawn at its real scale
    floor_texture: str = "gravel"
    wall_rgb: RGB = (0.85, 0.82, 0.78)  # the photograph's tint: painted or bare brick, concrete's shade
    floor_rgb: RGB = (0.7, 0.68, 0.62)
    window: bool = False  # a bright window on the wall behind the target (backlit)
    exposure_s: float = 1.0 / 120.0  # the camera's exposure time: motion blur
    noise_sigma: float = 0.0  # sensor noise at unit gain
    jpeg_quality: int = 90
    wind: tuple[float, float] = (0.0, 0.0)  # steady wind, m/s along x and y
    gusts: float = 0.0  # gust strength, m/s (a seeded random process)
    time_budget_s: float = 60.0
    effects: Effects = IDEAL  # the randomised world's imperfections (randomise.py)
    wall_margin: float = field(default=0.25)  # the drone's radius

    def target_visible(self, t: float) -> bool:
        return not any(iv.contains(t) for iv in self.hidden)

    def target_offset(self, t: float) -> tuple[float, float]:
        ax, ay, period = self.target_motion
        s = math.sin(2.0 * math.pi * t / period)
        return ax * s, ay * s

    @property
    def distractors(self) -> tuple[Prop, ...]:
        return tuple(p for p in self.props if p.distractor)
