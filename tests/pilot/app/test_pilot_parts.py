"""Config, calibration and frame sources (the simulator: test_pilot_sim.py)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import drone_protocol as dp
import numpy as np
import pilot_synth as synth
import pytest
import yaml

from pilot.common import config as config_mod
from pilot.common.config import HsvConfig, PilotConfig
from pilot.common.errors import ConfigError, FrameSourceError
from pilot.vision.calibrate import calibrate_to_config, hsv_ranges_from_sample
from pilot.vision.detect import HsvBlobDetector
from pilot.vision.sources import CameraSource, ImageFolderSource, VideoFileSource

PAN0, TILT0 = dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default

# -- config --------------------------------------------------------------------------------------------


def test_config_round_trip(tmp_path: Path) -> None:
    cfg = dataclasses.replace(
        PilotConfig(), detector="aruco", controller=dataclasses.replace(PilotConfig().controller, fire_ms=900)
    )
    path = tmp_path / "pilot.yaml"
    config_mod.save(cfg, path)
    assert config_mod.load(path) == cfg


@pytest.mark.parametrize(
    "text,needle",
    [
        ("controller:\n  fire_msec: 10\n", "unknown option 'controller.fire_msec'"),
        ("controller:\n  fire_ms: soon\n", "option 'controller.fire_ms' must be an integer"),
        ("detector: sonar\n", "option 'detector' must be one of"),
        ("hsv:\n  ranges: [[[0, 0, 0], [200, 255, 255]]]\n", "option 'hsv.ranges[0]'"),
        ("hsv:\n  ranges: [[[0, 0], [10, 255, 255]]]\n", "option 'hsv.ranges[0][0]' must have 3 items"),
        # an inverted range matched nothing, and an inverted hue range raised a ValueError building the detector
        ("hsv:\n  ranges: [[[174, 120, 70], [6, 255, 255]]]\n", "option 'hsv.ranges[0]' low (174, 120, 70) is above "
         "high (6, 255, 255) in H (a hue range across 179 is two ranges"),
        ("hsv:\n  ranges: [[[0, 200, 70], [6, 120, 255]]]\n", "option 'hsv.ranges[0]' low (0, 200, 70) is above high"),
        ("controller:\n  retreat_size: 0.5\n", "option 'controller.retreat_size'"),
        ("controller:\n  back_off_size: 0.1\n", "option 'controller.back_off_size'"),
        ("link: 5\n", "option 'link' must be a mapping"),
        ("- a\n- b\n", "the top level must be a mapping"),
    ],
)
def test_config_errors_name_the_option_and_the_file(tmp_path: Path, text: str, needle: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        config_mod.load(path)
    assert needle in str(info.value)
    assert str(path) in str(info.value)


def test_missing_config_file_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read config"):
        config_mod.load(tmp_path / "nope.yaml")


# -- calibration ----------------------------------------------------------------------------------------


def test_calibration_of_red_gives_two_ranges_that_find_the_target(tmp_path: Path) -> None:
    bg = synth.background(320, 240)
    img = bg.copy()
    cv2.circle(img, (160, 120), 40, (40, 20, 200), -1)  # a red whose pixels straddle hue 0 with noise
    img = synth.degrade(img, 1.0, 6.0, seed=1)
    ranges = hsv_ranges_from_sample(img)
    assert len(ranges) == 2
    assert ranges[0][0][0] == 0 and ranges[1][1][0] == 179
    det = HsvBlobDetector(HsvConfig(ranges=ranges))
    moved = bg.copy()
    cv2.circle(moved, (80, 60), 20, (40, 20, 200), -1)  # the calibrated red, elsewhere
    d = det.detect(moved)
    assert d.found and abs(d.cx - 80) <= 1.5 and abs(d.cy - 60) <= 1.5
    assert not det.detect(synth.background(320, 240)).found


def test_calibration_of_blue_gives_one_range_and_is_saved(tmp_path: Path) -> None:
    img = synth.background(320, 240)
    cv2.circle(img, (100, 100), 30, (200, 80, 30), -1)
    image_path = tmp_path / "blue.png"
    cv2.imwrite(str(image_path), img)
    cfg_path = tmp_path / "pilot.yaml"
    cfg_path.write_text(yaml.safe_dump({"controller": {"fire_ms": 700}}))
    cfg = calibrate_to_config(image_path, cfg_path, roi=(85, 85, 30, 30))
    assert len(cfg.hsv.ranges) == 1
    (lo, hi) = cfg.hsv.ranges[0]
    hue = int(cv2.cvtColor(np.array([[[200, 80, 30]]], np.uint8), cv2.COLOR_BGR2HSV)[0, 0, 0])
    assert lo[0] <= hue <= hi[0]
    reloaded = config_mod.load(cfg_path)
    assert reloaded.hsv.ranges == cfg.hsv.ranges
    assert reloaded.controller.fire_ms == 700  # the rest of the file is kept
    assert HsvBlobDetector(reloaded.hsv).detect(img).found
    assert (tmp_path / "pilot.calibration.png").exists()  # the mask preview, next to the config


def test_calibration_takes_the_hue_mode_not_the_background_in_the_roi(tmp_path: Path) -> None:
    """A ROI half filled by an orange background still gives a range around the target's red."""
    img = synth.background(320, 240)
    cv2.rectangle(img, (160, 0), (320, 240), (0, 140, 255), -1)  # orange wall on the right half
    cv2.circle(img, (150, 120), 28, (30, 30, 210), -1)
    (lo, hi), *rest = hsv_ranges_from_sample(img, roi=(120, 90, 70, 60))
    hues = {h for r in [(lo, hi), *rest] for h in range(r[0][0], r[1][0] + 1)}
    assert 0 in hues and not hues & set(range(10, 20))  # red in, orange (hue ~16) out


