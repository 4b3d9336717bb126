"""bench/vision/timing_ab.py, the detector of another checkout timed against this tree's: every order of the three
calls in turn, the ratios it reports, and another checkout's detector loaded beside this one's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import timing_ab as ab
from pilot_synth import background, red_disc
from run import TIMING_SEED, timing_frames

from pilot.vision.hsv.detector import HsvBlobDetector

REPO = Path(__file__).resolve().parents[3]


def test_each_frame_sees_every_order_of_the_three_calls() -> None:
    calls: list[tuple[int, int]] = []  # (function, frame)
    frames = [np.full((4, 4, 3), i, np.uint8) for i in range(3)]

    def fn(k: int) -> ab.Detect:
        return lambda image: calls.append((k, int(image[0, 0, 0])))

    times = ab.paired(frames, 6, (fn(0), fn(1), fn(2)))
    assert [[len(per) for per in f] for f in times] == [[6, 6, 6]] * 3
    triples = [calls[j:j + 3] for j in range(0, len(calls), 3)]
    assert all(len({i for _, i in t}) == 1 for t in triples)  # one frame at a time
    for frame in range(3):  # six rounds: each frame once in each of the six orders
        orders = [tuple(k for k, _ in t) for t in triples if t[0][1] == frame]
        assert sorted(orders) == sorted(ab.ORDERS)


def test_the_summary_reads_the_ratios() -> None:
    floor = [[1.0, 1.0], [1.0, 1.0]]
    before = [[2.0, 2.0], [4.0, 4.0]]
    after = [[1.0, 1.0], [4.0, 4.0]]
    lines = ab.summary([floor, before, after])
    assert lines[0].startswith("before 3.000x the floor, after 2.500x")
    assert lines[1] == "after / before: 0.833 (medians), 0.750 (frame by frame)"


def test_another_checkout_loads_beside_this_one_and_finds_the_same() -> None:
    before = ab.detector_of(REPO, "pilot_timing_ab_test")
    image = red_disc(background(320, 240), 160, 120, 20)
    found, theirs = HsvBlobDetector().candidates(image), before(image)
    assert found and isinstance(theirs, list) and repr(theirs) == repr(found)
    assert type(theirs[0]).__module__ == "pilot_timing_ab_test.vision.detection"  # not this tree's own module


def test_a_folder_with_no_pilot_is_refused(tmp_path: Path) -> None:
    with pytest.raises(SystemExit, match=r"no pilot/__init__\.py"):
        ab.detector_of(tmp_path, "pilot_nowhere")


def test_the_timing_views_are_the_reports_every_time() -> None:
    a, b = (timing_frames(np.random.default_rng(TIMING_SEED), 320, 240) for _ in range(2))
    assert len(a) == 200 and all(f.shape == (240, 320, 3) and f.dtype == np.uint8 for f in a)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
