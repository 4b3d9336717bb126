"""The simulated world: the virtual drone's RC pulses fly the airframe in MuJoCo (through the emulated
ArduCopter), its servo outputs turn the camera and laser mount, and the flight is scored.

``SimWorld`` is both the pilot's pacer (``now()``; ``wait_tick()`` steps the firmware's clock by one tick and
the physics over it, the pulses changing at the millisecond the firmware changed them) and, via ``camera()``,
its frame source. The laser is a ray along the camera's axis: lit on the target's surface (the ball, or the
marker plate when the pilot aims at the marker) within reach counts for the flight; lit on anything else is a
non-target hit.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..common.closing import Closing
from ..common.errors import FrameSourceError, SimulatorError
from ..vision.sources import Frame, FrameSourceBase
from . import mj, rc
from .camera import CameraModel, Image, Sensor
from .latency import FrameTiming, History, Pose, Servos
from .physics import Airframe, AirframeState
from .scenario import Scenario
from .scene import DRONE_GROUP, HIDDEN_GROUP, build
from .virtual import Outputs, VirtualDrone

BOOT_MS = 20  # the firmware boots and sends its ready line (39 bytes at 115200 baud: under 4 ms)
STEP_MS = 2  # the physics' time step


@dataclass
class FlightScore:
    lit_on_target_ms: int = 0  # laser on and its ray on the target's surface, within reach
    lit_elsewhere_ms: int = 0  # laser on, its ray on anything else
    non_target_hits: int = 0  # times the laser came on (or moved) onto something that is not the target
    non_target_what: list[str] = field(default_factory=list)
    lit_during_fault_ms: int = 0  # laser on while the camera was faulty
    min_distance: float = math.inf
    reached: bool = False  # came within reach
    path: list[tuple[float, float, float, float]] = field(default_factory=list)  # t, x, y, z
    max_altitude: float = 0.0
    # the simulator's cost, in CPU time (the process's, all its threads): the machine's other load does not count
    physics_ms: float = 0.0  # physics, control and estimation
    render_ms: float = 0.0  # MuJoCo's renderer (and posing the past for it)
    sensor_ms: float = 0.0  # the sensor's effects
    frames: int = 0
    # each stay of the laser spot on the target, unbroken (lit, on its surface, within reach): [start ms, length ms]
    on_target_runs: list[list[int]] = field(default_factory=list)
    on_target_now: bool = False

    def spot(self, on_target: bool, t_ms: int, dt_ms: int) -> None:
        """The spot during the ``dt_ms`` that end at ``t_ms``: a stay on the target goes on or ends."""
        if on_target and not self.on_target_now:
            self.on_target_runs.append([t_ms - dt_ms, 0])
        if on_target:
            self.on_target_runs[-1][1] += dt_ms
        self.on_target_now = on_target

    @property
    def longest_on_target_ms(self) -> int:
        return max((length for _, length in self.on_target_runs), default=0)


class PortCounts(Protocol):
    """What the step barrier needs of the pilot's link (pilot.link.serial_link.Link)."""

    bytes_written: int
    bytes_read: int

    def unread(self) -> int | None: ...


