"""The randomised world's camera (pilot/sim/camera.py, scene.py): shadows, auto-exposure and auto white balance
that lag a change of scene, and the two camera profiles (the Pi camera's uncompressed rolling-shutter frames, a
USB webcam's MJPEG)."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

from pilot.sim.camera import CameraModel, Image
from pilot.sim.randomise import Effects
from pilot.sim.room import make_scenario
from pilot.sim.scenario import Prop
from pilot.sim.still import StillView


def _view(effects: Effects, name: str = "ahead", seed: int = 2) -> StillView:
    sc = dataclasses.replace(make_scenario(name, seed, ideal=True), effects=effects)
    return StillView(sc, CameraModel(160, 120))


def _means(img: Image) -> tuple[float, float, float]:
    b, g, r = cv2.mean(img)[:3]
    return b, g, r


def _raw(view: StillView) -> Image:
    """MuJoCo's render alone (before the sensor's exposure, which would take some of a shadow back out)."""
    view.sensor.renderer.update_scene(view.data, camera=view.sensor.cam_id)
    return np.asarray(view.sensor.renderer.render(), dtype=np.uint8)


def test_the_lights_cast_shadows_in_the_randomised_world() -> None:
    shots = []
    for effects in (Effects(), Effects(shadows=1.0)):
        sc = make_scenario("ahead", 2, ideal=True)
        lx, ly, _ = max(sc.lights, key=lambda lt: sum(lt.rgb)).position  # the light that casts shadows
        cube = Prop("box", (lx + 0.8, ly, 0.4), (0.4, 0.4, 0.4), (0.6, 0.6, 0.6))  # a cabinet beside it
        view = StillView(dataclasses.replace(sc, props=(cube,), effects=effects), CameraModel(160, 120))
        view.place(lx - 1.5, ly, 1.5, 0.0, tilt=60.0)  # looking down at it and the floor behind it
        shots.append(_raw(view).astype(np.int16))
        view.close()
    darker = shots[0] - shots[1]
    assert darker.max() > 20  # some of the floor lies in its shadow ...
    assert darker.min() >= -2  # ... and nothing got lighter


def test_auto_exposure_lags_a_change_of_light_by_its_time_constant() -> None:
    view = _view(Effects(ae_tau_s=0.4))
    try:
        before = sum(_means(view.render(0.0)))
        view.model.light_diffuse[:] *= 1.8  # the room's lights brighten
        view.model.vis.headlight.ambient[:] *= 1.8
        t, first = 0.05, sum(_means(view.render(0.05)))
        while t < 1.2:  # three time constants
            t += 0.05
            last = sum(_means(view.render(t)))
    finally:
        view.close()
    assert first > 1.4 * before  # the frame right after the change is bright ...
    assert last == pytest.approx(before, rel=0.15)  # ... and the exposure has caught up three time constants on


def test_auto_white_balance_lags_a_change_of_colour_by_its_time_constant() -> None:
    view = _view(Effects(ae_tau_s=0.3, awb_tau_s=0.8))
    try:
        b0, _, r0 = _means(view.render(0.0))
        warm = np.array([1.4, 1.0, 0.6])  # more red, less blue
        view.model.light_diffuse[:] *= warm
        view.model.vis.headlight.ambient[:] *= warm
        b1, _, r1 = _means(view.render(0.05))
        t = 0.05
        while t < 2.4:
            t += 0.05
            b2, _, r2 = _means(view.render(t))
    finally:
        view.close()
    assert r1 / b1 > 1.3 * (r0 / b0)  # at first the frame turns warm ...
    assert r2 / b2 == pytest.approx(r0 / b0, rel=0.12)  # ... then the balance takes it out


def test_the_pi_camera_sends_uncompressed_frames_a_webcam_mjpeg() -> None:
    sc = make_scenario("ahead", 2, ideal=True)
    picam, usb = _view(Effects(picam=1.0)), _view(Effects(picam=0.0))
    try:
        a, b = picam.render(), usb.render()
    finally:
        picam.close()
        usb.close()
    ok, data = cv2.imencode(".jpg", a, [cv2.IMWRITE_JPEG_QUALITY, sc.jpeg_quality])
    assert ok and np.array_equal(np.asarray(cv2.imdecode(data, cv2.IMREAD_COLOR)), b)
    assert not np.array_equal(a, b)


def test_the_pi_camera_profile_reads_its_rows_over_its_readout_time() -> None:
    view = _view(Effects(picam=1.0, readout_s=0.025))
    try:
        assert view.sensor.readout_s == 0.025
    finally:
        view.close()


def test_the_scene_is_drawn_once_when_the_camera_is_built() -> None:
    """Mesa compiles its shaders at their first draw: that belongs to building the world, not to the first frame
    (whose cost the speed probe counts)."""
    view = StillView(make_scenario("ahead", 2), CameraModel(160, 120))
    try:
        assert view.sensor.renderer.scene.ngeom > 0
    finally:
        view.close()
