"""The camera and the laser on the pan/tilt mount, rendered by MuJoCo, and what a real sensor adds.

The mount sits on the airframe's nose and moves with it (lean, turn); the firmware's pan/tilt servo outputs
turn it (at the spec's default angles it looks straight ahead along the airframe). The laser shares the
camera's optical axis. Each frame: MuJoCo's offscreen render, then the sensor: auto-exposure, motion blur from
the camera's actual angular rate over the exposure time, optionally a rolling shutter's skew (rows read one after
another over ``readout_s``, each shifted by the image motion since the middle row), auto-exposure and auto white
balance (grey world) that settle with their time constants after a change of scene, Gaussian noise growing with
the gain (drawn once per seed and cycled), JPEG compression (a USB webcam's MJPEG; the Pi camera has none).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import cv2
import drone_protocol as dp
import numpy as np
import numpy.typing as npt

from . import mj
from .scenario import Scenario

Image = npt.NDArray[np.uint8]
FloatArray = npt.NDArray[np.float64]
# the camera frame in the airframe's (x forward, y left, z up): MuJoCo cameras look along their -z, y up
NOISE_GAINS = (1.0, 2.0, 4.0)
NOISE_FRAMES = 4
_LOOK_AHEAD = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class CameraModel:
    width: int = 320
    height: int = 240
    hfov_deg: float = 60.0
    target_brightness: float = 105.0  # auto-exposure's goal for the mean grey level
    max_gain: float = 4.0
    readout_s: float = 0.0  # rolling shutter: top to bottom row (0: a global shutter, the campaign's camera)

    @property
    def focal(self) -> float:
        return (self.width / 2.0) / math.tan(math.radians(self.hfov_deg) / 2.0)

    @property
    def fovy_deg(self) -> float:
        return math.degrees(2.0 * math.atan(math.tan(math.radians(self.hfov_deg) / 2.0) * self.height / self.width))


def mount_rotation(pan_deg: float, tilt_deg: float) -> FloatArray:
    """The camera frame in the airframe for the servo angles: pan above its default looks right
    (``servo_right``), tilt above its default looks up (``servo_up``)."""
    pan = -math.radians(pan_deg - dp.SERVOS[dp.ServoName.PAN].default)
    tilt = -math.radians(tilt_deg - dp.SERVOS[dp.ServoName.TILT].default)
    cz, sz = math.cos(pan), math.sin(pan)
    cy, sy = math.cos(tilt), math.sin(tilt)
    rz = np.array([[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]])
    result: FloatArray = rz @ ry @ _LOOK_AHEAD
    return result


class Sensor:
    """Renders the mount's view and applies the sensor's effects; deterministic for a scenario's seed."""

    def __init__(self, scenario: Scenario, camera: CameraModel, model: mj.Model, data: mj.Data) -> None:
        mujoco = mj.module()
        self.sc, self.cam, self.model, self.data = scenario, camera, model, data
        self.cam_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "eye")
        self.renderer = mujoco.Renderer(model, camera.height, camera.width)
        # Mesa compiles its shaders at their first draw (40-50 ms at 320x240): a cost of building the world, drawn
        # once here rather than in the flight's first frame
        self.renderer.update_scene(data, camera=self.cam_id)
        self.renderer.render()
        self.gain = 1.0
        self.white = (1.0, 1.0, 1.0)  # auto white balance's gains, B, G, R
        self.effects = scenario.effects
        self.readout_s = max(camera.readout_s, scenario.effects.readout_s)
        self._last_frame_t: float | None = None
        self._noise = self._noise_frames(np.random.default_rng([scenario.seed, 0x5EED]))
        self._frame_count = 0
        self._last_axis: FloatArray | None = None
        self._last_t = 0.0
        self.render_ms = 0.0  # time in MuJoCo's renderer for the last frame (the simulator's figures)
        self.sensor_ms = 0.0  # time in the sensor's effects for the last frame

    def _noise_frames(self, rng: np.random.Generator) -> dict[float, list[tuple[Image, Image]]]:
        """Sensor noise drawn once per seed (drawing it per frame costs more than MuJoCo's render): for gains of
        1, 2 and 4 (its sigma grows as the gain's square root), NOISE_FRAMES frames each, as the positive and
        the negative part for OpenCV's saturating add and subtract."""
        if self.sc.noise_sigma <= 0.0:
            return {}
        shape = (self.cam.height, self.cam.width, 3)
        out: dict[float, list[tuple[Image, Image]]] = {}
        for gain in NOISE_GAINS:
            frames = []
            for _ in range(NOISE_FRAMES):
                n = rng.normal(0.0, self.sc.noise_sigma * math.sqrt(gain), shape)
                frames.append((np.clip(n, 0, 255).astype(np.uint8), np.clip(-n, 0, 255).astype(np.uint8)))
            out[gain] = frames
        return out

    def aim(self, pan_deg: float, tilt_deg: float) -> None:
        mujoco = mj.module()
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, mount_rotation(pan_deg, tilt_deg).reshape(-1))
        self.model.cam_quat[self.cam_id] = quat
        mujoco.mj_camlight(self.model, self.data)

    def axis(self) -> tuple[FloatArray, FloatArray]:
        """The optical axis (and the laser's ray): origin and unit direction, world frame."""
        xmat = np.asarray(self.data.cam_xmat[self.cam_id]).reshape(3, 3)
        return np.array(self.data.cam_xpos[self.cam_id]), -xmat[:, 2]

    def render(self, t: float) -> Image:
        t0 = time.process_time()
        self.renderer.update_scene(self.data, camera=self.cam_id)
        rgb = self.renderer.render()
        t1 = time.process_time()
        self.render_ms = (t1 - t0) * 1000.0
        # OpenCV's channel swap: numpy's copy of a reversed view cost ten times as much (0.7 ms at 320x240)
        img: Image = self._sensor(np.asarray(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), dtype=np.uint8), t)
        self.sensor_ms = (time.process_time() - t1) * 1000.0
        return img

    def _sensor(self, img: Image, t: float) -> Image:
        sc = self.sc
        self._auto(cv2.mean(img)[:3], t)
        out = img
        flow = self._image_motion(t)
        blur = None if flow is None else _blur_kernel(flow * self.sc.exposure_s)
        if blur is not None:
            out = np.asarray(cv2.filter2D(out, -1, blur), dtype=np.uint8)
        if flow is not None and self.readout_s > 0.0:
            out = rolling_shutter(out, flow, self.readout_s)
        gains = tuple(self.gain * w for w in self.white)
        if max(abs(g - 1.0) for g in gains) > 1e-3:
            out = np.asarray(cv2.transform(out, np.diag(np.asarray(gains))), dtype=np.uint8)
        if self._noise:
            nearest = min(NOISE_GAINS, key=lambda g: abs(math.log(g / self.gain)))
            pos, neg = self._noise[nearest][self._frame_count % NOISE_FRAMES]
            out = np.asarray(cv2.subtract(cv2.add(out, pos), neg), dtype=np.uint8)
        self._frame_count += 1
        if self.effects.picam:
            return out
        ok, data = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, sc.jpeg_quality])
        if ok:
            out = np.asarray(cv2.imdecode(data, cv2.IMREAD_COLOR), dtype=np.uint8)
        return out

    def _auto(self, means: tuple[float, ...], t: float) -> None:
        """Auto-exposure towards ``target_brightness`` and grey-world white balance from the rendered frame's
        channel means, each a first-order lag of its time constant (settled at the first frame: the camera ran
        before take-off). Without a time constant (the ideal world) the exposure moves half-way each frame by the
        earlier rule, which overshoots to its limits, and there is no white balance."""
        cam, e = self.cam, self.effects
        grey = max(sum(means) / 3.0, 1.0)
        first, dt = self._last_frame_t is None, max(t - (self._last_frame_t or 0.0), 0.0)
        self._last_frame_t = t
        if e.ae_tau_s <= 0.0:
            wanted = cam.target_brightness / grey * self.gain
            self.gain += (min(cam.max_gain, max(0.5, wanted)) - self.gain) * 0.5
            return
        a = 1.0 if first else 1.0 - math.exp(-dt / e.ae_tau_s)
        self.gain += (min(cam.max_gain, max(0.5, cam.target_brightness / grey)) - self.gain) * a
        if e.awb_tau_s > 0.0:
            a = 1.0 if first else 1.0 - math.exp(-dt / e.awb_tau_s)
            want = [min(2.0, max(0.5, grey / max(c, 1.0))) for c in means]
            b, g, r = (w + (v - w) * a for w, v in zip(self.white, want))
            self.white = (b, g, r)

    def _image_motion(self, t: float) -> FloatArray | None:
        """The image's motion (px/s, x right, y down) from the optical axis' angular rate since the last frame."""
        _, axis = self.axis()
        last, dt = self._last_axis, t - self._last_t
        self._last_axis, self._last_t = axis, t
        if last is None or dt <= 0.0:
            return None
        xmat = np.asarray(self.data.cam_xmat[self.cam_id]).reshape(3, 3)
        rate = (axis - last) / dt  # radians per second, world frame
        return np.array([float(rate @ xmat[:, 0]), -float(rate @ xmat[:, 1])]) * self.cam.focal

    def close(self) -> None:
        self.renderer.close()