def test_calibration_refuses_ranges_that_match_the_room(tmp_path: Path) -> None:
    img = synth.background(320, 240)
    cv2.rectangle(img, (0, 0), (320, 120), (30, 30, 200), -1)  # a red wall behind a red target
    cv2.circle(img, (160, 150), 30, (30, 30, 210), -1)
    image_path = tmp_path / "red_wall.png"
    cv2.imwrite(str(image_path), img)
    cfg_path = tmp_path / "pilot.yaml"
    with pytest.raises(ConfigError, match=r"calibration refused: .* of the picture outside the roi"):
        calibrate_to_config(image_path, cfg_path, roi=(140, 130, 40, 40))
    assert not cfg_path.exists()  # nothing saved
    assert (tmp_path / "pilot.calibration.png").exists()  # but the preview shows why


def test_calibration_roi_outside_the_image() -> None:
    with pytest.raises(ConfigError, match="not inside"):
        hsv_ranges_from_sample(synth.background(320, 240), roi=(300, 200, 50, 50))


@pytest.mark.parametrize("sample", [np.full((240, 320), 128, np.uint8), np.zeros((240, 320, 4), np.uint8),
                                    np.zeros((240, 320, 3), np.float32), None])
def test_calibration_names_a_sample_that_is_no_colour_image(sample: object) -> None:
    """Grey, BGRA, float or no image: named as such, not an OpenCV error or "0 pixels are coloured"."""
    with pytest.raises(ConfigError, match="8-bit, 3-channel"):
        hsv_ranges_from_sample(sample)  # type: ignore[arg-type]


# -- frame sources -------------------------------------------------------------------------------------


def write_video(path: Path, n: int) -> None:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 20.0, (160, 120))
    for i in range(n):
        img = np.full((120, 160, 3), 100, np.uint8)
        cv2.circle(img, (20 + 5 * i, 60), 10, synth.RED, -1)
        writer.write(img)
    writer.release()


def test_video_source_in_order_then_none(tmp_path: Path) -> None:
    path = tmp_path / "v.avi"
    write_video(path, 10)
    det = HsvBlobDetector()
    xs = []
    with VideoFileSource(path, time_fn=lambda: 1.5) as src:
        while (frame := src.read()) is not None:
            assert frame.t == 1.5
            xs.append(det.detect(frame.image).cx)
        assert src.read() is None
    assert len(xs) == 10
    assert all(abs(x - (20 + 5 * i)) <= 2 for i, x in enumerate(xs))


def test_image_folder_source_sorted(tmp_path: Path) -> None:
    for i in (3, 1, 2):
        img = np.full((60, 80, 3), 100, np.uint8)
        cv2.circle(img, (10 * i, 30), 6, synth.RED, -1)
        cv2.imwrite(str(tmp_path / f"frame{i}.png"), img)
    (tmp_path / "notes.txt").write_text("not an image")
    with ImageFolderSource(tmp_path) as src:
        frames = [src.read() for _ in range(4)]
    assert frames[3] is None
    got = [HsvBlobDetector(HsvConfig(min_area=10)).detect(f.image).cx for f in frames[:3] if f is not None]
    assert [round(x) for x in got] == [10, 20, 30]
    assert [f.index for f in frames[:3] if f is not None] == [0, 1, 2]


def test_source_errors(tmp_path: Path) -> None:
    with pytest.raises(FrameSourceError, match="no such file"):
        VideoFileSource(tmp_path / "missing.avi")
    with pytest.raises(FrameSourceError, match="not a directory"):
        ImageFolderSource(tmp_path / "missing")
    with pytest.raises(FrameSourceError, match="holds no images"):
        ImageFolderSource(tmp_path)
    with pytest.raises(FrameSourceError, match="cannot open"):
        CameraSource(str(tmp_path / "no-such-camera"))


def test_camera_source_reports_a_lost_camera(tmp_path: Path) -> None:
    """A capture that stops delivering frames (here: a short recording opened as the camera device)."""
    path = tmp_path / "cam.avi"
    write_video(path, 3)
    src = CameraSource(str(path), max_failures=3)
    got = [src.read() for _ in range(3)]
    assert all(f is not None for f in got)
    with pytest.raises(FrameSourceError, match="lost"):
        src.read()
    src.close()
    src.close()
