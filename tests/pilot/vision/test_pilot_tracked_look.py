"""A tracked ball that darkens under the frame's V bound (a bright window filling more of the frame) gets a closer
look where the track expects it; nothing untracked, nor a track the pilot would not act on, gets one."""

from __future__ import annotations

import cv2
import numpy as np
import pilot_synth as synth

from pilot.common.config import VisionConfig
from pilot.vision.detect import TrackedDetector
from pilot.vision.detection import Candidate
from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.tracking import Tracker

Image = np.ndarray


def backlit(ball_value: int, cx: int = 160, seed: int = 0) -> Image:
    """A white window in the top half (the frame's brightest part sets the V bound) and a red ball of this
    brightness (HSV value) below it."""
    img = synth.background(320, 240)
    img[:90, 60:260] = 255
    red = cv2.cvtColor(np.array([[[0, 230, ball_value]]], np.uint8), cv2.COLOR_HSV2BGR)[0, 0]
    cv2.circle(img, (cx, 120), 24, tuple(int(v) for v in red), -1, lineType=cv2.LINE_AA)
    return synth.degrade(img, 1.0, 1.5, seed)  # sensor noise: no two frames alike (a frozen camera's are)


def tracked(look_again_from: float = 0.6) -> TrackedDetector:
    return TrackedDetector(HsvBlobDetector(), 0.3, 60.0, VisionConfig(), look_again_from)


def test_the_frame_alone_loses_a_ball_this_dark() -> None:
    assert HsvBlobDetector().detect(backlit(120)).found
    assert not HsvBlobDetector().detect(backlit(30)).found  # under the second look's reach too (pilot/hsv_colour.Grown)


def test_a_tracked_ball_darkening_stays_found_and_its_middle_counts_as_the_target() -> None:
    det = tracked()
    for n, value in enumerate((120, 100, 80, 65, 55, 45, 40, 36, 33, 30, 30, 30)):
        d = det.detect(backlit(value, seed=n))
        assert d.found and not d.predicted, value
        assert abs(d.cx - 160) < 2 and abs(d.cy - 120) < 2 and d.confidence >= 0.6
        assert d.aim_on_target


def test_no_closer_look_without_a_track_the_pilot_acts_on() -> None:
    assert not tracked().detect(backlit(30)).found  # no track: the frame's look only
    det = tracked(look_again_from=1.01)  # no score reaches this: no track is acted on
    assert det.detect(backlit(120)).found
    for n in range(5):
        d = det.detect(backlit(30, seed=n))
        assert not d.found or d.predicted  # bridged by the tracker a few frames, never measured


def test_the_closer_look_is_only_where_the_track_expects_the_ball() -> None:
    det = tracked()
    assert det.detect(backlit(120, cx=80)).found
    d = det.detect(backlit(30, cx=250))  # the dark ball elsewhere: not looked for there
    assert not d.found or d.predicted


def test_the_tracker_says_where_it_expects_the_target_without_moving() -> None:
    t = Tracker(VisionConfig())
    assert t.expected() is None and not t.takes([Candidate(10, 10, 20, 1.0)], 320)
    t.update([Candidate(100, 100, 20, 1.0)], 320)
    t.update([Candidate(110, 100, 20, 1.0)], 320)
    before = t.expected()
    assert before is not None and before[0] > 110 and before[2] == 20
    assert t.takes([Candidate(before[0], before[1], 21, 0.7)], 320)
    assert not t.takes([Candidate(before[0], before[1], 60, 0.7)], 320)  # not the tracked size
    assert not t.takes([Candidate(300, 220, 20, 0.7)], 320)  # out of reach
    assert t.expected() == before  # asking moved nothing