def _blur_kernel(swept: FloatArray) -> FloatArray | None:
    """A line kernel along ``swept`` (px moved during the exposure); None under 1.5 px."""
    dx, dy = float(swept[0]), float(swept[1])
    length = math.hypot(dx, dy)
    if length < 1.5:
        return None
    size = math.ceil(length) | 1
    kernel = np.zeros((size, size))
    c = size // 2
    cv2.line(kernel, (round(c - dx / 2), round(c - dy / 2)), (round(c + dx / 2), round(c + dy / 2)), 1.0, 1)
    total = float(kernel.sum())
    return kernel / total if total > 0 else None


def rolling_shutter(img: Image, flow: FloatArray, readout_s: float) -> Image:
    """Rows read top to bottom over ``readout_s``: each shows the scene as it stood when it was read, i.e. moved by
    ``flow`` (px/s) times its delay from the middle row. Unchanged when no row would move by half a pixel."""
    h, w = img.shape[:2]
    if float(np.hypot(*flow)) * readout_s / 2.0 < 0.5:
        return img
    delay = ((np.arange(h, dtype=np.float32) + 0.5) / h - 0.5) * np.float32(readout_s)  # s, per row
    xs = np.arange(w, dtype=np.float32)[None, :] - np.float32(flow[0]) * delay[:, None]
    ys = np.arange(h, dtype=np.float32)[:, None] - np.float32(flow[1]) * delay[:, None] + np.zeros((1, w), np.float32)
    out = cv2.remap(img, xs, ys, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return np.asarray(out, dtype=np.uint8)
