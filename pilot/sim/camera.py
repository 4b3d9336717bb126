"""A pinhole camera on the drone's pan/tilt mount, rendering the simulated room cheaply.

Each frame starts from a prepared background (ceiling above the horizon, floor below) copied
into place; the four walls are drawn as polygons clipped at the near plane, then the balls (target
and distractors, with their poles) and the ArUco plate, far to near. Lighting gain and Gaussian
noise come from the scenario and are deterministic (the noise frames are drawn once per seed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import drone_protocol as dp
import numpy as np
import numpy.typing as npt

from .room import BGR, Ball, MarkerPlate, Scenario, Vec3

Image = npt.NDArray[np.uint8]
FloatArray = npt.NDArray[np.float64]

CEILING: BGR = (225, 225, 222)
FLOOR: BGR = (95, 110, 125)
WALLS: tuple[BGR, ...] = ((185, 180, 170), (170, 176, 182), (160, 168, 160), (176, 170, 176))
POLE: BGR = (110, 110, 110)
NEAR = 0.05
SHIFT = 4  # sub-pixel bits for OpenCV drawing
ONE = 1 << SHIFT


@dataclass(frozen=True)
class CameraModel:
    width: int = 320
    height: int = 240
    hfov_deg: float = 60.0

    @property
    def focal(self) -> float:
        return (self.width / 2.0) / math.tan(math.radians(self.hfov_deg) / 2.0)


@dataclass(frozen=True)
class CameraPose:
    position: Vec3
    yaw: float  # heading of the optical axis, radians, counter-clockwise from +x
    pitch: float  # elevation of the optical axis, radians, up positive

    @staticmethod
    def from_drone(x: float, y: float, z: float, heading: float, pan_deg: float, tilt_deg: float) -> CameraPose:
        """Servo angles in degrees: at the spec's defaults (``drone_protocol.SERVOS``) the camera looks straight
        ahead and level; pan above its default looks right (``servo_right``), tilt above looks up (``servo_up``)."""
        pan0, tilt0 = dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default
        return CameraPose((x, y, z), heading - math.radians(pan_deg - pan0), math.radians(tilt_deg - tilt0))

    def axes(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        cy, sy = math.cos(self.yaw), math.sin(self.yaw)
        cp, sp = math.cos(self.pitch), math.sin(self.pitch)
        forward = np.array([cp * cy, cp * sy, sp])
        right = np.array([sy, -cy, 0.0])
        up = np.array([-sp * cy, -sp * sy, cp])  # right x forward
        return forward, right, up

    def matrix(self) -> FloatArray:
        """Rows: right, up, forward (world -> camera)."""
        forward, right, up = self.axes()
        return np.stack([right, up, forward])


def marker_bits(plate: MarkerPlate) -> npt.NDArray[np.bool_]:
    """The marker's cells including its black border: True = black."""
    dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, plate.dictionary))
    cells = dictionary.markerSize + 2
    img = cv2.aruco.generateImageMarker(dictionary, plate.marker_id, cells * 10)
    centres = np.asarray(img)[5::10, 5::10]
    return np.asarray(centres < 128)