class SimWorld(Closing):
    def __init__(
        self,
        scenario: Scenario,
        vd: VirtualDrone,
        camera: CameraModel | None = None,
        *,
        tick_ms: int = 50,
        reach_m: float = 2.0,
        aim_point: str = "ball",
        params: rc.SimParams | None = None,
        lose_camera_at_s: float | None = None,
        fault: CameraFault | None = None,
    ) -> None:
        mujoco = mj.module()
        self.scenario = scenario
        self.vd = vd
        self.camera_model = camera or CameraModel()
        self.params = (params or rc.load()).varied(scenario.effects)
        built = build(scenario, self.params.airframe, self.camera_model.width, self.camera_model.height,
                      self.camera_model.fovy_deg)
        try:
            self.mj_model = mujoco.MjModel.from_xml_string(built.xml, built.assets)
        except ValueError as exc:  # pragma: no cover - the scene builder's own bug
            raise SimulatorError(f"MuJoCo refused the scene: {exc}") from exc
        self.mj_data = mujoco.MjData(self.mj_model)
        self.airframe = Airframe(scenario, self.params, self.mj_model, self.mj_data)
        self.sensor = Sensor(scenario, self.camera_model, self.mj_model, self.mj_data)
        self.tick_ms = tick_ms
        self.reach_m = reach_m
        self.aim_point = aim_point
        self.lose_camera_at_s = lose_camera_at_s
        self.fault = fault
        self.fault_start = None if fault is None or fault.start_s < 0 else fault.start_s
        self.score = FlightScore()
        self._ray_groups = np.array([1 if g not in (DRONE_GROUP, HIDDEN_GROUP) else 0 for g in range(6)], np.uint8)
        wanted = "target_marker" if aim_point == "marker" and scenario.marker is not None else "target_ball"
        self._aim_geom = int(mujoco.mj_name2id(self.mj_model, mujoco.mjtObj.mjOBJ_GEOM, wanted))
        self._last_hit = -1
        self.link: PortCounts | None = None  # the pilot's port on the pty, when attached: the step barrier
        changes = vd.step(BOOT_MS)
        if vd.outputs is None:
            raise SimulatorError("virtual drone reported no outputs at boot")
        self.outputs: Outputs = vd.outputs
        self.fw_state = vd.state
        self.changes_seen = len(changes)
        self._t_ms = vd.t_ms
        self.sensor.aim(self.outputs.pan, self.outputs.tilt)
        effects = scenario.effects
        self.servos = Servos(effects, self.outputs.pan, self.outputs.tilt)
        self.timing = FrameTiming(effects, scenario.seed)
        self.history = (History(self.timing.keep_s, STEP_MS)
                        if effects.frame_latency_s > 0.0 or effects.frame_drop > 0.0 else None)
        self._remember()
        self._record_path()

    @property
    def state(self) -> AirframeState:
        return self.airframe.state

    # -- the pacer ------------------------------------------------------------------------------
    def now(self) -> float:
        return self.vd.t_ms / 1000.0

    def wait_tick(self) -> None:
        self.advance(self.tick_ms)

    def advance(self, ms: int) -> None:
        """Run the firmware ``ms`` milliseconds, then the physics over the same time in 2 ms steps, each with the
        outputs the firmware had at the step's start."""
        link = self.link
        changes = self.vd.step(ms, None if link is None else link.bytes_written)
        if link is not None:
            self._await_replies(link)
        self.changes_seen += len(changes)
        pending = list(changes)
        end = self.vd.t_ms
        outputs = self.outputs
        t0 = time.process_time()
        while self._t_ms + STEP_MS <= end:
            while pending and pending[0].t_ms <= self._t_ms:
                outputs = pending.pop(0).outputs
            if self.servos.step(outputs.pan, outputs.tilt, STEP_MS / 1000.0):
                self.sensor.aim(self.servos.pan, self.servos.tilt)
            self.airframe.step(outputs.pulses, STEP_MS / 1000.0)
            self._t_ms += STEP_MS
            self._remember()
            self._score(outputs, STEP_MS)
        for change in pending:
            outputs = change.outputs
        self.outputs = outputs
        if self.servos.step(outputs.pan, outputs.tilt, 0.0):  # ideal servos follow a change at the tick's end
            self.sensor.aim(self.servos.pan, self.servos.tilt)
        self.fw_state = self.vd.state
        self.score.physics_ms += (time.process_time() - t0) * 1000.0
        self._record_path()

    def _await_replies(self, link: PortCounts) -> None:
        """Wait (up to 2 s of wall time) until the pilot's port holds every byte the firmware wrote back, so
        that a reply is read in the tick it was sent whatever the machine's load."""
        deadline = time.monotonic() + 2.0
        while time.monotonic() < deadline:
            unread = link.unread()
            if unread is None or link.bytes_read + unread >= self.vd.tx_total:
                return
            time.sleep(0.0002)

    # -- the camera -----------------------------------------------------------------------------
    def render(self) -> Image:
        """The frame the pilot reads now: the room as it was at the frame's exposure (``latency.py``)."""
        t0 = time.process_time()
        t = self.timing.exposure(self.now())
        pose = None if self.history is None else self.history.at(t * 1000.0)
        img = self.sensor.render(self.now()) if pose is None else self._render_past(pose, t)
        self.score.sensor_ms += self.sensor.sensor_ms
        self.score.render_ms += (time.process_time() - t0) * 1000.0 - self.sensor.sensor_ms
        self.score.frames += 1
        return img

    def _render_past(self, pose: Pose, t: float) -> Image:
        """Render from ``pose`` (the airframe, the target and the mount then), then put the present back."""
        mujoco, d = mj.module(), self.mj_data
        qpos, mocap = d.qpos.copy(), d.mocap_pos.copy()
        d.qpos[:], d.mocap_pos[:] = pose.qpos, pose.mocap
        mujoco.mj_kinematics(self.mj_model, d)
        self.sensor.aim(pose.pan, pose.tilt)
        try:
            return self.sensor.render(t)
        finally:
            d.qpos[:], d.mocap_pos[:] = qpos, mocap
            mujoco.mj_kinematics(self.mj_model, d)
            self.sensor.aim(self.servos.pan, self.servos.tilt)

    def _remember(self) -> None:
        if self.history is not None:
            d = self.mj_data
            self.history.record(Pose(self._t_ms, d.qpos.copy(), d.mocap_pos.copy(), self.servos.pan,
                                     self.servos.tilt))

    def camera(self) -> SimCamera:
        return SimCamera(self)

    # -- scoring -------------------------------------------------------------------------------------
    def laser_hit(self) -> int:
        """The geom the laser's ray meets first (-1: nothing)."""
        mujoco = mj.module()
        origin, axis = self.sensor.axis()
        geom = np.array([-1], np.int32)
        mujoco.mj_ray(self.mj_model, self.mj_data, origin, axis, self._ray_groups, 1, self.airframe.body, geom)
        return int(geom[0])

    def target_position(self) -> tuple[float, float, float]:
        geom = self._aim_geom
        x, y, z = (float(v) for v in self.mj_data.geom_xpos[geom])
        return x, y, z

    def distance(self) -> float:
        s = self.state
        return math.dist((s.x, s.y, s.z), self.target_position())

    def _score(self, outputs: Outputs, dt_ms: int) -> None:
        score = self.score
        s = self.state
        dist = self.distance()
        score.min_distance = min(score.min_distance, dist)
        if dist <= self.reach_m:
            score.reached = True
        score.max_altitude = max(score.max_altitude, s.z)
        if not outputs.laser:
            self._last_hit = -1
            score.spot(False, self._t_ms, dt_ms)
            return
        fault = self.fault
        if fault is not None and self.fault_start is None:
            self.fault_start = self._t_ms / 1000.0  # a fault that starts with the laser
        if fault is not None and fault.active(self._t_ms / 1000.0, self.fault_start):
            score.lit_during_fault_ms += dt_ms
        hit = self.laser_hit()
        score.spot(hit == self._aim_geom and dist <= self.reach_m, self._t_ms, dt_ms)
        if hit == self._aim_geom and dist <= self.reach_m:
            score.lit_on_target_ms += dt_ms
        else:
            score.lit_elsewhere_ms += dt_ms
            if hit != self._last_hit and hit != self._aim_geom:
                score.non_target_hits += 1
                mujoco = mj.module()
                score.non_target_what.append(mujoco.mj_id2name(self.mj_model, mujoco.mjtObj.mjOBJ_GEOM, hit) or "?")
        self._last_hit = hit

    def _record_path(self) -> None:
        s = self.state
        self.score.path.append((self.now(), s.x, s.y, s.z))

    def close(self) -> None:
        try:
            self.sensor.close()
        finally:
            self.vd.close()


