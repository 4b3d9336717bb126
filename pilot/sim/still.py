"""A scenario's room seen from a pose of our choosing, without the virtual drone or the physics: the pilot's
``--dry-run`` view and the benches' and tests' frames. Same scene, same camera and sensor as a flight."""

from __future__ import annotations

import math

import drone_protocol as dp
import numpy as np

from . import mj, rc
from .camera import CameraModel, Image, Sensor
from .scenario import Scenario
from .scene import build


class StillView:
    def __init__(self, scenario: Scenario, camera: CameraModel | None = None) -> None:
        mujoco = mj.module()
        self.scenario = scenario
        self.camera = camera or CameraModel()
        params = rc.load()
        built = build(scenario, params.airframe, self.camera.width, self.camera.height, self.camera.fovy_deg)
        self.model = mujoco.MjModel.from_xml_string(built.xml, built.assets)
        self.data = mujoco.MjData(self.model)
        self.sensor = Sensor(scenario, self.camera, self.model, self.data)
        x, y, heading = scenario.start
        self.place(x, y, 1.2, heading)

    def place(self, x: float, y: float, z: float, heading: float, pan: float | None = None,
              tilt: float | None = None) -> None:
        """The airframe level at (x, y, z) facing ``heading``; the mount at the servo angles (default: ahead)."""
        mujoco = mj.module()
        pan = dp.SERVOS[dp.ServoName.PAN].default if pan is None else pan
        tilt = dp.SERVOS[dp.ServoName.TILT].default if tilt is None else tilt
        self.data.qpos[0:7] = [x, y, z + 0.05, math.cos(heading / 2.0), 0.0, 0.0, math.sin(heading / 2.0)]
        mujoco.mj_forward(self.model, self.data)
        self.sensor.aim(pan, tilt)

    def render(self, t: float = 0.0) -> Image:
        return self.sensor.render(t)

    def project(self, point: tuple[float, float, float]) -> tuple[float, float, float] | None:
        """Pixel coordinates and depth of a world point, or None when it is behind the camera."""
        xmat = np.asarray(self.sensor.data.cam_xmat[self.sensor.cam_id]).reshape(3, 3)
        d = np.asarray(point) - np.asarray(self.sensor.data.cam_xpos[self.sensor.cam_id])
        right, up, back = xmat[:, 0] @ d, xmat[:, 1] @ d, xmat[:, 2] @ d
        if -back <= 0.05:
            return None
        f = self.camera.focal
        return (self.camera.width / 2.0 + f * right / -back, self.camera.height / 2.0 - f * up / -back, float(-back))

    def close(self) -> None:
        self.sensor.close()

