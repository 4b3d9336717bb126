"""Frame sources behind one interface: camera, video file, image folder (the simulated camera is in pilot.sim).

A source is a context manager; ``read()`` returns the newest ``Frame`` or ``None`` when a finite
source (video, folder) is exhausted, and raises ``FrameSourceError`` when a camera is lost.
``close()`` is safe to call twice.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Protocol

import cv2
from cv2.typing import MatLike

from ..common.closing import Closing
from ..common.errors import FrameSourceError

if TYPE_CHECKING:
    from typing_extensions import Self

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff")


@dataclass(frozen=True)
class Frame:
    image: MatLike  # BGR, uint8
    t: float  # arrival time (the source's clock), seconds
    index: int


class FrameSource(Protocol):
    def read(self) -> Frame | None: ...

    def close(self) -> None: ...

    def __enter__(self) -> Self: ...

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None: ...


class FrameSourceBase(Closing):
    """Frame numbering and the closed flag of every source."""

    def __init__(self, time_fn: Callable[[], float]) -> None:
        self._time_fn = time_fn
        self._index = 0
        self._closed = False

    def _frame(self, image: MatLike) -> Frame:
        frame = Frame(image=image, t=self._time_fn(), index=self._index)
        self._index += 1
        return frame

    def close(self) -> None:
        self._closed = True


class CameraSource(FrameSourceBase):
    """A V4L2/OpenCV camera (index or device path) with a one-frame buffer, so that decisions use
    the newest image rather than one up to ~130 ms old. ``max_failures`` consecutive failed reads
    mean the camera is lost."""

    def __init__(
        self,
        device: int | str,
        width: int = 640,
        height: int = 480,
        max_failures: int = 5,
        time_fn: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(time_fn)
        self.device = device
        self._cap = cv2.VideoCapture(device)
        if not self._cap.isOpened():
            raise FrameSourceError(f"camera {device!r}: cannot open")
        self._cap.set(cv2.CAP_PROP_BUFFERSIZE, 1)
        self._cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
        self._cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
        self._max_failures = max_failures

    def read(self) -> Frame | None:
        if self._closed:
            raise FrameSourceError(f"camera {self.device!r}: read after close")
        for _ in range(self._max_failures):
            ok, image = self._cap.read()
            if ok and image is not None:
                return self._frame(image)
        raise FrameSourceError(f"camera {self.device!r}: lost ({self._max_failures} failed reads in a row)")

    def close(self) -> None:
        if not self._closed:
            self._cap.release()
        super().close()


class VideoFileSource(FrameSourceBase):
    """Frames of a video file, in order; ``None`` at the end."""

    def __init__(self, path: str | Path, time_fn: Callable[[], float] = time.monotonic) -> None:
        super().__init__(time_fn)
        self.path = Path(path)
        if not self.path.is_file():
            raise FrameSourceError(f"video {str(self.path)!r}: no such file")
        self._cap = cv2.VideoCapture(str(self.path))
        if not self._cap.isOpened():
            raise FrameSourceError(f"video {str(self.path)!r}: cannot open")

    def read(self) -> Frame | None:
        if self._closed:
            return None
        ok, image = self._cap.read()
        if not ok or image is None:
            return None
        return self._frame(image)

    def close(self) -> None:
        if not self._closed:
            self._cap.release()
        super().close()


class ImageFolderSource(FrameSourceBase):
    """The images of a folder in name order; ``None`` after the last."""

    def __init__(self, folder: str | Path, time_fn: Callable[[], float] = time.monotonic) -> None:
        super().__init__(time_fn)
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise FrameSourceError(f"image folder {str(self.folder)!r}: not a directory")
        self._paths = sorted(p for p in self.folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not self._paths:
            raise FrameSourceError(f"image folder {str(self.folder)!r}: holds no images ({', '.join(IMAGE_SUFFIXES)})")
        self._next = 0
        self._check_sizes()

    def _check_sizes(self) -> None:
        """One size for every image, checked before the first frame: a recording and the detector's
        geometry need it, and a failure halfway through a run would leave half a recording."""
        first: tuple[str, tuple[int, ...]] | None = None
        for path in self._paths:
            image = cv2.imread(str(path), cv2.IMREAD_COLOR)
            if image is None:
                raise FrameSourceError(f"option --images: cannot decode {str(path)!r}: remove it or fix it")
            if first is None:
                first = (path.name, image.shape[:2])
            elif image.shape[:2] != first[1]:
                h, w = image.shape[:2]
                raise FrameSourceError(
                    f"option --images: {path.name!r} is {w}x{h} but {first[0]!r} is {first[1][1]}x{first[1][0]}: "
                    "every image of the folder must have one size"
                )

    def read(self) -> Frame | None:
        if self._closed or self._next >= len(self._paths):
            return None
        path = self._paths[self._next]
        self._next += 1
        image = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if image is None:
            raise FrameSourceError(f"image {str(path)!r}: cannot decode")
        return self._frame(image)