@dataclass(frozen=True)
class CameraFault:
    """A camera that misbehaves from ``start_s`` (or, when it is negative, from the moment the laser first comes on)
    for ``duration_s``: ``black``, ``saturated``, ``frozen`` (its last good frame again), ``small`` (a frame of
    another size) or ``grey`` (one channel)."""

    kind: str
    start_s: float
    duration_s: float

    KINDS = ("black", "saturated", "frozen", "small", "grey")

    @staticmethod
    def parse(text: str) -> CameraFault:
        """KIND@START+DURATION, seconds: ``black@8+3``; START ``fire``: when the laser first comes on."""
        try:
            kind, times = text.split("@")
            start, duration = times.split("+")
            fault = CameraFault(kind, -1.0 if start == "fire" else float(start), float(duration))
        except ValueError as exc:
            raise SimulatorError(f"camera fault {text!r}: expected KIND@START+DURATION, e.g. black@8+3") from exc
        if fault.kind not in CameraFault.KINDS or not math.isfinite(fault.start_s) or fault.duration_s <= 0:
            raise SimulatorError(f"camera fault {text!r}: kind one of {', '.join(CameraFault.KINDS)}, "
                                 "START seconds or 'fire', DURATION above 0")
        return fault

    def active(self, t: float, start: float | None) -> bool:
        """``start``: when it began (``start_s``, or the laser's first on; None: not yet)."""
        return start is not None and start <= t < start + self.duration_s

    def apply(self, t: float, start: float | None, image: Image, last: Image | None) -> Image:
        if not self.active(t, start):
            return image
        if self.kind == "black":
            return np.zeros_like(image)
        if self.kind == "saturated":
            return np.full_like(image, 255)
        if self.kind == "frozen":
            return last if last is not None else image
        if self.kind == "small":
            return np.ascontiguousarray(image[::2, ::2])
        return np.ascontiguousarray(image[..., 1])  # grey: one channel


class SimCamera(FrameSourceBase):
    """The frame source of the simulated room: the view from the drone's current pose."""

    def __init__(self, world: SimWorld) -> None:
        super().__init__(world.now)
        self.world = world
        self._good: Image | None = None

    def read(self) -> Frame | None:
        w = self.world
        if self._closed:
            raise FrameSourceError("simulated camera: read after close")
        if w.lose_camera_at_s is not None and w.now() >= w.lose_camera_at_s:
            raise FrameSourceError(f"simulated camera lost at t={w.now():.2f} s")
        image = w.render()
        if w.fault is not None:
            faulty = w.fault.apply(w.now(), w.fault_start, image, self._good)
            if faulty is image:
                self._good = image
            image = faulty
        return self._frame(image)