class Renderer:
    def __init__(self, scenario: Scenario, camera: CameraModel | None = None) -> None:
        self.scenario = scenario
        self.camera = camera or CameraModel()
        cam = self.camera
        self._focal = cam.focal
        self._cx = cam.width / 2.0
        self._cy = cam.height / 2.0
        # prepared background twice the frame's height: ceiling over floor, the horizon in the middle;
        # each frame copies the window that puts the horizon where the camera's pitch puts it
        self._background = np.empty((2 * cam.height, cam.width, 3), np.uint8)
        self._background[: cam.height] = CEILING
        self._background[cam.height :] = FLOOR
        r = scenario.room
        corners = [(0.0, 0.0), (r.width, 0.0), (r.width, r.depth), (0.0, r.depth)]
        self._walls = [
            np.array(
                [
                    [a[0], a[1], 0.0],
                    [b[0], b[1], 0.0],
                    [b[0], b[1], r.height],
                    [a[0], a[1], r.height],
                ]
            )
            for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
        ]
        self._bits = marker_bits(scenario.marker) if scenario.marker is not None else None
        self._black = np.nonzero(self._bits) if self._bits is not None else (np.zeros(0, np.intp),) * 2
        rng = np.random.default_rng([scenario.seed, 0x5EED])
        self._noise: list[tuple[Image, Image]] = []
        if scenario.noise_sigma > 0:
            for _ in range(4):
                n = rng.normal(0.0, scenario.noise_sigma, (cam.height, cam.width, 3))
                self._noise.append(
                    (np.clip(n, 0, 255).astype(np.uint8), np.clip(-n, 0, 255).astype(np.uint8))
                )
        self._count = 0
        self._pose: CameraPose | None = None
        self._rot_t = np.eye(3)
        self._origin = np.zeros(3)

    # -- projection -------------------------------------------------------------------------
    def _to_camera(self, pose: CameraPose, points: FloatArray) -> FloatArray:
        if pose is not self._pose:
            self._pose = pose
            self._rot_t = pose.matrix().T
            self._origin = np.asarray(pose.position)
        result: FloatArray = (points - self._origin) @ self._rot_t
        return result

    def _project(self, cam_pts: FloatArray) -> FloatArray:
        z = cam_pts[..., 2]
        u = self._cx + self._focal * cam_pts[..., 0] / z
        v = self._cy - self._focal * cam_pts[..., 1] / z
        return np.clip(np.stack([u, v], axis=-1), -1e4, 1e4)

    def project_point(self, pose: CameraPose, point: Vec3) -> tuple[float, float, float] | None:
        """Pixel coordinates and depth of a world point, or None when it is behind the camera."""
        c = self._to_camera(pose, np.array([point]))[0]
        if c[2] <= NEAR:
            return None
        uv = self._project(c)
        return float(uv[0]), float(uv[1]), float(c[2])

    @staticmethod
    def _clip_near(poly: FloatArray) -> FloatArray:
        out: list[FloatArray] = []
        n = len(poly)
        for i in range(n):
            a, b = poly[i], poly[(i + 1) % n]
            a_in, b_in = a[2] > NEAR, b[2] > NEAR
            if a_in:
                out.append(a)
            if a_in != b_in:
                t = (NEAR - a[2]) / (b[2] - a[2])
                out.append(a + t * (b - a))
        return np.array(out) if out else np.empty((0, 3))

    def _fill(self, img: Image, uv: FloatArray, colour: BGR) -> None:
        pts = np.round(uv * ONE).astype(np.int32)
        cv2.fillConvexPoly(img, pts, colour, lineType=cv2.LINE_8, shift=SHIFT)

    # -- drawing -------------------------------------------------------------------------------
    def render(self, pose: CameraPose, t: float) -> Image:
        cam = self.camera
        horizon = self._cy + self._focal * math.tan(pose.pitch)
        row = int(min(max(round(horizon), 0), cam.height))
        img: Image = self._background[cam.height - row : 2 * cam.height - row].copy()
        for wall, colour in zip(self._walls, WALLS, strict=True):
            clipped = self._clip_near(self._to_camera(pose, wall))
            if len(clipped) >= 3:
                self._fill(img, self._project(clipped), colour)
        items: list[tuple[float, Ball | MarkerPlate]] = []
        sc = self.scenario
        visible = sc.target_visible(t)
        balls = list(sc.distractors) + ([sc.target] if visible else [])
        for ball in balls:
            c = self._to_camera(pose, np.array([ball.position]))[0]
            if c[2] > NEAR + ball.radius:
                items.append((float(c[2]), ball))
        if sc.marker is not None and visible:
            c = self._to_camera(pose, np.array([sc.marker.centre]))[0]
            if c[2] > NEAR + sc.marker.side:
                items.append((float(c[2]), sc.marker))
        items.sort(key=lambda item: -item[0])
        # poles first: the marker plate hangs on the target's pole and must cover it at any tilt
        for _, item in items:
            if isinstance(item, Ball):
                self._draw_pole(img, pose, item)
        for _, item in items:
            if isinstance(item, Ball):
                self._draw_ball(img, pose, item)
            else:
                self._draw_plate(img, pose, item)
        out: Image = img
        gain = sc.light_gain * (1.0 + sc.light_wobble * math.sin(2.0 * math.pi * t / 7.0))
        if abs(gain - 1.0) > 1e-3:
            out = np.asarray(cv2.convertScaleAbs(img, alpha=gain, beta=0.0), dtype=np.uint8)
        if self._noise:
            pos, neg = self._noise[self._count % len(self._noise)]
            out = np.asarray(cv2.subtract(cv2.add(out, pos), neg), dtype=np.uint8)
        self._count += 1
        return out

    def _draw_pole(self, img: Image, pose: CameraPose, ball: Ball) -> None:
        x, y, z = ball.position
        pole = self._to_camera(pose, np.array([[x, y, z - ball.radius], [x, y, 0.0]]))
        clipped = self._clip_near(np.vstack([pole, pole[::-1]]))
        if len(clipped) >= 2:
            uv = self._project(clipped)
            depth = max(float(pole[:, 2].min()), NEAR)
            thick = max(1, int(self._focal * 0.03 / depth))
            p0 = np.round(uv[0] * ONE).astype(np.int32)
            p1 = np.round(uv[len(uv) // 2] * ONE).astype(np.int32)
            cv2.line(img, (int(p0[0]), int(p0[1])), (int(p1[0]), int(p1[1])), POLE, thick, cv2.LINE_8, SHIFT)

    def _draw_ball(self, img: Image, pose: CameraPose, ball: Ball) -> None:
        c = self._to_camera(pose, np.array([ball.position]))[0]
        uv = self._project(c)
        radius = self._focal * ball.radius / c[2]
        cv2.circle(
            img,
            (round(uv[0] * ONE), round(uv[1] * ONE)),
            round(radius * ONE),
            ball.colour,
            -1,
            cv2.LINE_AA,
            SHIFT,
        )

    def _draw_plate(self, img: Image, pose: CameraPose, plate: MarkerPlate) -> None:
        assert self._bits is not None
        f = plate.facing
        right = np.array([-math.sin(f), math.cos(f), 0.0])
        up = np.array([0.0, 0.0, 1.0])
        centre = np.asarray(plate.centre)
        normal = np.array([math.cos(f), math.sin(f), 0.0])
        if float(normal @ (np.asarray(pose.position) - centre)) <= 0:
            return  # seen from behind: a plain plate edge, not drawn
        n = self._bits.shape[0]
        half = plate.side / 2.0
        border = plate.side * 0.25
        white = np.array(
            [
                centre + sx * (half + border) * right + sy * (half + border) * up
                for sx, sy in ((-1, 1), (1, 1), (1, -1), (-1, -1))
            ]
        )
        cam_white = self._to_camera(pose, white)
        if (cam_white[:, 2] <= NEAR).any():
            return
        self._fill(img, self._project(cam_white), (235, 235, 235))
        cell = plate.side / n
        js, is_ = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
        grid = (
            centre
            + ((-half + js * cell)[..., None]) * right
            + ((half - is_ * cell)[..., None]) * up
        )
        uv = self._project(self._to_camera(pose, grid.reshape(-1, 3))).reshape(n + 1, n + 1, 2)
        i, j = self._black
        quads = np.stack([uv[i, j], uv[i, j + 1], uv[i + 1, j + 1], uv[i + 1, j]], axis=1)  # (cells, 4, 2)
        pts = np.round(quads * ONE).astype(np.int32)
        cv2.fillPoly(img, list(pts), (20, 20, 20), cv2.LINE_8, SHIFT)
