"""A Scenario as a MuJoCo model: the room textured with photographs, furniture, distractors, lights, the target
(a mocap body: it can move) and the airframe with four thrust actuators and its pan/tilt camera.

Geom groups: 0 what the camera sees, 3 the airframe (its own camera never sees it), 4 a hidden target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import placement, textures
from .rc import Airframe
from .scenario import Prop, Scenario

DRONE_GROUP = 3
HIDDEN_GROUP = 4
CAMERA_POS = (0.23, 0.0, -0.03)  # on the airframe's nose, below the arms
ZNEAR = 0.001  # the camera's near clipping plane, in the room's extents (about 1 cm): at MuJoCo's 0.01 (11 cm), a
# wall within 9 cm of the airframe's nose vanished, and the camera saw the black outside the room
SHADOW_MAP_PX = 256  # the shadow map's side: soft shadows, as under diffuse room light; 1024 cost 1.5x the render
# MuJoCo draws a plane as a grid of quads of this side (its size's third figure) and lights it per vertex: the
# floor's and walls' light pools need a grid well under the lights' spread (a few metres), and each visible quad
# costs the software renderer in each of its three passes (colour, shadow map, shadowed light). 0.25 m moves a
# pixel by 0.2 grey levels on average from 0.1 m and saves a third of the render. Small planes keep 0.1 m.
ROOM_GRID_M = 0.25
SMALL_GRID_M = 0.1
MOTOR_SPIN = (1, -1, 1, -1)  # front-left, front-right... alternating directions cancel the reaction torque


@dataclass(frozen=True)
class Built:
    xml: str
    assets: dict[str, bytes]


def _f(*values: float) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _yaw_quat(yaw: float) -> str:
    return _f(math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))


def motor_positions(arm: float) -> list[tuple[float, float]]:
    """X configuration in the body frame (x forward, y left)."""
    d = arm / math.sqrt(2.0)
    return [(d, d), (d, -d), (-d, -d), (-d, d)]


def _wall_plane(name: str, x: float, y: float, z: float, normal_heading: float, half: tuple[float, float],
                material: str, offset: float = 0.0, solid: bool = True, grid: float = SMALL_GRID_M) -> str:
    """A plane facing into the room (its normal along ``normal_heading``); x axis = up x normal. MuJoCo collides
    with a plane as an infinite half-space, whatever its size (which is only drawn): a plane that is not
    ``solid`` (a picture on a wall, the marker on its backing board) is seen and hit by the laser's ray, never
    touched. A solid marker plane made the whole room behind the target a wall."""
    nx, ny = math.cos(normal_heading), math.sin(normal_heading)
    touch = "" if solid else ' contype="0" conaffinity="0"'
    return (f'<geom name="{name}" type="plane" pos="{_f(x + offset * nx, y + offset * ny, z)}" '
            f'xyaxes="{_f(-ny, nx, 0, 0, 0, 1)}" size="{_f(half[0], half[1], grid)}" material="{material}"{touch}/>')


class _Writer:
    def __init__(self) -> None:
        self.assets: dict[str, bytes] = {}
        self.materials: list[str] = []

    def photo_material(self, photo: str, repeat: tuple[float, float] = (1.0, 1.0), rgba: str = "1 1 1 1") -> str:
        name = f"photo_{photo}_{len(self.materials)}"
        file = f"{photo}.png"
        if file not in self.assets:
            self.assets[file] = textures.photo(photo)
            self.materials.append(f'<texture name="tex_{photo}" type="2d" file="{file}"/>')
        self.materials.append(f'<material name="{name}" texture="tex_{photo}" texrepeat="{_f(*repeat)}" '
                              f'rgba="{rgba}"/>')
        return name

    def surface_material(self, surface: str, rgb: tuple[float, float, float]) -> str:
        """A wall or floor photograph repeated at its real scale (MuJoCo's texuniform: repeats per metre)."""
        name = f"surface_{surface}_{len(self.materials)}"
        file = f"surface_{surface}.png"
        if file not in self.assets:
            self.assets[file] = textures.surface(surface)
            self.materials.append(f'<texture name="tex_surface_{surface}" type="2d" file="{file}"/>')
        per_m = 1.0 / textures.SURFACES[surface].metres
        self.materials.append(f'<material name="{name}" texture="tex_surface_{surface}" texuniform="true" '
                              f'texrepeat="{_f(per_m, per_m)}" rgba="{_f(*rgb, 1.0)}" specular="0.1"/>')
        return name

    def colour_material(self, name: str, rgb: tuple[float, float, float], emission: float = 0.0) -> str:
        self.materials.append(f'<material name="{name}" rgba="{_f(*rgb, 1.0)}" emission="{emission:g}" '
                              f'specular="0.2" shininess="0.3"/>')
        return name

    def prop(self, i: int, p: Prop) -> str:
        name = f"{'distractor' if p.distractor else 'prop'}_{i}"
        mat = self.photo_material(p.texture) if p.texture else self.colour_material(f"mat_{name}", p.rgb)
        if p.shape == "poster":
            return _wall_plane(name, p.position[0], p.position[1], p.position[2], p.yaw, (p.size[0], p.size[1]),
                               mat, offset=0.01, solid=False)
        size = {"box": p.size, "sphere": p.size[:1], "cylinder": p.size[:2]}[p.shape]
        return (f'<geom name="{name}" type="{p.shape}" pos="{_f(*p.position)}" quat="{_yaw_quat(p.yaw)}" '
                f'size="{_f(*size)}" material="{mat}"/>')


def build(scenario: Scenario, frame: Airframe, width: int, height: int, fovy_deg: float) -> Built:
    sc, room = scenario, scenario.room
    placement.check(sc)  # a spawn or target in a wall or a piece of furniture is refused, never flown
    w = _Writer()
    walls = w.surface_material(sc.wall_texture, sc.wall_rgb)
    floor = w.surface_material(sc.floor_texture, sc.floor_rgb)
    ceiling = w.colour_material("ceiling", (0.88, 0.88, 0.86))
    target = w.colour_material("target", sc.target.rgb)
    pole = w.colour_material("pole", (0.42, 0.42, 0.42))
    w.colour_material("airframe", (0.1, 0.1, 0.1))
    body: list[str] = [
        f'<geom name="floor" type="plane" pos="{_f(room.width / 2, room.depth / 2, 0)}" '
        f'size="{_f(room.width / 2, room.depth / 2, ROOM_GRID_M)}" material="{floor}"/>',
        # one quad: the lights hang below it and shine down, so it shows the ambient light alone, the same at
        # every vertex
        f'<geom name="ceiling" type="plane" pos="{_f(room.width / 2, room.depth / 2, room.height)}" '
        f'xyaxes="1 0 0 0 -1 0" size="{_f(room.width / 2, room.depth / 2, max(room.width, room.depth))}" '
        f'material="{ceiling}"/>',
    ]
    half_h = room.height / 2
    for name, x, y, heading, length in (("wall_south", room.width / 2, 0.0, math.pi / 2, room.width),
                                        ("wall_east", room.width, room.depth / 2, math.pi, room.depth),
                                        ("wall_north", room.width / 2, room.depth, -math.pi / 2, room.width),
                                        ("wall_west", 0.0, room.depth / 2, 0.0, room.depth)):
        body.append(_wall_plane(name, x, y, half_h, heading, (length / 2, half_h), walls, grid=ROOM_GRID_M))
    body += [w.prop(i, p) for i, p in enumerate(sc.props)]
    tx, ty, tz = sc.target.position
    if sc.window:  # a bright window on the wall behind the target, as seen from the start
        body.append(_window(w, sc))
    target_geoms = [
        f'<geom name="target_pole" type="cylinder" pos="0 0 {tz / 2:.4g}" size="0.015 {tz / 2:.4g}" '
        f'material="{pole}"/>',
        f'<geom name="target_ball" type="sphere" pos="0 0 {tz:.4g}" size="{sc.target.radius:.4g}" '
        f'material="{target}"/>',
    ]
    if sc.marker is not None:
        plate = sc.marker
        w.assets["marker.png"] = textures.marker(plate)
        w.materials.append('<texture name="tex_marker" type="2d" file="marker.png"/>')
        w.materials.append('<material name="marker" texture="tex_marker" rgba="1 1 1 1" specular="0"/>')
        half = plate.side * 0.75
        f = plate.facing
        # in front of the pole (radius 0.015): a pole across the marker's border would hide it from the detector
        target_geoms.append(_wall_plane("target_marker", 0.0, 0.0, plate.centre[2], f, (half, half), "marker",
                                        offset=0.032, solid=False))  # the backing board is what a drone touches
        bx, by = 0.022 * math.cos(f), 0.022 * math.sin(f)
        target_geoms.append(f'<geom name="target_backing" type="box" pos="{_f(bx, by, plate.centre[2])}" '
                            f'quat="{_yaw_quat(f)}" size="{_f(0.008, half, half)}" material="{pole}"/>')
    # shadows from the brightest light only: each shadowing light costs the software renderer a pass
    brightest = max(range(len(sc.lights)), key=lambda i: sum(sc.lights[i].rgb)) if sc.lights else -1
    casts = ["true" if sc.effects.shadows and i == brightest else "false" for i in range(len(sc.lights))]
    lights = [f'<light name="light_{i}" pos="{_f(*lt.position)}" dir="{_f(*lt.direction)}" '
              f'diffuse="{_f(*lt.rgb)}" specular="0.1 0.1 0.1" castshadow="{casts[i]}" attenuation="1 0 0"/>'
              for i, lt in enumerate(sc.lights)]
    motors = motor_positions(frame.arm_m)
    sites = "\n".join(f'      <site name="motor_{i}" pos="{_f(x, y, 0.02)}" size="0.01" group="{DRONE_GROUP}"/>'
                      for i, (x, y) in enumerate(motors))
    actuators = "\n".join(
        f'    <general site="motor_{i}" gear="{_f(0, 0, 1, 0, 0, spin * frame.yaw_moment_m)}" dyntype="filter" '
        f'dynprm="{frame.motor_tau_s:g}" gainprm="1" ctrllimited="true" ctrlrange="0 {frame.motor_max_n:g}"/>'
        for i, spin in enumerate(MOTOR_SPIN))
    sx, sy, heading = sc.start
    ix, iy, iz = frame.inertia
    amb = sc.ambient
    # no multisampling: MSAA doubled the software renderer's cost (5 -> 10 ms at 320x240), and the sensor's JPEG
    # and motion blur soften the edges anyway; shadows (the randomised world's) from a SHADOW_MAP_PX map
    xml = f"""<mujoco model="room">
  <compiler angle="radian"/>
  <option timestep="0.002"/>
  <visual>
    <global offwidth="{width}" offheight="{height}"/>
    <headlight ambient="{_f(amb, amb, amb)}" diffuse="0 0 0" specular="0 0 0"/>
    <quality shadowsize="{SHADOW_MAP_PX if sc.effects.shadows else 0}" offsamples="0"/>
    <map znear="{ZNEAR}"/>
  </visual>
  <asset>
    {chr(10).join('    ' + m for m in w.materials).strip()}
  </asset>
  <worldbody>
    {chr(10).join('    ' + line for line in lights + body).strip()}
    <body name="target" mocap="true" pos="{_f(tx, ty, 0)}">
      {chr(10).join('      ' + g for g in target_geoms).strip()}
    </body>
    <body name="drone" pos="{_f(sx, sy, 0.05)}" quat="{_yaw_quat(heading)}">
      <freejoint name="drone"/>
      <inertial pos="0 0 0" mass="{frame.mass_kg:g}" diaginertia="{_f(ix, iy, iz)}"/>
      <geom name="airframe" type="box" size="{_f(frame.radius_m, frame.radius_m, 0.05)}" mass="0"
            group="{DRONE_GROUP}" material="airframe"/>
{sites}
      <camera name="eye" pos="{_f(*CAMERA_POS)}" fovy="{fovy_deg:.5g}"/>
    </body>
  </worldbody>
  <actuator>
{actuators}
  </actuator>
</mujoco>
"""
    return Built(xml, w.assets)


def _window(w: _Writer, sc: Scenario) -> str:
    """The wall point behind the target along the line from the start, with a bright emissive pane."""
    sx, sy, _ = sc.start
    tx, ty, _ = sc.target.position
    room = sc.room
    dx, dy = tx - sx, ty - sy
    n = math.hypot(dx, dy)
    dx, dy = dx / n, dy / n
    ts = [t for t in ((room.width - tx) / dx if dx > 0 else -tx / dx if dx < 0 else math.inf,
                      (room.depth - ty) / dy if dy > 0 else -ty / dy if dy < 0 else math.inf)]
    t = min(ts)
    x, y = tx + t * dx, ty + t * dy
    on_x_wall = abs(t - ts[0]) < 1e-9  # the line meets a wall of constant x first
    heading = (math.pi if dx > 0 else 0.0) if on_x_wall else (-math.pi / 2 if dy > 0 else math.pi / 2)
    mat = w.colour_material("window", (1.0, 0.98, 0.92), emission=2.5)
    frame = w.colour_material("window_frame", (0.85, 0.85, 0.82))
    # the pane, then its frame and a cross of glazing bars in front of it (the bars cut the backlight as a
    # real window's do)
    along = (-math.sin(heading), math.cos(heading))
    parts = [_wall_plane("window", x, y, 1.6, heading, (1.0, 0.8), mat, offset=0.02, solid=False)]
    for i, (u, z, half) in enumerate(((0.0, 1.6, (0.03, 0.8)), (0.0, 1.6, (1.0, 0.03)), (-1.0, 1.6, (0.05, 0.85)),
                                      (1.0, 1.6, (0.05, 0.85)), (0.0, 0.8, (1.05, 0.05)), (0.0, 2.4, (1.05, 0.05)))):
        parts.append(_wall_plane(f"window_bar_{i}", x + u * along[0], y + u * along[1], z, heading, half, frame,
                                 offset=0.025, solid=False))
    return "\n    ".join(parts)
