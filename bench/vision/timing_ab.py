"""The colour-ball detector of this tree timed against another checkout's, frame by frame: whether a change made it
faster, when the change is smaller than what the shared machine's load does to a timing run.

The report's timing (run.py) gives the ratio to the floor in blocks that the load moves by 0.1x or more. Here the
floor (cvtColor + inRange), the other checkout's detector and this tree's are called on each of the report's
320x240 timing views in turn, in all six orders one after another, and compared frame by frame. The six orders
matter: in a fixed rotation of (floor, before, after) the call that always follows the other detector finds the
frame and the caches warm, and identical code read 0.94-0.96 of itself (the thirty-first session); with the six
orders, 0.99-1.01. Time identical code first, for the noise of the day::

    git worktree add /tmp/before HEAD
    PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/timing_ab.py /tmp/before

The two detectors' candidates are compared too: a change meant only to be faster must give the same ones.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import itertools
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import vision_imagery as vi
from run import TIMING_SEED, floor, timing_frames

from pilot.vision.hsv.detector import HsvBlobDetector

ORDERS = tuple(itertools.permutations(range(3)))  # floor, before, after
Detect = Callable[[vi.Image], object]


def detector_of(root: Path, name: str) -> Detect:
    """A fresh colour-ball detector's ``candidates`` from the checkout at ``root``, its ``pilot`` package imported as
    ``name`` (beside this tree's own)."""
    init = root / "pilot" / "__init__.py"
    if not init.is_file():
        raise SystemExit(f"{root}: no pilot/__init__.py (give a checkout of this repository)")
    spec = importlib.util.spec_from_file_location(name, init, submodule_search_locations=[str(init.parent)])
    if spec is None or spec.loader is None:
        raise SystemExit(f"{init}: cannot be imported")
    package = importlib.util.module_from_spec(spec)
    sys.modules[name] = package
    spec.loader.exec_module(package)
    try:  # the layered pilot (pilot/vision/hsv/), or a checkout from before it (pilot/hsv.py)
        module = importlib.import_module(f"{name}.vision.hsv.detector")
    except ModuleNotFoundError:
        module = importlib.import_module(f"{name}.hsv")
    detector = module.HsvBlobDetector()
    candidates: Detect = detector.candidates
    return candidates


def paired(frames: list[vi.Image], rounds: int, fns: tuple[Detect, Detect, Detect]) -> list[list[list[float]]]:
    """Seconds per call of each function on each frame: ``rounds`` times over the frames, the three called on a
    frame in one of the six orders, the next order on the next frame and in the next round (a multiple of six
    rounds calls each frame in each order as often)."""
    out: list[list[list[float]]] = [[[] for _ in frames] for _ in fns]
    for r in range(rounds):
        for i, image in enumerate(frames):
            for k in ORDERS[(r + i) % len(ORDERS)]:
                t0 = time.perf_counter()
                fns[k](image)
                out[k][i].append(time.perf_counter() - t0)
    return out


def summary(times: list[list[list[float]]]) -> list[str]:
    """The detectors over the floor (medians over every call), and after over before: the ratio of those medians,
    and the median over the frames of each frame's ratio of medians."""
    every = [statistics.median([t for per in fn for t in per]) for fn in times]
    by_frame = [statistics.median(a) / statistics.median(b) for a, b in zip(times[2], times[1], strict=True)]
    return [f"before {every[1] / every[0]:.3f}x the floor, after {every[2] / every[0]:.3f}x "
            f"(floor {1e3 * every[0]:.3f} ms)",
            f"after / before: {every[2] / every[1]:.3f} (medians), {statistics.median(by_frame):.3f} (frame by frame)"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=Path, help="the other checkout (a git worktree, say)")
    ap.add_argument("--rounds", type=int, default=30,
                    help="times over the 200 views, best a multiple of 6 (30: about 25 s)")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    frames = timing_frames(np.random.default_rng(TIMING_SEED), 320, 240)
    before, after = detector_of(args.before.resolve(), "pilot_before"), HsvBlobDetector().candidates
    same = sum(repr(before(f)) == repr(after(f)) for f in frames)  # dataclasses: their fields, exactly
    print(f"the same candidates on {same} of {len(frames)} views")
    for line in summary(paired(frames, args.rounds, (floor, before, after))):
        print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
