"""``--camera picam``: the Raspberry Pi camera through libcamera's ``picamera2`` (the supported API on
Raspberry Pi OS Bookworm, where a CSI camera is not a V4L2 device OpenCV can open).

``picamera2`` is imported only when this source is asked for: it is not on PyPI's wheels for most machines
and the rest of the pilot does not need it. On Raspberry Pi OS: ``sudo apt install python3-picamera2``,
then make the venv with ``python3 -m venv --system-site-packages`` so that it sees the system package.
"""

from __future__ import annotations

import contextlib
import importlib
import time
from collections.abc import Callable
from types import ModuleType
from typing import Any

from ..common.errors import FrameSourceError, PilotError
from .sources import Frame, FrameSourceBase

APT_LINE = "sudo apt install python3-picamera2"


def import_picamera2() -> ModuleType:
    try:
        return importlib.import_module("picamera2")
    except ImportError as exc:
        raise PilotError(
            f"option --camera picam: the picamera2 library is missing: on Raspberry Pi OS run `{APT_LINE}` "
            "and create the venv with --system-site-packages (or pick a V4L2 camera: --camera 0)"
        ) from exc


class PicameraSource(FrameSourceBase):
    """Frames from ``Picamera2.capture_array()`` of a video configuration. Its ``RGB888`` format is,
    in libcamera's naming, blue-green-red in memory: OpenCV's BGR, used as is."""

    def __init__(
        self,
        width: int = 640,
        height: int = 480,
        max_failures: int = 5,
        time_fn: Callable[[], float] = time.monotonic,
        module: ModuleType | None = None,
    ) -> None:
        super().__init__(time_fn)
        picamera2 = module if module is not None else import_picamera2()
        self._max_failures = max_failures
        self._cam: Any = None
        try:
            self._cam = picamera2.Picamera2()
            config = self._cam.create_video_configuration(main={"size": (width, height), "format": "RGB888"})
            self._cam.configure(config)
            self._cam.start()
        except Exception as exc:  # no camera (IndexError), busy (RuntimeError), ...: one message
            self._release()
            raise FrameSourceError(
                f"option --camera picam: cannot start the Pi camera ({type(exc).__name__}: {exc}); "
                "is it connected and enabled, and not used by another program?"
            ) from exc

    def read(self) -> Frame | None:
        if self._closed:
            raise FrameSourceError("Pi camera: read after close")
        problem = ""
        for _ in range(self._max_failures):
            try:
                image = self._cam.capture_array()
            except Exception as exc:  # the library's errors are not one class
                problem = f": {type(exc).__name__}: {exc}"
                continue
            if image is not None and getattr(image, "ndim", 0) == 3:
                return self._frame(image)
        raise FrameSourceError(f"Pi camera: lost ({self._max_failures} failed captures in a row{problem})")

    def _release(self) -> None:
        cam, self._cam = self._cam, None
        if cam is None:
            return
        for step in (cam.stop, cam.close):
            with contextlib.suppress(Exception):  # closing must go on: the camera may never have started
                step()

    def close(self) -> None:
        if not self._closed:
            self._release()
        super().close()
