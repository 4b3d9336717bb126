"""The randomised rooms (pilot/sim/room.py, everyday.py, textures.py): photographs at their real scale, everyday
things of the target's colour near it, the target out of view at take-off in at least half the scenarios, and the
ball's size and shade as bought."""

from __future__ import annotations

import math
import re

import pytest
from sim_rig import PARAMS

from pilot.sim import textures
from pilot.sim.everyday import CLOTHING, SKIN
from pilot.sim.room import SCENARIOS, make_scenario
from pilot.sim.scenario import Room
from pilot.sim.scene import ROOM_GRID_M, build

SEEDS = range(6)


def test_walls_and_floor_are_photographs_at_their_real_scale() -> None:
    for name in SCENARIOS:
        sc = make_scenario(name, 1)
        assert sc.wall_texture in textures.SURFACES and sc.floor_texture in textures.SURFACES
    xml = build(make_scenario("ahead", 1), PARAMS.airframe, 64, 48, 45.0).xml
    repeats = [float(v) for v in re.findall(r'texuniform="true" texrepeat="([\d.]+) ', xml)]
    assert repeats == pytest.approx([1 / 0.72, 1 / 0.5])  # brick courses of 75 mm, gravel of 1-2 cm
    assert not re.search(r'file="(text|page|coins|grass)', xml)


def test_the_target_is_out_of_view_at_take_off_in_at_least_half_the_scenarios() -> None:
    for seed in SEEDS:
        hidden = 0
        for name in SCENARIOS:
            sc = make_scenario(name, seed)
            x, y, heading = sc.start
            tx, ty, _ = sc.target.position
            bearing = math.degrees((math.atan2(ty - y, tx - x) - heading + math.pi) % (2 * math.pi) - math.pi)
            hidden += abs(bearing) > 30.0 + math.degrees(sc.target.radius / math.dist((x, y), (tx, ty)))
        assert hidden >= len(SCENARIOS) / 2, seed


def test_everyday_things_of_the_target_s_colour_stand_near_it() -> None:
    colours = set()
    for name in SCENARIOS:
        for seed in SEEDS:
            sc = make_scenario(name, seed)
            tx, ty, _ = sc.target.position
            near = [p for p in sc.distractors if math.dist(p.position[:2], (tx, ty)) < 2.7]
            assert len(near) >= 2, (name, seed)
            colours |= {p.rgb for p in near}
    assert colours & set(CLOTHING) and colours & set(SKIN)  # red clothing and skin tones among them


def test_the_ball_s_size_and_shade_vary_as_bought() -> None:
    balls = [make_scenario("ahead", seed).target for seed in range(20)]
    assert all(0.135 <= b.radius <= 0.165 for b in balls) and len({b.radius for b in balls}) == 20
    assert all(b.rgb[0] >= 0.7 and max(b.rgb[1:]) <= 0.14 for b in balls) and len({b.rgb for b in balls}) == 20


def test_the_occluding_panel_stands_on_the_floor() -> None:
    sc = make_scenario("occluded", 1)
    panel = [p for p in sc.props if p.shape == "box" and p.size[0] == 0.02]
    assert len(panel) == 1 and panel[0].position[2] == pytest.approx(panel[0].size[2])


def test_the_room_is_drawn_in_quads_as_coarse_as_its_lighting_allows() -> None:
    """MuJoCo lights a plane per vertex of its grid, and each quad costs the software renderer: the floor and the
    walls in quads of ROOM_GRID_M, the ceiling (which the down-pointing lights never reach) in one."""
    grids: dict[str, float] = {}
    for name in SCENARIOS:
        sc = make_scenario(name, 1)
        xml = build(sc, PARAMS.airframe, 64, 48, 45.0).xml
        grids |= {g: float(v) for g, v in re.findall(r'name="(floor|ceiling|wall_\w+)" type="plane".*?size="'
                                                      r'[\d.]+ [\d.]+ ([\d.]+)"', xml)}
        for light in sc.lights:  # MuJoCo's spot cutoff: 45 degrees; the ceiling lies 90 degrees off straight down
            dx, dy, dz = light.direction
            assert math.degrees(math.acos(-dz / math.hypot(dx, dy, dz))) + 45.0 < 90.0, (name, light)
    assert grids.pop("ceiling") >= max(Room().width, Room().depth)
    assert set(grids) == {"floor", "wall_south", "wall_east", "wall_north", "wall_west"}
    assert set(grids.values()) == {ROOM_GRID_M}
