"""Learning the room (pilot/vision/calibrate_room.py, colour_model.py): a red ball against a room of pale red
things is learnt and kept apart from them; a room of the ball's own colour, frames of another size, and a model
file that is corrupt, truncated or of another version are refused in one line naming the figure or the file."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from cli_rig import call

import pilot.vision.colour_model as cm
from pilot.common.config import HsvConfig, PilotConfig, load
from pilot.common.errors import ConfigError
from pilot.vision.calibrate_room import learn_room, read_frames
from pilot.vision.detect import make_detector
from pilot.vision.hsv.detector import HsvBlobDetector

BALL = (20, 10, 210)  # BGR: red, hue 178
PALE = (70, 60, 235)  # BGR: a paler red (hue 177, saturation 190): in the ranges, not the ball's colour


def room(seed: int, orange: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    img = np.clip(rng.normal(120, 12, (240, 320, 3)), 0, 255).astype(np.uint8)
    if orange:
        for _ in range(3):  # pale red cushions
            x, y = int(rng.integers(10, 250)), int(rng.integers(10, 180))
            cv2.rectangle(img, (x, y), (x + 50, y + 30), PALE, -1)
    return img


def with_ball(img: np.ndarray, cx: int = 160, cy: int = 120, r: int = 18) -> np.ndarray:
    out = img.copy()
    cv2.circle(out, (cx, cy), r + 6, (120, 120, 120), -1)
    cv2.circle(out, (cx, cy), r, BALL, -1)
    cv2.circle(out, (cx - r // 3, cy - r // 3), r // 3, (60, 50, 240), -1)  # its lit side
    return out


def frames(folder: Path, name: str, images: list[np.ndarray]) -> list[str]:
    paths = []
    for i, img in enumerate(images):
        p = folder / f"{name}{i}.png"
        cv2.imwrite(str(p), img)
        paths.append(str(p))
    return paths


def test_the_learnt_room_keeps_the_ball_and_drops_its_own_colours(tmp_path: Path) -> None:
    ball = frames(tmp_path, "ball", [with_ball(room(s), 160 + 4 * s, 120 - 3 * s) for s in range(4)])
    empty = frames(tmp_path, "room", [room(10 + s) for s in range(4)])
    report = learn_room(ball, empty, tmp_path / "pilot.yaml", None, (320, 240))
    assert report.room_detections == 0.0 and report.ball_found == 1.0 and report.model_path.exists()
    cfg = load(tmp_path / "pilot.yaml")
    assert cfg.hsv.colour_model == str(report.model_path.resolve())
    lamp = room(30)
    cv2.circle(lamp, (200, 150), 22, PALE, -1)  # a pale red round thing in a new view of the room
    plain = HsvBlobDetector(dataclasses.replace(cfg.hsv, colour_model=""))
    learnt = HsvBlobDetector(cfg.hsv)
    assert any(c.score >= 0.6 for c in plain.candidates(lamp))  # the ranges alone take it
    assert not any(c.score >= 0.6 for c in learnt.candidates(lamp))  # the room's model does not
    found = learnt.candidates(with_ball(room(31), 100, 150))
    assert found and found[0].score >= 0.6 and abs(found[0].cx - 100) < 3 and abs(found[0].cy - 150) < 3


def test_a_room_of_the_balls_own_colour_is_refused_with_the_figure(tmp_path: Path) -> None:
    red_room = []
    for s in range(4):
        img = room(s, orange=False)
        img[:, : 160 + 20 * s] = BALL  # a red wall over most of the view
        red_room.append(img)
    ball = frames(tmp_path, "ball", [with_ball(img) for img in red_room[:2]])
    code, _out, err = call("--calibrate", *ball, "--room", *frames(tmp_path, "room", red_room),
                          "--config", str(tmp_path / "pilot.yaml"))
    assert code == 2 and "calibration refused" in err and "%" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "pilot.yaml").exists() and not (tmp_path / "pilot.colour.npz").exists()


def test_frames_of_another_size_than_the_cameras_are_refused(tmp_path: Path) -> None:
    ball = frames(tmp_path, "ball", [with_ball(room(0))])
    small = frames(tmp_path, "room", [cv2.resize(room(1), (160, 120))])
    code, _, err = call("--calibrate", *ball, "--room", *small, "--config", str(tmp_path / "pilot.yaml"))
    assert code == 2 and "160x120" in err and "320x240" in err and "Traceback" not in err
    code, _, err = call("--calibrate", *ball, "--room", *small, "--size", "160x120",
                        "--config", str(tmp_path / "pilot.yaml"))
    assert code == 2 and "ball0.png" in err and "320x240" in err


def test_one_sample_image_still_calibrates_the_ranges(tmp_path: Path) -> None:
    sample = frames(tmp_path, "ball", [with_ball(room(0, orange=False))])
    code, _, err = call("--calibrate", *sample, "--config", str(tmp_path / "pilot.yaml"))
    assert code == 0, err
    assert yaml.safe_load((tmp_path / "pilot.yaml").read_text())["hsv"]["ranges"]
    code, _, err = call("--calibrate", *sample, *sample, "--config", str(tmp_path / "pilot.yaml"))
    assert code == 2 and "--room" in err


def _model(path: Path) -> None:
    cm.save(cm.ColourModel(np.full((cm.H_BINS, cm.S_BINS), 200.0, np.float32), 100.0, 320, 240), path)


@pytest.mark.parametrize("damage", ["truncated", "garbage", "version", "missing", "shape"])
def test_a_bad_model_file_is_refused_at_start_naming_it(tmp_path: Path, damage: str) -> None:
    path = tmp_path / "pilot.colour.npz"
    _model(path)
    if damage == "truncated":
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "garbage":
        path.write_bytes(b"not a colour model at all")
    elif damage == "version":
        with open(path, "wb") as f:
            np.savez(f, version=np.int32(cm.VERSION + 1), ratio=np.zeros((cm.H_BINS, cm.S_BINS), np.float32),
                     threshold=np.float32(100), size=np.array([320, 240], np.int32))
    elif damage == "missing":
        path.unlink()
    else:
        with open(path, "wb") as f:
            np.savez(f, version=np.int32(cm.VERSION), ratio=np.zeros((3, 3), np.float32),
                     threshold=np.float32(100), size=np.array([320, 240], np.int32))
    cfg = PilotConfig(hsv=HsvConfig(colour_model=str(path)))
    with pytest.raises(ConfigError, match="colour model") as info:
        make_detector(cfg)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_a_good_model_file_loads_and_mirrors_for_red(tmp_path: Path) -> None:
    path = tmp_path / "m.npz"
    _model(path)
    model = cm.load(path)
    assert model.threshold == 100.0 and (model.width, model.height) == (320, 240)
    det = HsvBlobDetector(HsvConfig(colour_model=str(path)))  # the default red: its hue circle mirrored
    assert det.colour.model is not None and det.colour.code == cv2.COLOR_RGB2HSV


def test_a_short_video_of_the_ball_is_read_frame_by_frame(tmp_path: Path) -> None:
    video = tmp_path / "ball.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter.fourcc(*"MJPG"), 10.0, (320, 240))
    for s in range(8):
        writer.write(with_ball(room(s), 150 + 3 * s, 120))
    writer.release()
    report = learn_room([str(video)], frames(tmp_path, "room", [room(20 + s) for s in range(3)]),
                        tmp_path / "pilot.yaml", None, (320, 240))
    assert report.ball_found == 1.0 and report.room_detections == 0.0
    assert len(read_frames(video, (320, 240))) == 4  # every other frame of the eight
    with pytest.raises(ConfigError, match=r"ball\.avi.*320x240"):
        read_frames(video, (640, 480))


def test_the_pilot_refuses_to_start_on_a_corrupt_model_in_one_line(tmp_path: Path) -> None:
    model = tmp_path / "pilot.colour.npz"
    model.write_bytes(b"garbage")
    (tmp_path / "pilot.yaml").write_text(f"hsv:\n  colour_model: {model}\n")
    folder = tmp_path / "frames"
    folder.mkdir()
    frames(folder, "f", [room(s) for s in range(2)])
    code, out, err = call("--config", str(tmp_path / "pilot.yaml"), "--images", str(folder), "--dry-run",
                          "--no-status")
    assert code == 2 and str(model) in err and len(err.strip().splitlines()) == 1 and "dry-run" not in out
