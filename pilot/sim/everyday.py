"""Everyday things of the target's colour, placed near it: a person-sized figure in red or orange clothing with
skin-toned head and hands, a red chair, a terracotta pot, a wooden cabinet. A real room has them; a detector that
takes each for the ball lights the wrong thing. Each is a few solid props (boxes, cylinders, a sphere)."""

from __future__ import annotations

import math

import numpy as np

from . import scenario as r
from .furnish import Placement

# clothing of the target's hue and near it (red, crimson, orange-red, rust), skin tones (light to dark), wood
CLOTHING: tuple[r.RGB, ...] = ((0.78, 0.1, 0.1), (0.62, 0.06, 0.12), (0.9, 0.3, 0.1), (0.6, 0.22, 0.12))
SKIN: tuple[r.RGB, ...] = ((0.92, 0.72, 0.6), (0.8, 0.56, 0.42), (0.6, 0.4, 0.28), (0.4, 0.26, 0.18))
TROUSERS: tuple[r.RGB, ...] = ((0.15, 0.17, 0.25), (0.3, 0.3, 0.3), (0.45, 0.4, 0.32))
CHAIR_RED: tuple[r.RGB, ...] = ((0.75, 0.08, 0.08), (0.6, 0.1, 0.1))
TERRACOTTA: r.RGB = (0.7, 0.33, 0.2)
WOOD: tuple[r.RGB, ...] = ((0.55, 0.3, 0.16), (0.45, 0.24, 0.13), (0.62, 0.4, 0.24))


def _pick(rng: np.random.Generator, options: tuple[r.RGB, ...]) -> r.RGB:
    return options[int(rng.integers(0, len(options)))]


def _at(x: float, y: float, yaw: float, forward: float, left: float) -> tuple[float, float]:
    return x + forward * math.cos(yaw) - left * math.sin(yaw), y + forward * math.sin(yaw) + left * math.cos(yaw)


def person(x: float, y: float, yaw: float, rng: np.random.Generator) -> list[r.Prop]:
    """A standing figure about 1.7 m tall facing ``yaw``: legs, a torso and arms in clothing, a head."""
    shirt, skin, legs = _pick(rng, CLOTHING), _pick(rng, SKIN), _pick(rng, TROUSERS)
    out = []
    for side in (-1.0, 1.0):
        lx, ly = _at(x, y, yaw, 0.0, 0.1 * side)
        out.append(r.Prop("cylinder", (lx, ly, 0.42), (0.07, 0.42, 0.0), legs))
        ax, ay = _at(x, y, yaw, 0.0, 0.27 * side)
        out.append(r.Prop("cylinder", (ax, ay, 1.12), (0.05, 0.3, 0.0), shirt, distractor=True))
        hx, hy = _at(x, y, yaw, 0.0, 0.27 * side)
        out.append(r.Prop("sphere", (hx, hy, 0.78), (0.05, 0.0, 0.0), skin, distractor=True))  # a hand
    out.append(r.Prop("box", (x, y, 1.14), (0.12, 0.2, 0.3), shirt, yaw, distractor=True))
    out.append(r.Prop("sphere", (x, y, 1.57), (0.11, 0.0, 0.0), skin, distractor=True))
    return out


def chair(x: float, y: float, yaw: float, rng: np.random.Generator) -> list[r.Prop]:
    """A red chair: four legs, a seat and a back."""
    rgb = _pick(rng, CHAIR_RED)
    out = [r.Prop("box", (x, y, 0.45), (0.22, 0.22, 0.025), rgb, yaw, distractor=True)]
    bx, by = _at(x, y, yaw, -0.2, 0.0)
    out.append(r.Prop("box", (bx, by, 0.72), (0.025, 0.22, 0.25), rgb, yaw, distractor=True))
    for f, left in ((0.19, 0.19), (0.19, -0.19), (-0.19, 0.19), (-0.19, -0.19)):
        cx, cy = _at(x, y, yaw, f, left)
        out.append(r.Prop("cylinder", (cx, cy, 0.21), (0.02, 0.21, 0.0), (0.25, 0.25, 0.25)))
    return out


def pot(x: float, y: float, yaw: float, rng: np.random.Generator) -> list[r.Prop]:
    """A terracotta plant pot."""
    h = float(rng.uniform(0.18, 0.3))
    return [r.Prop("cylinder", (x, y, h), (float(rng.uniform(0.15, 0.22)), h, 0.0), TERRACOTTA, distractor=True)]


def cabinet(x: float, y: float, yaw: float, rng: np.random.Generator) -> list[r.Prop]:
    """A wooden cabinet."""
    half = (float(rng.uniform(0.2, 0.3)), float(rng.uniform(0.35, 0.5)), float(rng.uniform(0.4, 0.6)))
    return [r.Prop("box", (x, y, half[2]), half, _pick(rng, WOOD), yaw, distractor=True)]


KINDS = ((person, 0.4), (chair, 0.35), (pot, 0.25), (cabinet, 0.5))  # each with its footprint's radius


def near_target(p: Placement, count: int) -> tuple[r.Prop, ...]:
    """``count`` different everyday things 1-2.5 m from the target, off the straight path to it."""
    rng = p.rng
    out: list[r.Prop] = []
    tx, ty = p.target
    for k in rng.permutation(len(KINDS))[:count]:
        make, radius = KINDS[int(k)]
        for _ in range(100):
            d, a = float(rng.uniform(1.0, 2.5)), float(rng.uniform(-math.pi, math.pi))
            x, y = tx + d * math.cos(a), ty + d * math.sin(a)
            if p.clear(x, y, radius):
                out += make(x, y, float(rng.uniform(-math.pi, math.pi)), rng)
                break
    return tuple(out)
