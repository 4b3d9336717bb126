"""The packaged imagery of the source-separated evaluation (issue 51, item 5): photographs and video frames from
five sources that install with pip or apt, split by source, never by photo, into tuning and held-out.

The split was fixed before any figure of this evaluation was read. Tuning: scikit-image's and scikit-learn's photos,
which every rule of pilot/vision/hsv was chosen on (some of scikit-image's were once "held out" by photo, but a
source that any threshold saw is not held out). Held out: avr-libc's manual (an electronics bench indoors), Debian's
opencv-doc (OpenCV's sample photos and its three sample videos) and matplotlib's sample photo; no rule was chosen on
them. The photos of each source were picked by what they show, before the detector saw them: real photographs only
(no renderings, drawings or text scans), one of each stereo or before/after pair. Photos whose subject is a red or
orange round object (sweets, an apple, an orange) are natural distractors: their views count as distractor views,
never as empty ones, since the target is a red ball too. A video is sampled every ``VIDEO_STEP`` frames as views,
and its runs of consecutive frames feed the whole pipeline (sources_run.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.uint8]
OPENCV_DIR = Path("/usr/share/doc/opencv-doc/examples")
AVR_DIR = Path("/usr/share/doc/avr-libc/avr-libc-user-manual")
VIDEO_STEP = 10  # a video's frames used as views: every tenth
VIDEO_SIDE = 480  # a video frame's height at most, once decoded
APT_PACKAGES = ("opencv-doc", "avr-libc")  # bench/bench.mk installs them for `make bench-vision-sources`


@dataclass(frozen=True)
class Source:
    name: str
    installs: str  # how: the pip or apt package
    split: str  # "tuning" or "held-out"
    photos: tuple[str, ...]  # names load() reads: "<source>:<file>"
    videos: tuple[str, ...] = ()  # "<source>:<file>.avi"
    distractors: tuple[str, ...] = ()  # natural distractor photos (red or orange round subjects)
    shows: str = ""  # indoor rooms, skin, wood, red clothing, printed signs, ...


_SKIMAGE = ("chelsea", "coffee", "rocket", "immunohistochemistry", "colorwheel", "motorcycle_left", "brick",
            "astronaut", "retina", "logo", "hubble_deep_field", "gravel")
_OPENCV = ("alphamat/input_images/plant.jpg", "data/aero1.jpg", "data/aloeL.jpg", "data/baboon.jpg",
           "data/basketball1.png", "data/board.jpg", "data/box_in_scene.png", "data/building.jpg", "data/butterfly.jpg",
           "data/chicky_512.png", "data/ela_original.jpg", "data/graf1.png", "data/home.jpg", "data/leuvenA.jpg",
           "data/licenseplate_motion.jpg", "data/messi5.jpg", "data/rubberwhale1.png", "data/squirrel_cls.jpg",
           "data/stuff.jpg", "data/text_defocus.jpg", "hfs/data/000.jpg", "hfs/data/001.jpg", "hfs/data/002.jpg")
_OPENCV_DISTRACTORS = ("data/smarties.png", "data/apple.jpg", "data/orange.jpg", "data/fruits.jpg")

SOURCES = (
    Source("scikit-image", "pip: scikit-image", "tuning", tuple(f"scikit-image:{n}" for n in _SKIMAGE),
           shows="a cat, a kitchen's coffee cup, a red motorbike, a brick wall, a person (skin), a retina, a logo"),
    Source("scikit-learn", "pip: scikit-learn", "tuning", ("scikit-learn:china.jpg", "scikit-learn:flower.jpg"),
           shows="a temple's red columns, an orange dahlia"),
    Source("avr-libc", "apt: avr-libc", "held-out",
           tuple(f"avr-libc:{n}.jpg" for n in ("largedemo-setup", "largedemo-wiring", "largedemo-wiring2",
                                               "stdiodemo-setup")),
           shows="an electronics bench indoors: wood, red buttons, sockets and wires"),
    Source("opencv-doc", "apt: opencv-doc", "held-out", tuple(f"opencv-doc:{n}" for n in _OPENCV),
           tuple(f"opencv-doc:data/{v}.avi" for v in ("vtest", "Megamind", "tree")),
           tuple(f"opencv-doc:{n}" for n in _OPENCV_DISTRACTORS),
           shows="rooms and desks, toys on wood, a footballer's red shirt (skin), graffiti, a licence plate, printed "
                 "text, streets; videos: people walking, an animated restaurant (skin), a tree through a window"),
    Source("matplotlib", "pip: matplotlib", "held-out", ("matplotlib:grace_hopper.jpg",),
           shows="a portrait (skin) before a flag's red stripes"),
)


def by_name(name: str) -> Source:
    return next(s for s in SOURCES if s.name == name)


def video_frames(video: str) -> tuple[str, ...]:
    """A video's views: every ``VIDEO_STEP``-th frame, named ``<video>@<index>``."""
    return tuple(f"{video}@{k}" for k in range(0, len(frames(video)), VIDEO_STEP))


def views_of(source: Source) -> tuple[str, ...]:
    """Every still a source's empty and target views are cut from: its photos and its videos' sampled frames."""
    return source.photos + tuple(f for v in source.videos for f in video_frames(v))


def load(name: str) -> Image:
    """A still as BGR uint8: ``<source>:<file>`` or a video's frame ``<source>:<file>.avi@<index>``."""
    if "@" in name:
        video, index = name.rsplit("@", 1)
        return frames(video)[int(index)]
    source, file = name.split(":", 1)
    if source == "scikit-learn":
        from sklearn.datasets import load_sample_image

        return np.ascontiguousarray(np.asarray(load_sample_image(file))[..., ::-1])
    if source == "matplotlib":
        import matplotlib

        path = Path(matplotlib.get_data_path()) / "sample_data" / file
    else:
        path = {"opencv-doc": OPENCV_DIR, "avr-libc": AVR_DIR}[source] / file
    img = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if img is None:
        raise FileNotFoundError(f"{path}: install {source} (make bench-vision-sources installs it)")
    return np.asarray(img, np.uint8)


@cache
def frames(video: str) -> tuple[Image, ...]:
    """Every frame of a packaged video, BGR, shrunk to at most ``VIDEO_SIDE`` px high (the three are 68-795 frames,
    at most 768x576: vtest's 795 frames take 730 MB at 640x480)."""
    source, file = video.split(":", 1)
    path = {"opencv-doc": OPENCV_DIR}[source] / file
    cap = cv2.VideoCapture(str(path))
    out = []
    while True:
        ok, img = cap.read()
        if not ok:
            break
        if img.shape[0] > VIDEO_SIDE:
            img = cv2.resize(img, (img.shape[1] * VIDEO_SIDE // img.shape[0], VIDEO_SIDE), interpolation=cv2.INTER_AREA)
        out.append(np.asarray(img, np.uint8))
    cap.release()
    if not out:
        raise FileNotFoundError(f"{path}: no frames (install {source}: make bench-vision-sources)")
    return tuple(out)
