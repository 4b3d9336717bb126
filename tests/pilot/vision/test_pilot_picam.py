"""``--camera picam`` against a fake ``picamera2`` module with the API surface the source uses."""

from __future__ import annotations

import sys
import types
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest
from cli_rig import call

from pilot.common.errors import FrameSourceError
from pilot.vision.picam import APT_LINE, PicameraSource


class FakePicamera2:
    """The calls of picamera2.Picamera2 the source makes, with their real signatures, recorded."""

    instances: ClassVar[list[FakePicamera2]] = []
    fail_open: ClassVar[BaseException | None] = None
    fail_start: ClassVar[BaseException | None] = None

    def __init__(self, camera_num: int = 0) -> None:
        if FakePicamera2.fail_open is not None:
            raise FakePicamera2.fail_open
        self.calls: list[str] = []
        self.config: dict[str, Any] | None = None
        self.started = False
        self.frames = 0
        self.fail_captures = 0
        FakePicamera2.instances.append(self)

    def create_video_configuration(self, main: dict[str, Any] | None = None, **kwargs: Any) -> dict[str, Any]:
        self.calls.append("create_video_configuration")
        return {"use_case": "video", "main": dict(main or {}), **kwargs}

    def create_preview_configuration(self, main: dict[str, Any] | None = None, **kwargs: Any) -> dict[str, Any]:
        self.calls.append("create_preview_configuration")
        return {"use_case": "preview", "main": dict(main or {}), **kwargs}

    def configure(self, camera_config: dict[str, Any]) -> None:
        self.calls.append("configure")
        self.config = camera_config

    def start(self, config: dict[str, Any] | None = None, show_preview: bool = False) -> None:
        self.calls.append("start")
        if FakePicamera2.fail_start is not None:
            raise FakePicamera2.fail_start
        self.started = True

    def capture_array(self, name: str = "main") -> np.ndarray:
        assert self.started and self.config is not None, "capture before configure/start"
        if self.fail_captures:
            self.fail_captures -= 1
            raise RuntimeError("camera frontend has timed out")
        w, h = self.config["main"]["size"]
        self.frames += 1
        img = np.zeros((h, w, 3), np.uint8)
        img[..., 0] = self.frames  # blue: the first byte in memory of libcamera's RGB888
        return img

    def stop(self) -> None:
        self.calls.append("stop")
        self.started = False

    def close(self) -> None:
        self.calls.append("close")


@pytest.fixture
def fake_picamera2(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    module = types.ModuleType("picamera2")
    module.Picamera2 = FakePicamera2  # type: ignore[attr-defined]
    FakePicamera2.instances = []
    FakePicamera2.fail_open = None
    FakePicamera2.fail_start = None
    monkeypatch.setitem(sys.modules, "picamera2", module)
    return module


def test_frames_come_from_a_configured_started_camera_and_it_is_released(fake_picamera2: types.ModuleType) -> None:
    with PicameraSource(320, 240) as source:
        first, second = source.read(), source.read()
    (cam,) = FakePicamera2.instances
    assert first is not None and second is not None
    assert first.image.shape == (240, 320, 3) and (first.index, second.index) == (0, 1)
    assert int(second.image[0, 0, 0]) == 2  # the newest capture, used as BGR without conversion
    assert cam.config == {"use_case": "video", "main": {"size": (320, 240), "format": "RGB888"}}
    assert cam.calls == ["create_video_configuration", "configure", "start", "stop", "close"]


def test_a_few_failed_captures_are_retried_then_the_camera_is_lost(fake_picamera2: types.ModuleType) -> None:
    with PicameraSource(160, 120, max_failures=3) as source:
        cam = FakePicamera2.instances[0]
        cam.fail_captures = 2
        assert source.read() is not None
        cam.fail_captures = 3
        with pytest.raises(FrameSourceError, match=r"lost .*timed out"):
            source.read()


def test_a_missing_or_busy_camera_is_one_clear_error_and_is_released(fake_picamera2: types.ModuleType) -> None:
    FakePicamera2.fail_open = IndexError("list index out of range")  # what Picamera2() raises with no camera
    with pytest.raises(FrameSourceError, match="--camera picam: cannot start the Pi camera"):
        PicameraSource()
    FakePicamera2.fail_open = None
    FakePicamera2.fail_start = RuntimeError("Device or resource busy")
    with pytest.raises(FrameSourceError, match="resource busy"):
        PicameraSource()
    (cam,) = FakePicamera2.instances
    assert cam.calls[-2:] == ["stop", "close"]


def test_cli_without_picamera2_prints_the_apt_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "picamera2", None)  # None in sys.modules: the import fails
    code, out, err = call("--camera", "picam", "--dry-run", "--no-status")
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, out + err
    assert "--camera picam" in err and APT_LINE in err


def test_cli_flies_a_dry_run_from_the_fake_pi_camera(fake_picamera2: types.ModuleType) -> None:
    code, out, err = call("--camera", "picam", "--dry-run", "--no-status", "--max-seconds", "0.3")
    assert code in (0, 1) and "dry-run " in out, out + err
    (cam,) = FakePicamera2.instances
    assert cam.frames >= 2 and cam.calls[-2:] == ["stop", "close"]
