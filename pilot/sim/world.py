"""The simulated world: the virtual drone's outputs move the kinematic model, the model's pose
(with the pan/tilt servo angles) drives the camera, and the flight is scored.

``SimWorld`` is both the pilot's pacer (``now()``, ``wait_tick()`` steps the firmware's clock by one
tick and integrates the model over it, following every output change at its millisecond) and, via
``camera()``, its frame source.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..closing import Closing
from ..errors import FrameSourceError, SimulatorError
from ..sources import Frame, FrameSourceBase
from .camera import CameraModel, CameraPose, Image, Renderer
from .model import DroneModel, ModelParams, Outputs, StickCentres
from .room import Scenario
from .virtual import VirtualDrone

BOOT_MS = 20  # the firmware boots and sends its ready line (39 bytes at 115200 baud: under 4 ms)


@dataclass
class FlightScore:
    lit_on_target_ms: int = 0  # laser on and its ray through the target, within reach
    lit_elsewhere_ms: int = 0
    min_distance: float = math.inf
    reached: bool = False  # came within reach
    path: list[tuple[float, float, float, float]] = field(default_factory=list)  # t, x, y, z
    max_altitude: float = 0.0


class SimWorld(Closing):
    def __init__(
        self,
        scenario: Scenario,
        vd: VirtualDrone,
        camera: CameraModel | None = None,
        *,
        tick_ms: int = 50,
        substep_ms: int = 10,
        reach_m: float = 2.0,
        aim_point: str = "ball",
        params: ModelParams | None = None,
        lose_camera_at_s: float | None = None,
    ) -> None:
        self.scenario = scenario
        self.vd = vd
        self.camera_model = camera or CameraModel()
        self.renderer = Renderer(scenario, self.camera_model)
        self.model = DroneModel(scenario.room, scenario.start, StickCentres.from_protocol(), params, scenario.wind)
        self.tick_ms = tick_ms
        self.substep_ms = substep_ms
        self.reach_m = reach_m
        self.aim_point = aim_point
        self.lose_camera_at_s = lose_camera_at_s
        self.score = FlightScore()
        changes = vd.step(BOOT_MS)
        if vd.outputs is None:
            raise SimulatorError("virtual drone reported no outputs at boot")
        self.outputs: Outputs = vd.outputs
        self.fw_state = vd.state
        self.changes_seen = len(changes)
        self._record_path()

    # -- the pacer ------------------------------------------------------------------------------
    def now(self) -> float:
        return self.vd.t_ms / 1000.0

    def wait_tick(self) -> None:
        self.advance(self.tick_ms)

    def advance(self, ms: int) -> None:
        t0 = self.vd.t_ms
        changes = self.vd.step(ms)
        self.changes_seen += len(changes)
        t = t0
        outputs = self.outputs
        pending = list(changes)
        end = self.vd.t_ms
        while t < end:
            while pending and pending[0].t_ms <= t:
                outputs = pending.pop(0).outputs
            nxt = min(end, t + self.substep_ms)
            if pending:
                nxt = min(nxt, max(pending[0].t_ms, t + 1))
            dt_ms = nxt - t
            self.model.step(outputs, dt_ms / 1000.0)
            self._score(outputs, dt_ms)
            t = nxt
        for change in pending:
            outputs = change.outputs
        self.outputs = outputs
        self.fw_state = self.vd.state
        self._record_path()

    # -- the camera -----------------------------------------------------------------------------
    def pose(self) -> CameraPose:
        s = self.model.state
        return CameraPose.from_drone(s.x, s.y, s.z, s.heading, self.outputs.pan, self.outputs.tilt)

    def render(self) -> Image:
        return self.renderer.render(self.pose(), self.now())

    def camera(self) -> SimCamera:
        return SimCamera(self)

    # -- scoring -------------------------------------------------------------------------------------
    def aim_target(self) -> tuple[tuple[float, float, float], float]:
        sc = self.scenario
        if self.aim_point == "marker" and sc.marker is not None:
            return sc.marker.centre, sc.marker.side / 2.0
        return sc.target.position, sc.target.radius

    def laser_on_target(self) -> bool:
        """Is the laser (on the camera mount, along its optical axis) hitting the target now?"""
        pose = self.pose()
        forward, _, _ = pose.axes()
        (tx, ty, tz), radius = self.aim_target()
        d = (tx - pose.position[0], ty - pose.position[1], tz - pose.position[2])
        along = d[0] * forward[0] + d[1] * forward[1] + d[2] * forward[2]
        if along <= 0:
            return False
        perp2 = d[0] ** 2 + d[1] ** 2 + d[2] ** 2 - along**2
        return perp2 <= radius**2 and self.scenario.target_visible(self.now())

    def distance(self) -> float:
        s = self.model.state
        (tx, ty, tz), _ = self.aim_target()
        return math.dist((s.x, s.y, s.z), (tx, ty, tz))

    def _score(self, outputs: Outputs, dt_ms: int) -> None:
        score = self.score
        dist = self.distance()
        score.min_distance = min(score.min_distance, dist)
        if dist <= self.reach_m:
            score.reached = True
        score.max_altitude = max(score.max_altitude, self.model.state.z)
        if outputs.laser:
            if dist <= self.reach_m and self.laser_on_target():
                score.lit_on_target_ms += dt_ms
            else:
                score.lit_elsewhere_ms += dt_ms

    def _record_path(self) -> None:
        s = self.model.state
        self.score.path.append((self.now(), s.x, s.y, s.z))

    def close(self) -> None:
        self.vd.close()



class SimCamera(FrameSourceBase):
    """The frame source of the simulated room: the view from the drone's current pose."""

    def __init__(self, world: SimWorld) -> None:
        super().__init__(world.now)
        self.world = world

    def read(self) -> Frame | None:
        w = self.world
        if self._closed:
            raise FrameSourceError("simulated camera: read after close")
        if w.lose_camera_at_s is not None and w.now() >= w.lose_camera_at_s:
            raise FrameSourceError(f"simulated camera lost at t={w.now():.2f} s")
        return self._frame(w.render())
